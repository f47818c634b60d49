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

// The windowed increments' series of a gps or position stream over [from, to] (gap/twin.h TwinResidualOptions):
// windows from a sample to the last sample within window_s of it, the next from there, each at least 0.9 window_s
// long.
void AddIncrementSeries(const Stream& s, const std::vector<double>& sigma, Time from, Time to, double window_s,
                        Layout* layout) {
  Series series;
  series.name = s.info.name;
  series.stream = s.info.name;
  series.type = s.info.type;
  series.sigma = sigma;
  std::size_t a = static_cast<std::size_t>(std::lower_bound(s.t.begin(), s.t.end(), from) - s.t.begin());
  while (a < s.t.size() && s.t[a] <= to) {
    std::size_t b = a;
    while (b + 1 < s.t.size() && s.t[b + 1] <= to && SecondsBetween(s.t[a], s.t[b + 1]) <= window_s + 1e-9) ++b;
    if (b == a || SecondsBetween(s.t[a], s.t[b]) < kShortestWindowShare * window_s) break;
    series.starts.push_back(a);
    series.rows.push_back(b);
    series.t.push_back(s.t[b]);
    a = b;
  }
  series.offset = layout->size;
  layout->size += series.size();
  layout->series.push_back(std::move(series));
}

// A pose stream's windows over [from, to] as TwinDrift takes them (gap/twin.h TwinResidualOptions): one starting
// every stride_s from the first sample (at the first sample at or after that time), ending at the last sample within
// window_s of it (at least 0.9 window_s long), the alignment over its samples within align_s of its start (before its
// end); each entry weighted sqrt(stride_s / window_s) when the windows overlap.
void AddPoseWindowSeries(const Stream& s, const std::vector<double>& sigma, Time from, Time to,
                         const TwinResidualOptions& options, Layout* layout) {
  Series series;
  series.name = s.info.name;
  series.stream = s.info.name;
  series.type = s.info.type;
  series.sigma = sigma;
  const double window_s = options.increment_window_s;
  const double stride_s = options.increment_stride_s > 0.0 ? options.increment_stride_s : window_s;
  series.weight = std::sqrt(std::min(1.0, stride_s / window_s));
  const std::size_t first = static_cast<std::size_t>(std::lower_bound(s.t.begin(), s.t.end(), from) - s.t.begin());
  std::size_t last = first;
  while (last + 1 < s.t.size() && s.t[last + 1] <= to) ++last;
  std::size_t a = first;
  for (double w0 = 0.0;
       first < s.t.size() && s.t[first] <= to && w0 + window_s <= SecondsBetween(s.t[first], s.t[last]) + 1e-9;
       w0 += stride_s) {
    while (a < last && SecondsBetween(s.t[first], s.t[a]) < w0 - 1e-9) ++a;
    std::size_t b = a;
    while (b < last && SecondsBetween(s.t[first], s.t[b + 1]) <= w0 + window_s + 1e-9) ++b;
    if (b <= a || SecondsBetween(s.t[a], s.t[b]) < kShortestWindowShare * window_s) continue;
    std::size_t e = a;
    while (e + 1 < b && SecondsBetween(s.t[a], s.t[e + 1]) <= options.align_s + 1e-9) ++e;
    series.starts.push_back(a);
    series.align_ends.push_back(e);
    series.rows.push_back(b);
    series.t.push_back(s.t[b]);
  }
  series.offset = layout->size;
  layout->size += series.size();
  layout->series.push_back(std::move(series));
}

// A pose window's whitened end error (gap/twin.h TwinResidualOptions): the twin aligned onto the recorded poses of
// rows a..e (PlanarAlignment), the recorded position at row b less the aligned twin's, along and across the lever
// l = p_b - c (c the recorded centroid of a..e, about which the alignment turns the twin), over the noise of the
// recorded samples: sigma^2 (1 + 1/n) each way (p_b and the centroid of n samples), plus l^2 / I across (I the
// alignment yaw's information). NaN when the twin lacks the sample of row a or b.
Eigen::Vector2d WhitenedPoseWindow(const Series& series, const Stream& real, const Stream& twin, std::size_t i) {
  const Eigen::Vector2d missing = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  const Time ta = real.t[series.starts[i]], te = real.t[series.align_ends[i]], tb = real.t[series.rows[i]];
  const Track head = Matched(real, twin, ta, te, std::nullopt);
  const Track end = Matched(real, twin, tb, tb, std::nullopt);
  if (head.t_s.empty() || head.t_s.front() != ta.seconds() || end.t_s.empty()) return missing;
  const PlanarFit fit = PlanarAlignment(head, 0, head.t_s.size() - 1);
  const Eigen::Vector2d error = (end.real[0] - (fit.R * end.twin[0] + fit.p)).head<2>();
  const Eigen::Vector2d lever = (end.real[0] - fit.real_centroid).head<2>();
  const Eigen::Vector2d along = lever.norm() > 0.0 ? Eigen::Vector2d(lever.normalized()) : Eigen::Vector2d::UnitX();
  const Eigen::Vector2d across(-along.y(), along.x());
  const double n = static_cast<double>(head.t_s.size());
  const double point2 = series.sigma[0] * series.sigma[0] * (1.0 + 1.0 / n);
  const double turn2 = fit.yaw_information > 0.0 ? lever.squaredNorm() / fit.yaw_information : 0.0;
  return series.weight *
         Eigen::Vector2d(error.dot(along) / std::sqrt(point2), error.dot(across) / std::sqrt(point2 + turn2));
}

