#include "sim/internal/stream_clock.h"

#include <utility>

namespace roamlab::sim::internal {

recording::Stream MakeStream(const std::string& name, recording::StreamType type, double rate_hz,
                             std::vector<std::string> columns, const std::string& units, const Clock& clock) {
  recording::Stream stream;
  stream.info.name = name;
  stream.info.type = type;
  stream.info.rate_hz = rate_hz;
  stream.info.columns = std::move(columns);
  stream.info.units = units;
  stream.t.reserve(clock.samples);
  for (std::size_t k = 0; k < clock.samples; ++k)
    stream.t.push_back(Time::FromNanoseconds(static_cast<std::int64_t>(k) * clock.period_ns));
  stream.values.setZero(static_cast<Eigen::Index>(clock.samples),
                        static_cast<Eigen::Index>(stream.info.columns.size()));
  return stream;
}

}  // namespace roamlab::sim::internal
