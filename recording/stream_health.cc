#include "recording/stream_health.h"

namespace roamlab::recording {
namespace {

bool ChecksFrozen(StreamType type) {
  switch (type) {
    case StreamType::kImu:
    case StreamType::kGyroscope:
    case StreamType::kAccelerometer:
    case StreamType::kMagnetometer:
    case StreamType::kGps:
    case StreamType::kPosition:
    case StreamType::kPose:
      return true;
    default:
      return false;
  }
}

bool SameRow(const Stream& s, std::size_t a, std::size_t b) {
  return s.values.row(static_cast<Eigen::Index>(a)) == s.values.row(static_cast<Eigen::Index>(b));
}

std::vector<FrozenRun> FrozenRuns(const Stream& s) {
  std::vector<FrozenRun> runs;
  if (!ChecksFrozen(s.info.type) || s.values.cols() == 0) return runs;
  std::size_t first = 0;
  for (std::size_t i = 1; i <= s.t.size(); ++i) {
    if (i < s.t.size() && SameRow(s, first, i)) continue;
    const int rows = static_cast<int>(i - first);
    if (rows >= kFrozenMinRows && SecondsBetween(s.t[first], s.t[i - 1]) >= kFrozenMinSeconds)
      runs.push_back({s.t[first], s.t[i - 1], rows});
    first = i;
  }
  return runs;
}

}  // namespace

int StreamHealth::FrozenRepeats() const {
  int repeats = 0;
  for (const FrozenRun& run : frozen) repeats += run.rows - 1;
  return repeats;
}

StreamHealth CheckStreamHealth(const Stream& stream) {
  StreamHealth health;
  if (stream.info.rate_hz > 0.0) {
    const double limit_s = kGapPeriods / stream.info.rate_hz;
    for (std::size_t i = 1; i < stream.t.size(); ++i) {
      const double dt = SecondsBetween(stream.t[i - 1], stream.t[i]);
      if (dt > limit_s) health.gaps.push_back({stream.t[i - 1], dt});
    }
  }
  health.frozen = FrozenRuns(stream);
  return health;
}

void DropDuplicateRows(Recording* recording) {
  for (Stream& s : recording->streams) {
    std::vector<std::size_t> keep;
    for (std::size_t i = 0; i < s.t.size(); ++i) {
      const bool repeat =
          i > 0 && s.t[i] == s.t[i - 1] && SameRow(s, i, i - 1) && (s.text.empty() || s.text[i] == s.text[i - 1]);
      if (!repeat) keep.push_back(i);
    }
    if (keep.size() == s.t.size()) continue;
    s.duplicate_rows_dropped += static_cast<std::int64_t>(s.t.size() - keep.size());
    Eigen::MatrixXd values(static_cast<Eigen::Index>(keep.size()), s.values.cols());
    std::vector<Time> t;
    std::vector<std::string> text;
    for (std::size_t k = 0; k < keep.size(); ++k) {
      values.row(static_cast<Eigen::Index>(k)) = s.values.row(static_cast<Eigen::Index>(keep[k]));
      t.push_back(s.t[keep[k]]);
      if (!s.text.empty()) text.push_back(s.text[keep[k]]);
    }
    s.t = std::move(t);
    s.values = std::move(values);
    if (!s.text.empty()) s.text = std::move(text);
  }
}

}  // namespace roamlab::recording