// The whitened increments of one series: per window the recorded increment less the twin's (rows of `twin` matched
// by stamp, NaN where it lacks either); a gps fix's or position's per ENU axis over sqrt(2) sigma; a pose's as
// WhitenedPoseWindow.
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
    const Eigen::Index k = series.offset + static_cast<Eigen::Index>(i) * n;
    if (series.type == StreamType::kPose) {
      out->segment<2>(k) = WhitenedPoseWindow(series, real, twin, i);
      continue;
    }
    const std::size_t a = series.starts[i], b = series.rows[i];
    const auto ta = twin_row(real.t[a]), tb = twin_row(real.t[b]);
    if (!ta || !tb) continue;
    const Eigen::Vector3d delta = (position(real, b) - position(real, a)) - (position(twin, *tb) - position(twin, *ta));
    for (int c = 0; c < n; ++c) (*out)[k + c] = delta[c] / (std::sqrt(2.0) * series.sigma[static_cast<std::size_t>(c)]);
  }
}

}  // namespace

double Yaw(const Eigen::Quaterniond& q) {
  const Eigen::Vector3d x = q * Eigen::Vector3d::UnitX();
  return std::atan2(x.y(), x.x());
}

Track Matched(const Stream& r, const Stream& s, Time from, Time to,
              const std::optional<recording::GeodeticOrigin>& origin) {
  Track track;
  std::optional<estimator::EnuConverter> enu;
  if (origin) enu.emplace(*origin);
  const auto position = [&](const Stream& x, std::size_t row) {
    const Eigen::Vector3d v = x.values.row(static_cast<Eigen::Index>(row)).head(3).transpose();
    return x.info.type == StreamType::kGps ? Eigen::Vector3d(enu->ToEnu(v[0], v[1], v[2])) : v;
  };
  const auto attitude = [](const Stream& x, std::size_t row) {
    const auto v = x.values.row(static_cast<Eigen::Index>(row));
    return Eigen::Quaterniond(v[6], v[3], v[4], v[5]).normalized();
  };
  const bool pose = r.info.type == StreamType::kPose;
  if (pose) {
    const double sigma_m = std::max(Noise(r.info, "position_m"), Noise(r.info, "sigma_m"));
    const double sigma_rad = Noise(r.info, "orientation_rad");
    if (sigma_rad > 0.0) track.heading_weight = 1.0 / (sigma_rad * sigma_rad);
    track.position_weight = sigma_m > 0.0 ? 1.0 / (sigma_m * sigma_m) : sigma_rad > 0.0 ? 0.0 : 1.0;
  }
  std::size_t j = 0;
  for (std::size_t i = 0; i < r.t.size(); ++i) {
    if (r.t[i] < from || to < r.t[i]) continue;
    while (j < s.t.size() && s.t[j] < r.t[i]) ++j;
    if (j == s.t.size()) break;
    if (s.t[j] != r.t[i]) continue;
    track.t_s.push_back(r.t[i].seconds());
    track.real.push_back(position(r, i));
    track.twin.push_back(position(s, j));
    if (pose) {
      track.q_real.push_back(attitude(r, i));
      track.q_twin.push_back(attitude(s, j));
    }
  }
  return track;
}

PlanarFit PlanarAlignment(const Track& k, std::size_t a, std::size_t b) {
  const double n = static_cast<double>(b - a + 1);
  Eigen::Vector3d cr = Eigen::Vector3d::Zero(), ct = Eigen::Vector3d::Zero();
  double heading_sin = 0.0, heading_cos = 0.0;
  for (std::size_t i = a; i <= b; ++i) {
    cr += k.real[i];
    ct += k.twin[i];
    if (k.heading_weight <= 0.0) continue;
    const double d = Yaw(k.q_real[i]) - Yaw(k.q_twin[i]);
    heading_sin += std::sin(d);
    heading_cos += std::cos(d);
  }
  cr /= n;
  ct /= n;
  double extent = 0.0, sxx = 0.0, sxy = 0.0;
  for (std::size_t i = a; i <= b; ++i) {
    const Eigen::Vector2d r = (k.real[i] - cr).head<2>(), t = (k.twin[i] - ct).head<2>();
    extent = std::max(extent, r.norm());
    sxx += t.dot(r);
    sxy += t.x() * r.y() - t.y() * r.x();
  }
  PlanarFit fit;
  fit.real_centroid = cr;
  if (k.heading_weight <= 0.0 && extent < 0.1) {
    fit.p = k.real[a] - k.twin[a];
    return fit;
  }
  double yaw = std::atan2(sxy, sxx);
  const double positions = k.position_weight * std::hypot(sxx, sxy), headings = k.heading_weight * n;
  if (k.heading_weight > 0.0) {
    const double d = std::atan2(heading_sin, heading_cos);
    yaw = d + positions / (positions + headings) * std::remainder(yaw - d, 2.0 * M_PI);
  }
  fit.yaw_information = positions + headings;
  fit.R = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  fit.p = cr - fit.R * ct;
  return fit;
}

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
    if (options.increment_window_s > 0.0 && s.info.type == StreamType::kPose)
      AddPoseWindowSeries(s, sigma, from, to, options, &layout);
    else if (options.increment_window_s > 0.0 && Absolute(s.info.type))
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
