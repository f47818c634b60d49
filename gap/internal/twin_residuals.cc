#include "gap/internal/twin_residuals.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Geometry>

#include "estimator/models/enu.h"
#include "gap/locate.h"

namespace roamlab::gap::internal {
namespace {

using recording::Stream;
using recording::StreamType;

double Noise(const recording::StreamInfo& info, const std::string& key) {
  const auto it = info.noise.find(key);
  return it != info.noise.end() ? it->second : 0.0;
}

// Whitened residuals of one series: sums of squares per component, and their 1 s means (WindowMeans, as StreamFits).
struct Accumulator {
  explicit Accumulator(int components) : sum_squares(static_cast<std::size_t>(components), 0.0) {}

  void Add(Time t, const Eigen::VectorXd& whitened) {
    for (int k = 0; k < whitened.size(); ++k) sum_squares[static_cast<std::size_t>(k)] += whitened[k] * whitened[k];
    ++samples;
    windows.Add(t, whitened);
  }

  SimulatedStreamFit Fit() const {
    SimulatedStreamFit f;
    f.samples = samples;
    double total = 0.0;
    for (double s : sum_squares) {
      f.component_rms.push_back(samples > 0 ? std::sqrt(s / samples) : 0.0);
      total += s;
    }
    const double count = static_cast<double>(samples) * static_cast<double>(sum_squares.size());
    f.rms = count > 0.0 ? std::sqrt(total / count) : 0.0;
    f.rms_1s = windows.Rms();
    return f;
  }

