// Checks of a stream's timing and values that no single row shows: gaps (an outage or a clock that jumped) and runs
// of identical rows (a frozen sensor), and the dropping of identical repeated rows (duplicated messages) from a stream
// built in memory. The estimator counts what they find per stream (estimator/problem.h StreamCounts) and leaves a
// frozen run's repeated rows out; the calibrate and track commands print a warning for each finding.
//
//   gap      two consecutive stamps further apart than kGapPeriods nominal periods (info.rate_hz; none without a rate)
//   frozen   at least kFrozenMinRows consecutive rows with every value identical, spanning at least kFrozenMinSeconds,
//            in a stream whose readings carry continuous noise (imu, gyroscope, accelerometer, magnetometer, gps,
//            position, pose); wheel encoders, steering, velocity streams and inputs may legitimately repeat a value
//            (quantized angles, a robot at rest) and are not checked.
#pragma once

#include <cstdint>
#include <vector>

#include "common/time.h"
#include "recording/recording.h"

namespace roamlab::recording {

inline constexpr double kGapPeriods = 5.0;
inline constexpr int kFrozenMinRows = 10;
inline constexpr double kFrozenMinSeconds = 0.5;

struct StreamGap {
  Time after;           // the last stamp before the gap
  double length_s = 0;  // to the next stamp
};

struct FrozenRun {
  Time first, last;  // stamps of the run's first and last rows
  int rows = 0;      // rows in the run, the first included
};

struct StreamHealth {
  std::vector<StreamGap> gaps;
  std::vector<FrozenRun> frozen;
  int FrozenRepeats() const;  // rows that repeat a run's first row (rows - 1 per run)
};

// The gaps and frozen runs of `stream` (its stamps in order, as read).
StreamHealth CheckStreamHealth(const Stream& stream);

// Drops every row identical to the one before it (the same stamp, values and text), as ReadRecording does, adding
// the count to duplicate_rows_dropped. For a recording built in memory (a simulation with the duplicates fault).
void DropDuplicateRows(Recording* recording);

}  // namespace roamlab::recording
