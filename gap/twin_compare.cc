// The twin against the real recording (gap/twin.h): residual statistics, drift over windows, the white-noise
// and HAC covariances and the runners.
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>

#include <Eigen/Geometry>

#include "estimator/covariance.h"
#include "estimator/models/enu.h"
#include "gap/internal/twin_residuals.h"
#include "gap/twin.h"
#include "recording/odometry_pose.h"
#include "sim/replay.h"
#include "sim/simulator.h"

namespace roamlab::gap {
namespace {

using recording::Stream;
using recording::StreamType;

std::optional<TwinDrift> Drift(const Stream& r, const Stream& s, Time from, Time to,
                               const std::optional<recording::GeodeticOrigin>& origin, const DriftOptions& options) {
  const internal::Track k = internal::Matched(r, s, from, to, origin);
  TwinDrift d;
  d.stream = r.info.name;
  d.window_s = options.window_s;
  d.heading_measured = r.info.type == StreamType::kPose;
  if (k.t_s.size() < 2 || options.window_s <= 0.0 || options.stride_s <= 0.0) return std::nullopt;
  std::size_t a = 0;
  for (double w0 = k.t_s.front(); w0 + options.window_s <= k.t_s.back() + 1e-9; w0 += options.stride_s) {
    while (a < k.t_s.size() && k.t_s[a] < w0) ++a;
    std::size_t b = a;
    while (b + 1 < k.t_s.size() && k.t_s[b + 1] <= w0 + options.window_s + 1e-9) ++b;
    if (b <= a || k.t_s[b] - k.t_s[a] < 0.9 * options.window_s) continue;
    std::size_t e = a;
    while (e + 1 < b && k.t_s[e + 1] <= k.t_s[a] + options.align_s + 1e-9) ++e;
    const internal::PlanarFit fit = internal::PlanarAlignment(k, a, e);
    const Eigen::Matrix3d& R = fit.R;
    const double position = (R * k.twin[b] + fit.p - k.real[b]).norm();
    const double heading =
        d.heading_measured
            ? std::abs(std::remainder(internal::Yaw(Eigen::Quaterniond(R) * k.q_twin[b]) - internal::Yaw(k.q_real[b]),
                                      2.0 * M_PI))
            : 0.0;
    ++d.windows;
    d.mean_position_m += position;
    d.max_position_m = std::max(d.max_position_m, position);
    d.mean_heading_rad += heading;
    d.max_heading_rad = std::max(d.max_heading_rad, heading);
  }
  if (d.windows == 0) return std::nullopt;
  d.mean_position_m /= d.windows;
  d.mean_heading_rad /= d.windows;
  return d;
}

}  // namespace

TwinResidualOptions ReplayedResidualOptions(const sim::Scenario& nominal, const recording::Recording& real,
                                            double increment_window_s) {
  TwinResidualOptions out;
  out.increment_window_s = increment_window_s;
  auto drive = sim::DriveInputsFrom(real, nominal);
  if (!drive.ok()) return out;
  for (const std::string& name : drive.value().streams) {
    const Stream* s = real.Find(name);
    if (s && s->info.type == StreamType::kWheelEncoders)
      out.left_out[name] =
          "drives the replay (the twin's encoders track it through the wheel servos, a tick or two behind)";
  }
  return out;
}

TwinComparison CompareTwin(const recording::Recording& real, const recording::Recording& twin, double from_s,
                           double to_s, const DriftOptions& drift, const TwinResidualOptions& residuals) {
  TwinComparison out;
  out.from_s = from_s;
  out.to_s = to_s;
  out.increment_window_s = residuals.increment_window_s;
  const Time from = Time::FromSeconds(from_s), to = Time::FromSeconds(to_s);
  const internal::Layout layout = internal::MakeLayout(real, from, to, residuals);
  std::vector<std::string> missing;
  const Eigen::VectorXd whitened = internal::WhitenedResiduals(layout, real, twin, &missing);
  out.streams = internal::SeriesFits(layout, whitened);
  out.chi2 = internal::SumOfSquares(whitened, &out.residuals);
  out.left_out = layout.left_out;
  out.left_out.insert(out.left_out.end(), missing.begin(), missing.end());
  for (const Stream& r : real.streams) {
    const bool absolute =
        r.info.type == StreamType::kPose || r.info.type == StreamType::kPosition || r.info.type == StreamType::kGps;
    const Stream* s = twin.Find(r.info.name);
    if (!absolute || !s || s->info.type != r.info.type || r.values.cols() < (r.info.type == StreamType::kPose ? 7 : 3))
      continue;
    if (r.info.type == StreamType::kGps && !real.origin) continue;
    if (auto d = Drift(r, *s, from, to, real.origin, drift)) out.drift[r.info.name] = *d;
  }
  return out;
}

namespace {

// A cumulative wheel angle (wheel_encoders in rad, or without units) changes by the mean rate times the window; any
// other wheel reading (a rate, a speed, a steering angle) is averaged over it.
bool Cumulative(const Stream& s) {
  return s.info.type == StreamType::kWheelEncoders && (s.info.units.empty() || s.info.units == "rad");
}

// One window's drive of a stream: the first and last sample and the sum of the samples.
struct DriveWindow {
  Eigen::VectorXd first, last, sum;
  int n = 0;
  void Add(const Eigen::VectorXd& v) {
    if (n++ == 0) {
      first = v;
      sum = Eigen::VectorXd::Zero(v.size());
    }
    last = v;
    sum += v;
  }
  Eigen::VectorXd Drive(bool cumulative) const {
    return cumulative ? Eigen::VectorXd(last - first) : Eigen::VectorXd(sum / n);
  }
};

// The relative RMS difference of the drive of `s` (twin) from that of `r` (real) over consecutive kDriveWindowS
// windows of the stamps both have: per window the change of a cumulative angle (consecutive windows share their
// boundary sample), else the mean reading; each column's mean difference over the windows taken off (a constant offset
// of a reading, e.g. a steering offset, is not another drive); relative to the size of the real drive. The real
// stream's stated noise (ColumnSigmas) is taken out of both sums: a window's change carries twice a sample's variance,
// its mean 1/n of it. NaN when the real stream shows no drive.
double RelativeDriveDifference(const Stream& r, const Stream& s) {
  const bool cumulative = Cumulative(r);
  double noise_variance = 0.0;  // of one sample, summed over the columns
  for (const double x : internal::ColumnSigmas(r.info)) noise_variance += x * x;
  std::vector<Eigen::VectorXd> differences;
  double size = 0.0, noise = 0.0;
  DriveWindow wr, ws;
  Time start;
  std::size_t j = 0;
  for (std::size_t i = 0; i < r.t.size(); ++i) {
    while (j < s.t.size() && s.t[j] < r.t[i]) ++j;
    if (j == s.t.size()) break;
    if (s.t[j] != r.t[i]) continue;
    const Eigen::VectorXd vr = r.values.row(static_cast<Eigen::Index>(i)).transpose();
    const Eigen::VectorXd vs = s.values.row(static_cast<Eigen::Index>(j)).transpose();
    if (wr.n > 0 && SecondsBetween(start, r.t[i]) >= kDriveWindowS) {
      if (cumulative) {
        wr.Add(vr);
        ws.Add(vs);
      }
      const Eigen::VectorXd dr = wr.Drive(cumulative);
      differences.push_back(dr - ws.Drive(cumulative));
      size += dr.squaredNorm();
      noise += cumulative ? 2.0 * noise_variance : noise_variance / wr.n;
      wr = DriveWindow();
      ws = DriveWindow();
    }
    if (wr.n == 0) start = r.t[i];
    wr.Add(vr);
    ws.Add(vs);
  }
  if (differences.empty() || !(size - noise > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  Eigen::VectorXd offset = Eigen::VectorXd::Zero(r.values.cols());
  for (const Eigen::VectorXd& d : differences) offset += d;
  offset /= static_cast<double>(differences.size());
  double difference = 0.0;
  for (const Eigen::VectorXd& d : differences) difference += (d - offset).squaredNorm();
  return std::sqrt(std::max(difference - noise, 0.0) / (size - noise));
}

}  // namespace

DriveComparison CompareDrive(const recording::Recording& real, const recording::Recording& twin) {
  DriveComparison out;
  for (const Stream& r : real.streams) {
    if (r.info.type != StreamType::kWheelEncoders && r.info.type != StreamType::kSteering) continue;
    const Stream* s = twin.Find(r.info.name);
    if (!s || s->info.type != r.info.type || s->values.cols() != r.values.cols() || r.t.empty()) continue;
    const double relative = RelativeDriveDifference(r, *s);
    if (!std::isfinite(relative) || (!out.stream.empty() && relative <= out.relative)) continue;
    out.stream = r.info.name;
    out.relative = relative;
  }
  return out;
}

std::string DriveMismatch(const recording::Recording& real, const recording::Recording& twin) {
  const DriveComparison drive = CompareDrive(real, twin);
  if (drive.stream.empty()) return "no wheel stream (wheel_encoders, steering) in both to compare the drive";
  if (drive.relative < kMaxDriveMismatch) return "";
  return drive.stream + ": the twin's wheel motion differs from the recorded one by " + std::to_string(drive.relative) +
         " of its size";
}

double FixedBFactor(double b) {
  b = std::clamp(b, 0.0, 1.0);
  return (1.96 + b * (2.9694 + b * (0.4160 - 0.5324 * b))) / 1.96;
}

TwinCovariance ComputeTwinCovariance(const TwinFitRows& rows) {
  TwinCovariance out;
  const Eigen::Index k = rows.jacobian.cols();
  const Eigen::MatrixXd bread =
      (rows.jacobian.transpose() * rows.jacobian).completeOrthogonalDecomposition().pseudoInverse();
  out.white = bread;
  if (std::any_of(rows.weight.begin(), rows.weight.end(), [](double w) { return w != 1.0; })) {
    const Eigen::Map<const Eigen::VectorXd> w(rows.weight.data(), static_cast<Eigen::Index>(rows.weight.size()));
    out.white = bread * (rows.jacobian.transpose() * w.asDiagonal() * rows.jacobian) * bread;
  }
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(k, k);
  // Per series (its rows in time order, those of one stamp together): residual vectors and scores per stamp.
  for (std::size_t begin = 0; begin < rows.series.size();) {
    std::size_t end = begin;
    while (end < rows.series.size() && rows.series[end] == rows.series[begin]) ++end;
    std::vector<Eigen::VectorXd> residuals;
    std::vector<Eigen::VectorXd> scores;
    for (std::size_t i = begin; i < end;) {
      std::size_t j = i;
      while (j < end && rows.t[j] == rows.t[i]) ++j;
      const Eigen::Index first = static_cast<Eigen::Index>(i), n = static_cast<Eigen::Index>(j - i);
      residuals.push_back(rows.residuals.segment(first, n));
      scores.push_back(rows.jacobian.middleRows(first, n).transpose() * rows.residuals.segment(first, n));
      i = j;
    }
    Eigen::MatrixXd g(k, static_cast<Eigen::Index>(scores.size()));
    for (std::size_t t = 0; t < scores.size(); ++t) g.col(static_cast<Eigen::Index>(t)) = scores[t];
    // The lag from the stamps with every component (a stamp the twin misses a component of is left out of it).
    Eigen::Index dimension = 0;
    for (const Eigen::VectorXd& r : residuals) dimension = std::max(dimension, r.size());
    residuals.erase(std::remove_if(residuals.begin(), residuals.end(),
                                   [&](const Eigen::VectorXd& r) { return r.size() != dimension; }),
                    residuals.end());
    const int lag = estimator::AnalyzeAutocorrelation(residuals).lag;
    out.lags[rows.series[begin]] = lag;
    const double widening = FixedBFactor(static_cast<double>(lag + 1) / static_cast<double>(g.cols()));
    M += widening * widening * estimator::PrewhitenedBartlettSum(g, lag);
    begin = end;
  }
  out.hac = bread * M * bread;
  out.hac = 0.5 * (out.hac + out.hac.transpose()).eval();
  return out;
}

TwinRunner PlainSimulationRunner() {
  return [](const sim::Scenario& patched) -> Result<recording::Recording> {
    sim::SimulateOptions options;
    options.noise = false;
    auto simulation = sim::Simulate(patched, options);
    if (!simulation.ok()) return simulation.status();
    return std::move(simulation.value().recording);
  };
}

namespace {

// `start` moved by the planar rigid motion (PlanarAlignment, noise-weighted positions and headings) that best fits the
// pose track of `head` (a replay's first span from `start`) onto the recorded one; unchanged when the replay has no
// pose stream with 3 samples matched by stamp.
sim::ReplayStart PoseAlignedStart(const recording::Recording& real, const recording::Recording& head,
                                  sim::ReplayStart start) {
  for (const Stream& twin : head.streams) {
    const Stream* recorded = real.Find(twin.info.name);
    if (twin.info.type != StreamType::kPose || !recorded || recorded->info.type != StreamType::kPose ||
        recorded->values.cols() < 7 || twin.values.cols() < 7)
      continue;
    const Time from = Time::FromNanoseconds(std::numeric_limits<std::int64_t>::min());
    const Time to = Time::FromNanoseconds(std::numeric_limits<std::int64_t>::max());
    const internal::Track k = internal::Matched(*recorded, twin, from, to, real.origin);
    if (k.t_s.size() < 3) return start;
    const internal::PlanarFit fit = internal::PlanarAlignment(k, 0, k.t_s.size() - 1);
    const Eigen::Vector3d moved = fit.R * Eigen::Vector3d(start.p_m.x(), start.p_m.y(), 0.0) + fit.p;
    start.p_m = moved.head<2>();
    start.yaw_rad += std::atan2(fit.R(1, 0), fit.R(0, 0));
    start.source += ", aligned by its pose track's first " + std::to_string(static_cast<int>(sim::kStartAlignS)) + " s";
    return start;
  }
  return start;
}

}  // namespace

TwinRunner ReplayRunner(const recording::Recording& real) {
  auto recorded = std::make_shared<const recording::Recording>(real);
  std::optional<Time> first;
  for (const recording::Stream& s : real.streams)
    if (!s.t.empty() && (!first || s.t.front() < *first)) first = s.t.front();
  const double first_s = first ? first->seconds() : 0.0;
  // The start, found once (with the first runner call's scenario, its effects removed) and kept for every run.
  struct Start {
    std::once_flag once;
    std::optional<Result<sim::ReplayStart>> found;
  };
  auto start = std::make_shared<Start>();
  return [recorded, first_s, start](const sim::Scenario& patched) -> Result<recording::Recording> {
    std::call_once(start->once, [&] { start->found = sim::ReplayStartOf(patched, *recorded); });
    if (!start->found->ok()) return start->found->status();
    sim::ReplayOptions options;
    options.start = start->found->value();
    // With a pose stream: this scenario's replay of the first kStartAlignS, fitted onto the recorded poses, moves the
    // start (one pose's heading noise, and a start in motion that the twin takes a few steps to follow, would turn
    // the whole run by some mrad).
    if (std::any_of(recorded->streams.begin(), recorded->streams.end(), [&](const Stream& s) {
          return s.info.type == StreamType::kPose && !recording::PosedOdometry(*recorded, s);
        })) {
      sim::ReplayOptions head = options;
      head.to_s = first_s + std::min(sim::kStartAlignS, patched.duration_s);
      auto replayed = sim::Replay(patched, *recorded, head);
      if (!replayed.ok()) return Status::Error("the replay that aligns the start: " + replayed.status().message());
      options.start = PoseAlignedStart(*recorded, replayed.value().recording, *options.start);
    }
    options.to_s = first_s + patched.duration_s;
    auto replayed = sim::Replay(patched, *recorded, options);
    if (!replayed.ok()) return replayed.status();
    return std::move(replayed.value().recording);
  };
}

}  // namespace roamlab::gap
