// Private helpers of the simulator: the sample instants of a stream and its layout in the recording.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "recording/recording.h"

namespace roamlab::sim::internal {

// A stream's clock: its period and the number of samples in [0, end]. Sample k is stamped k * period and taken at
// k * period - shift (a time-shift effect: a late GPS fix, an IMU whose clock runs ahead); Due and Row take the time
// the sample is taken. A scheduled clock (a replay, sim/replay_schedule.h) has its samples at step_ns[k] instead (the
// physics step nearest stamp k, in simulation time), stamped stamps[k]; several samples may share one step, Row gives
// the first and FillRepeatedRows copies it to the others.
struct Clock {
  std::int64_t period_ns = 0;
  std::size_t samples = 0;
  std::int64_t shift_ns = 0;
  std::vector<std::int64_t> step_ns;  // scheduled: non-decreasing, one per sample
  std::vector<Time> stamps;           // scheduled: the samples' stamps
  bool scheduled() const { return !step_ns.empty(); }
  bool Due(std::int64_t t_ns) const {
    const std::int64_t stamp_ns = t_ns + shift_ns;
    if (scheduled()) return std::binary_search(step_ns.begin(), step_ns.end(), stamp_ns);
    return period_ns > 0 && stamp_ns >= 0 && stamp_ns % period_ns == 0 &&
           stamp_ns / period_ns < static_cast<std::int64_t>(samples);
  }
  Eigen::Index Row(std::int64_t t_ns) const {
    if (scheduled())
      return static_cast<Eigen::Index>(std::lower_bound(step_ns.begin(), step_ns.end(), t_ns + shift_ns) -
                                       step_ns.begin());
    return static_cast<Eigen::Index>((t_ns + shift_ns) / period_ns);
  }
  // The last instant at which a sample is taken (simulation time).
  std::int64_t LastSampleNs() const {
    if (scheduled()) return step_ns.back() - shift_ns;
    return samples > 0 ? static_cast<std::int64_t>(samples - 1) * period_ns - shift_ns : 0;
  }
};

// Schedules `clock` at `stamps` (strictly increasing, >= origin): each sample at the multiple of step_ns nearest its
// stamp - origin.
void Schedule(const std::vector<Time>& stamps, Time origin, std::int64_t step_ns, Clock* clock);

// A stream with one zero row per sample of `clock`: stamped origin + k * period, or a scheduled clock's stamps.
recording::Stream MakeStream(const std::string& name, recording::StreamType type, double rate_hz,
                             std::vector<std::string> columns, const std::string& units, const Clock& clock,
                             Time origin = Time());

// A scheduled clock's samples that share a step with the sample before take its row (Row gives the first of them).
void FillRepeatedRows(const Clock& clock, recording::Stream* stream);

}  // namespace roamlab::sim::internal
