#include "gap/locate.h"

#include <algorithm>
#include <cmath>

#include "common/check.h"
#include "common/chi_square.h"

namespace roamlab::gap {
namespace {

// Probability of the window and whole-stream chi-square tests.
constexpr double kQuantile = 0.999;

// Central difference of column `c` of `x` over +-h rows (one-sided at the ends), per second.
Eigen::VectorXd Derivative(const Eigen::VectorXd& x, const std::vector<double>& t_s, int h) {
  const int n = static_cast<int>(x.size());
  Eigen::VectorXd d = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < n; ++i) {
    const int a = std::max(0, i - h);
    const int b = std::min(n - 1, i + h);
    if (b > a) d[i] = (x[b] - x[a]) / (t_s[b] - t_s[a]);
  }
  return d;
}

double Pearson(const std::vector<double>& a, const std::vector<double>& b) {
  const int n = static_cast<int>(a.size());
  if (n < 3) return 0.0;
  double ma = 0.0, mb = 0.0;
  for (int i = 0; i < n; ++i) {
    ma += a[i];
    mb += b[i];
  }
  ma /= n;
  mb /= n;
  double sab = 0.0, saa = 0.0, sbb = 0.0;
  for (int i = 0; i < n; ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  return saa > 0.0 && sbb > 0.0 ? sab / std::sqrt(saa * sbb) : 0.0;
}

}  // namespace

double Conditions::At(int c, Time time) const {
  ROAMLAB_CHECK(!t.empty() && c >= 0 && c < values.cols(), "condition " << c);
  const auto it = std::lower_bound(t.begin(), t.end(), time);
  std::size_t k = static_cast<std::size_t>(it - t.begin());
  if (k == t.size()) k = t.size() - 1;
  if (k > 0 && time.nanoseconds() - t[k - 1].nanoseconds() < t[k].nanoseconds() - time.nanoseconds()) --k;
  return values(static_cast<Eigen::Index>(k), c);
}

Conditions ComputeConditions(const Trajectory& trajectory, const recording::Recording& recording) {
  Conditions out;
  const int n = static_cast<int>(trajectory.size());
  out.names = {"speed_mps",        "accel_long_mps2", "accel_lat_mps2", "yaw_rate_radps",
               "yaw_accel_radps2", "slope_rad",       "v_east_mps",     "v_north_mps"};
  const recording::Stream* steering = nullptr;
  for (const recording::Stream& s : recording.streams)
    if (s.info.type == recording::StreamType::kSteering && s.values.rows() > 0) steering = &s;
  if (steering) out.names.push_back("steering_rad");
  out.values.setZero(n, static_cast<Eigen::Index>(out.names.size()));
  if (n < 3) return out;

  // World velocity and yaw by central differences over h poses each side (about 0.1 s at 100 Hz: the poses carry
  // the GPS and odometer noise, and a derivative amplifies it).
  std::vector<double> t_s(n);
  for (int i = 0; i < n; ++i) t_s[i] = SecondsBetween(trajectory.front().t, trajectory[i].t);
  const double dt = t_s.back() / (n - 1);
  const int h = std::max(1, static_cast<int>(std::lround(0.05 / dt)));
  Eigen::VectorXd x(n), y(n), z(n), yaw(n);
  for (int i = 0; i < n; ++i) {
    const StampedPose& p = trajectory[i];
    out.t.push_back(p.t);
    x[i] = p.p_world_body.x();
    y[i] = p.p_world_body.y();
    z[i] = p.p_world_body.z();
    const Eigen::Vector3d forward = p.q_world_body * Eigen::Vector3d::UnitX();
    yaw[i] = std::atan2(forward.y(), forward.x());
    if (i > 0) {  // unwrap
      while (yaw[i] - yaw[i - 1] > M_PI) yaw[i] -= 2.0 * M_PI;
      while (yaw[i] - yaw[i - 1] < -M_PI) yaw[i] += 2.0 * M_PI;
    }
  }
  const Eigen::VectorXd vx = Derivative(x, t_s, h), vy = Derivative(y, t_s, h), vz = Derivative(z, t_s, h);
  const Eigen::VectorXd yaw_rate = Derivative(yaw, t_s, h);
  Eigen::VectorXd speed(n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d v_body = trajectory[i].q_world_body.conjugate() * Eigen::Vector3d(vx[i], vy[i], vz[i]);
    speed[i] = v_body.x();
    const Eigen::Vector3d forward = trajectory[i].q_world_body * Eigen::Vector3d::UnitX();
    out.values(i, 5) = std::asin(std::clamp(forward.z(), -1.0, 1.0));
  }
  out.values.col(0) = speed;
  out.values.col(1) = Derivative(speed, t_s, h);
  out.values.col(2) = speed.cwiseProduct(yaw_rate);
  out.values.col(3) = yaw_rate;
  out.values.col(4) = Derivative(yaw_rate, t_s, h);
  out.values.col(6) = vx;
  out.values.col(7) = vy;
  if (steering) {
    // The reading nearest each pose.
    std::size_t k = 0;
    for (int i = 0; i < n; ++i) {
      while (k + 1 < steering->t.size() && steering->t[k + 1] <= trajectory[i].t) ++k;
      out.values(i, 8) = steering->values(static_cast<Eigen::Index>(k), 0);
    }
  }
  return out;
}

void WindowMeans::Add(Time t, const Eigen::VectorXd& whitened) {
  if (!first_) first_ = t;
  const long w = static_cast<long>(std::floor(SecondsBetween(*first_, t) / kSystematicWindowS));
  auto& [sum, count] = windows_[w];
  if (count == 0) sum = Eigen::VectorXd::Zero(whitened.size());
  if (sum.size() != whitened.size()) return;
  sum += whitened;
  ++count;
}

double WindowMeans::Rms() const {
  double sum_squares = 0.0;
  int terms = 0;
  for (const auto& [w, window] : windows_) {
    sum_squares += (window.first / window.second).squaredNorm();
    terms += static_cast<int>(window.first.size());
  }
  return terms > 0 ? std::sqrt(sum_squares / terms) : 0.0;
}

std::map<std::string, StreamFit> StreamFits(const std::vector<estimator::MeasurementResidual>& residuals) {
  std::map<std::string, StreamFit> out;
  std::map<std::string, WindowMeans> windows;
  for (const estimator::MeasurementResidual& r : residuals) {
    if (!r.active) continue;
    StreamFit& f = out[r.stream];
    ++f.measurements;
    f.dof += static_cast<int>(r.whitened.size());
    f.chi2 += r.whitened.squaredNorm();
    windows[r.stream].Add(r.t, r.whitened);
  }
  for (auto& [name, f] : out) {
    f.chi2_per_dof = f.dof > 0 ? f.chi2 / f.dof : 0.0;
    f.rms = std::sqrt(f.chi2_per_dof);
    f.rms_1s = windows[name].Rms();
  }
  return out;
}

std::string ComponentKey(const std::string& stream, int component) { return stream + "/" + std::to_string(component); }

std::map<std::string, ComponentLevel> ComponentStatistics(
    const std::vector<estimator::MeasurementResidual>& residuals) {
  std::map<std::string, std::pair<double, int>> sums;
  for (const estimator::MeasurementResidual& r : residuals) {
    if (!r.active) continue;
    for (int c = 0; c < r.whitened.size(); ++c) {
      auto& s = sums[ComponentKey(r.stream, c)];
      s.first += r.whitened[c] * r.whitened[c];
      ++s.second;
    }
  }
  std::map<std::string, ComponentLevel> out;
  for (const auto& [key, s] : sums) out[key] = {s.second > 0 ? s.first / s.second : 0.0, s.second};
  return out;
}

std::map<std::string, double> ComponentLevels(const std::vector<estimator::MeasurementResidual>& residuals) {
  std::map<std::string, double> out;
  for (const auto& [key, level] : ComponentStatistics(residuals)) out[key] = level.chi2_per_dof;
  return out;
}

double LevelQuantile(double p, double expected_chi2_per_dof, int count) {
  const double expected = std::max(expected_chi2_per_dof, 1e-6);
  const double dof = std::max(1.0, count * std::min(1.0, expected));
  return expected * count * ChiSquareQuantile(p, dof) / dof;
}

bool Inconsistent(const ComponentLevel& level, double expected_chi2_per_dof, double ratio) {
  if (level.count <= 0) return false;
  const double expected = std::max(expected_chi2_per_dof, 1e-6);
  const double upper = LevelQuantile(kQuantile, expected, level.count) / level.count;
  return level.chi2_per_dof > std::max(upper, ratio * expected);
}

bool SignificantExcess(const ComponentLevel& level, double expected_chi2_per_dof) {
  if (level.count <= 0) return false;
  const double n = level.count;
  return (level.chi2_per_dof - expected_chi2_per_dof) * n > ChiSquareQuantile(kQuantile, level.count) - n;
}

std::vector<LocatedComponent> Locate(const std::vector<estimator::MeasurementResidual>& residuals,
                                     const Conditions& conditions, const std::map<std::string, double>& expected,
                                     const LocateOptions& options) {
  // Group the active residuals by stream and component.
  struct Series {
    std::vector<Time> t;
    std::vector<double> r;
  };
  std::map<std::string, std::map<int, Series>> series;
  for (const estimator::MeasurementResidual& m : residuals) {
    if (!m.active) continue;
    for (int c = 0; c < m.whitened.size(); ++c) {
      series[m.stream][c].t.push_back(m.t);
      series[m.stream][c].r.push_back(m.whitened[c]);
    }
  }

  std::vector<LocatedComponent> out;
  for (const auto& [stream, components] : series) {
    for (const auto& component_series : components) {
      const auto& component = component_series.first;
      const auto& s = component_series.second;  // a reference, not a binding: the lambda below captures it
      LocatedComponent lc;
      lc.stream = stream;
      lc.component = component;
      lc.count = static_cast<int>(s.r.size());
      if (lc.count < 10) continue;
      double chi2 = 0.0;
      for (double r : s.r) chi2 += r * r;
      lc.chi2_per_dof = chi2 / lc.count;
      const auto level = expected.find(ComponentKey(stream, component));
      lc.expected_chi2_per_dof = level != expected.end() ? std::max(level->second, 1e-6) : 1.0;
      lc.inconsistent =
          Inconsistent({lc.chi2_per_dof, lc.count}, lc.expected_chi2_per_dof, options.inconsistency_ratio);

      // When: windows of window_s, half overlapping, whose chi-square exceeds the level's quantile (Bonferroni:
      // 1 - (1 - kQuantile) / windows, so that a consistent component has no interval with probability kQuantile);
      // overlapping flagged windows merge into intervals.
      const double t_first = s.t.front().seconds();
      const double t_last = s.t.back().seconds();
      const double windows = std::max(1.0, std::ceil((t_last - t_first) / (0.5 * options.window_s)));
      const double window_quantile = 1.0 - (1.0 - kQuantile) / windows;
      std::size_t lo = 0;
      for (double w0 = t_first; w0 < t_last; w0 += 0.5 * options.window_s) {
        const double w1 = w0 + options.window_s;
        while (lo < s.t.size() && s.t[lo].seconds() < w0) ++lo;
        double sum = 0.0;
        int count = 0;
        for (std::size_t i = lo; i < s.t.size() && s.t[i].seconds() < w1; ++i, ++count) sum += s.r[i] * s.r[i];
        if (count < 5) continue;
        const double threshold = std::max(LevelQuantile(window_quantile, lc.expected_chi2_per_dof, count),
                                          options.inconsistency_ratio * lc.expected_chi2_per_dof * count);
        if (sum <= threshold) continue;
        if (!lc.intervals.empty() && lc.intervals.back().second >= w0)
          lc.intervals.back().second = std::min(w1, t_last);
        else
          lc.intervals.push_back({w0, std::min(w1, t_last)});
      }

      // Under which conditions: the best lag of each condition, then the three strongest.
      std::vector<Correlate> all;
      std::vector<double> cond(s.r.size());
      for (int c = 0; c < static_cast<int>(conditions.names.size()) && !conditions.t.empty(); ++c) {
        const auto rho_at = [&](double lag_s) {
          for (std::size_t i = 0; i < s.r.size(); ++i)
            cond[i] = conditions.At(c, Time::FromNanoseconds(s.t[i].nanoseconds() + std::llround(lag_s * 1e9)));
          return Pearson(s.r, cond);
        };
        // The zero lag unless another lag correlates clearly better: by twice the standard deviation of a
        // correlation estimate, (1 - rho^2) / sqrt(n) (noise would pick a lag at random otherwise).
        Correlate best{conditions.names[c], rho_at(0.0), 0.0};
        const double zero_lag =
            std::abs(best.rho) + 2.0 * (1.0 - best.rho * best.rho) / std::sqrt(static_cast<double>(s.r.size()));
        const int lags = static_cast<int>(std::lround(options.max_lag_s / options.lag_step_s));
        for (int l = -lags; l <= lags; ++l) {
          if (l == 0) continue;
          const double rho = rho_at(l * options.lag_step_s);
          if (std::abs(rho) > std::max(std::abs(best.rho), zero_lag))
            best = {conditions.names[c], rho, l * options.lag_step_s};
        }
        all.push_back(best);
      }
      std::sort(all.begin(), all.end(),
                [](const Correlate& a, const Correlate& b) { return std::abs(a.rho) > std::abs(b.rho); });
      if (all.size() > 3) all.resize(3);
      lc.correlates = all;
      out.push_back(lc);
    }
  }
  return out;
}

}  // namespace roamlab::gap
