#include "sim/internal/stream_clock.h"

#include <cmath>
#include <utility>

namespace roamlab::sim::internal {

recording::Stream MakeStream(const std::string& name, recording::StreamType type, double rate_hz,
                             std::vector<std::string> columns, const std::string& units, const Clock& clock,
                             Time origin) {
  recording::Stream stream;
  stream.info.name = name;
  stream.info.type = type;
  stream.info.rate_hz = rate_hz;
  stream.info.columns = std::move(columns);
  stream.info.units = units;
  stream.t.reserve(clock.samples);
  for (std::size_t k = 0; k < clock.samples; ++k) {
    stream.t.push_back(clock.scheduled() ? clock.stamps[k]
                                         : Time::FromNanoseconds(origin.nanoseconds() +
                                                                 static_cast<std::int64_t>(k) * clock.period_ns));
  }
  stream.values.setZero(static_cast<Eigen::Index>(clock.samples),
                        static_cast<Eigen::Index>(stream.info.columns.size()));
  return stream;
}

void Schedule(const std::vector<Time>& stamps, Time origin, std::int64_t step_ns, Clock* clock) {
  clock->stamps = stamps;
  clock->samples = stamps.size();
  clock->step_ns.clear();
  clock->step_ns.reserve(stamps.size());
  for (Time s : stamps) {
    const double steps = static_cast<double>(s.nanoseconds() - origin.nanoseconds()) / static_cast<double>(step_ns);
    clock->step_ns.push_back(std::llround(steps) * step_ns);
  }
}

void FillRepeatedRows(const Clock& clock, recording::Stream* stream) {
  for (std::size_t k = 1; k < clock.step_ns.size(); ++k) {
    const auto row = static_cast<Eigen::Index>(k);
    if (clock.step_ns[k] == clock.step_ns[k - 1]) stream->values.row(row) = stream->values.row(row - 1);
  }
}

}  // namespace roamlab::sim::internal