  std::vector<double> sum_squares;
  int samples = 0;
  WindowMeans windows;
};

// The series of one stream over [from, to]: an imu's columns as two series.
void AddSeries(const Stream& s, const std::vector<double>& sigma, Time from, Time to, Layout* layout) {
  std::vector<std::size_t> rows;
  std::vector<Time> t;
  for (std::size_t i = 0; i < s.t.size(); ++i) {
    if (s.t[i] < from || to < s.t[i]) continue;
    rows.push_back(i);
    t.push_back(s.t[i]);
  }
  const auto add = [&](const std::string& name, int first, int n) {
    Series series;
    series.name = name;
    series.stream = s.info.name;
    series.type = s.info.type;
    series.first_column = first;
    series.sigma.assign(sigma.begin() + first, sigma.begin() + first + n);
    series.rows = rows;
    series.t = t;
    series.offset = layout->size;
    layout->size += series.size();
    layout->series.push_back(std::move(series));
  };
  if (s.info.type == StreamType::kImu) {
    add("gyroscope", 0, 3);
    add("accelerometer", 3, 3);
  } else {
    add(s.info.name, 0, static_cast<int>(sigma.size()));
  }
}

bool Absolute(StreamType type) {
  return type == StreamType::kPose || type == StreamType::kGps || type == StreamType::kPosition;
}

// The windowed increments' series of an absolute stream over [from, to] (gap/twin.h TwinResidualOptions): windows
// from a sample to the last sample within window_s of it, the next from there, each at least 0.9 window_s long.
void AddIncrementSeries(const Stream& s, const std::vector<double>& sigma, Time from, Time to, double window_s,
                        Layout* layout) {
  Series series;
  series.name = s.info.name;
  series.stream = s.info.name;
  series.type = s.info.type;
  series.sigma = sigma;
  if (s.info.type == StreamType::kPose) series.heading_sigma = Noise(s.info, "orientation_rad");
  std::size_t a = static_cast<std::size_t>(std::lower_bound(s.t.begin(), s.t.end(), from) - s.t.begin());
  while (a < s.t.size() && s.t[a] <= to) {
    std::size_t b = a;
    while (b + 1 < s.t.size() && s.t[b + 1] <= to && SecondsBetween(s.t[a], s.t[b + 1]) <= window_s + 1e-9) ++b;
    if (b == a || SecondsBetween(s.t[a], s.t[b]) < 0.9 * window_s) break;
    series.starts.push_back(a);
    series.rows.push_back(b);
    series.t.push_back(s.t[b]);
    a = b;
  }
  series.offset = layout->size;
  layout->size += series.size();
  layout->series.push_back(std::move(series));
}

double Yaw(const Eigen::Quaterniond& q) {
  const Eigen::Vector3d x = q * Eigen::Vector3d::UnitX();
  return std::atan2(x.y(), x.x());
}

// A pose's planar increment from row a to row b in its frame at a: R(-yaw_a) (p_b - p_a).
Eigen::Vector2d PoseIncrement(const Stream& s, std::size_t a, std::size_t b) {
  const auto row = [&](std::size_t i) { return s.values.row(static_cast<Eigen::Index>(i)); };
  const Eigen::Quaterniond q_a(row(a)[6], row(a)[3], row(a)[4], row(a)[5]);
  const Eigen::Vector2d d(row(b)[0] - row(a)[0], row(b)[1] - row(a)[1]);
  return Eigen::Rotation2Dd(-Yaw(q_a.normalized())) * d;
}

// The whitened increments of one series: per window the recorded increment less the twin's (rows of `twin` matched
// by stamp, NaN where it lacks either), a pose's along and across the recorded displacement d, over sqrt(2) sigma and
// sqrt(2 sigma^2 + heading_sigma^2 |d|^2); a gps fix's or position's per ENU axis over sqrt(2) sigma.
void WhitenedIncrements(const Series& series, const Stream& real, const Stream& twin,
                        const std::optional<estimator::EnuConverter>& enu, Eigen::VectorXd* out) {
  const auto twin_row = [&](Time t) -> std::optional<std::size_t> {
    const auto it = std::lower_bound(twin.t.begin(), twin.t.end(), t);
    if (it == twin.t.end() || *it != t) return std::nullopt;
    return static_cast<std::size_t>(it - twin.t.begin());
  };
  const auto position = [&](const Stream& x, std::size_t row) {
    const Eigen::Vector3d p = x.values.row(static_cast<Eigen::Index>(row)).head(3).transpose();
    return series.type == StreamType::kGps ? Eigen::Vector3d(enu->ToEnu(p[0], p[1], p[2])) : p;
  };
  const int n = series.components();
  if (series.type == StreamType::kPose && (real.values.cols() < 7 || twin.values.cols() < 7)) return;
  for (std::size_t i = 0; i < series.rows.size(); ++i) {
    const std::size_t a = series.starts[i], b = series.rows[i];
    const auto ta = twin_row(real.t[a]), tb = twin_row(real.t[b]);
    if (!ta || !tb) continue;
    const Eigen::Index k = series.offset + static_cast<Eigen::Index>(i) * n;
    if (series.type == StreamType::kPose) {
      const Eigen::Vector2d d = PoseIncrement(real, a, b);
      const Eigen::Vector2d delta = d - PoseIncrement(twin, *ta, *tb);
      const Eigen::Vector2d along = d.norm() > 0.0 ? Eigen::Vector2d(d.normalized()) : Eigen::Vector2d::UnitX();
      const Eigen::Vector2d across(-along.y(), along.x());
      const double sigma2 = 2.0 * series.sigma[0] * series.sigma[0];
      const double heading2 = series.heading_sigma * series.heading_sigma * d.squaredNorm();
      (*out)[k] = delta.dot(along) / std::sqrt(sigma2);
      (*out)[k + 1] = delta.dot(across) / std::sqrt(sigma2 + heading2);
      continue;
    }
    const Eigen::Vector3d delta = (position(real, b) - position(real, a)) - (position(twin, *tb) - position(twin, *ta));
    for (int c = 0; c < n; ++c) (*out)[k + c] = delta[c] / (std::sqrt(2.0) * series.sigma[static_cast<std::size_t>(c)]);
  }
}

}  // namespace

std::vector<double> ColumnSigmas(const recording::StreamInfo& info) {
  const auto repeat = [](double sigma, int n) { return std::vector<double>(static_cast<std::size_t>(n), sigma); };
  switch (info.type) {
    case StreamType::kImu: {
      std::vector<double> s = repeat(Noise(info, "gyro_sigma_radps"), 3);
      const std::vector<double> a = repeat(Noise(info, "accel_sigma_mps2"), 3);
      s.insert(s.end(), a.begin(), a.end());
      return s;
    }
    case StreamType::kGps:
    case StreamType::kPosition:
      return repeat(Noise(info, "sigma_m"), 3);
    case StreamType::kPose:
      // x and y only: the height of a pose is that of the stream's reference point, which motion capture of a planar
      // robot does not state (an imported OptiOdom run writes 0).
      return repeat(Noise(info, "position_m") > 0.0 ? Noise(info, "position_m") : Noise(info, "sigma_m"), 2);
    case StreamType::kOdometry:
    case StreamType::kVisualOdometry:
    case StreamType::kScanMatching: {
      std::vector<double> s = repeat(Noise(info, "sigma_mps"), 3);
      const std::vector<double> w = repeat(Noise(info, "sigma_radps"), 3);
      s.insert(s.end(), w.begin(), w.end());
      return s;
    }
    case StreamType::kWheelEncoders: {
      const int n = static_cast<int>(info.columns.size());
      const auto ticks = info.attributes.find("ticks_per_revolution");
      if (info.units == "rad" && ticks != info.attributes.end() && ticks->second > 0.0)
        return repeat(2.0 * M_PI / ticks->second / std::sqrt(12.0), n);
      for (const char* key : {"sigma_mps", "sigma_radps", "sigma_rad"})
        if (Noise(info, key) > 0.0) return repeat(Noise(info, key), n);
      return {};
    }
    case StreamType::kCamera:
    case StreamType::kInputs:
    case StreamType::kLaserScan:
      return {};
    default:
      // One stated sigma for every column (gyroscope, accelerometer, magnetometer, steering).
      if (info.noise.size() != 1) return {};
      return repeat(info.noise.begin()->second, static_cast<int>(info.columns.size()));
  }
}

Layout MakeLayout(const recording::Recording& real, Time from, Time to, const TwinResidualOptions& options) {
  Layout layout;
  layout.origin = real.origin;
  for (const Stream& s : real.streams) {
    if (const auto it = options.left_out.find(s.info.name); it != options.left_out.end()) {
      layout.left_out.push_back(s.info.name + ": " + it->second);
      continue;
    }
    const std::vector<double> sigma = ColumnSigmas(s.info);
    const bool stated = !sigma.empty() && std::all_of(sigma.begin(), sigma.end(), [](double x) { return x > 0.0; });
    std::string why;
    if (!stated)
      why = "no stated noise";
    else if (static_cast<int>(s.info.columns.size()) < static_cast<int>(sigma.size()))
      why = "fewer columns than its type has";
    else if (s.info.type == StreamType::kGps && !real.origin)
      why = "no origin";
    if (!why.empty()) {
      layout.left_out.push_back(s.info.name + ": " + why);
      continue;
    }
    if (options.increment_window_s > 0.0 && Absolute(s.info.type))
      AddIncrementSeries(s, sigma, from, to, options.increment_window_s, &layout);
    else
      AddSeries(s, sigma, from, to, &layout);
  }
  return layout;
}

Eigen::VectorXd WhitenedResiduals(const Layout& layout, const recording::Recording& real,
                                  const recording::Recording& twin, std::vector<std::string>* missing) {
  Eigen::VectorXd out = Eigen::VectorXd::Constant(layout.size, std::numeric_limits<double>::quiet_NaN());
  std::optional<estimator::EnuConverter> enu;
  if (layout.origin) enu.emplace(*layout.origin);
  for (const Series& series : layout.series) {
    const Stream* r = real.Find(series.stream);
    const Stream* s = twin.Find(series.stream);
    const int n = series.components();
    if (!r || !s || s->info.type != series.type || s->values.cols() < series.first_column + n) {
      if (missing) missing->push_back(series.name + ": not in the twin");
      continue;
    }
    if (!series.starts.empty()) {
      WhitenedIncrements(series, *r, *s, enu, &out);
      continue;
    }
    const auto value = [&](const Stream& stream, std::size_t row) {
      const Eigen::Index k = static_cast<Eigen::Index>(row);
      if (series.type == StreamType::kGps) {
        const Eigen::Vector3d p = stream.values.row(k).head(3).transpose();
        return Eigen::VectorXd(enu->ToEnu(p[0], p[1], p[2]));
      }
      return Eigen::VectorXd(stream.values.row(k).segment(series.first_column, n).transpose());
    };
    std::size_t j = 0;
    for (std::size_t i = 0; i < series.rows.size(); ++i) {
      const Time t = series.t[i];
      while (j < s->t.size() && s->t[j] < t) ++j;
      if (j == s->t.size()) break;
      if (s->t[j] != t) continue;
      const Eigen::VectorXd d = value(*r, series.rows[i]) - value(*s, j);
      for (int c = 0; c < n; ++c)
        out[series.offset + static_cast<Eigen::Index>(i) * n + c] = d[c] / series.sigma[static_cast<std::size_t>(c)];
    }
  }
  return out;
}

std::map<std::string, SimulatedStreamFit> SeriesFits(const Layout& layout, const Eigen::VectorXd& whitened) {
  std::map<std::string, SimulatedStreamFit> out;
  for (const Series& series : layout.series) {
    const int n = series.components();
    Accumulator a(n);
    for (std::size_t i = 0; i < series.rows.size(); ++i) {
      const Eigen::VectorXd w = whitened.segment(series.offset + static_cast<Eigen::Index>(i) * n, n);
      if (w.allFinite()) a.Add(series.t[i], w);
    }
    if (a.samples > 0) out[series.name] = a.Fit();
  }
  return out;
}

double SumOfSquares(const Eigen::VectorXd& whitened, int* count) {
  double sum = 0.0;
  int n = 0;
  for (Eigen::Index i = 0; i < whitened.size(); ++i) {
    if (!std::isfinite(whitened[i])) continue;
    sum += whitened[i] * whitened[i];
    ++n;
  }
  if (count) *count = n;
  return sum;
}

std::vector<estimator::MeasurementResidual> MeasurementResiduals(const Layout& layout,
                                                                 const Eigen::VectorXd& whitened) {
  std::vector<estimator::MeasurementResidual> out;
  for (const Series& s : layout.series) {
    const int n = s.components();
    for (std::size_t i = 0; i < s.rows.size(); ++i) {
      const Eigen::VectorXd r = whitened.segment(s.offset + static_cast<Eigen::Index>(i) * n, n);
      if (r.allFinite()) out.push_back({s.name, s.t[i], r, true});
    }
  }
  return out;
}

}  // namespace roamlab::gap::internal
