// Private helpers of the simulator: the sample instants of a stream and its layout in the recording.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "recording/recording.h"

namespace roamlab::sim::internal {

// A stream's clock: its period and the number of samples in [0, end]. Sample k is stamped k * period and taken at
// k * period - shift (a time-shift effect: a late GPS fix, an IMU whose clock runs ahead); Due and Row take the time
// the sample is taken.
struct Clock {
  std::int64_t period_ns = 0;
  std::size_t samples = 0;
  std::int64_t shift_ns = 0;
  bool Due(std::int64_t t_ns) const {
    const std::int64_t stamp_ns = t_ns + shift_ns;
    return period_ns > 0 && stamp_ns >= 0 && stamp_ns % period_ns == 0 &&
           stamp_ns / period_ns < static_cast<std::int64_t>(samples);
  }
  Eigen::Index Row(std::int64_t t_ns) const { return static_cast<Eigen::Index>((t_ns + shift_ns) / period_ns); }
};

// A stream with one zero row per sample of `clock`, stamped k * period.
recording::Stream MakeStream(const std::string& name, recording::StreamType type, double rate_hz,
                             std::vector<std::string> columns, const std::string& units, const Clock& clock);

}  // namespace roamlab::sim::internal
