#include "gap/internal/twin_fit.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <limits>
#include <numeric>
#include <thread>

namespace roamlab::gap::internal {
namespace {

constexpr double kMinDecrease = 0.1;
constexpr double kMinRelativeDecrease = 1e-5;
constexpr int kMaxTries = 4;
// The spans a time shift's batch-means std cuts the training part into (BatchShiftStd): 10 s each on an 80 s part.
constexpr int kShiftBatches = 8;
// A parameter is informed by the data when its conditional white std (the others fitted along) is below this share of
// its range (hi - lo); others are held at their neutral values.
constexpr double kMaxInformedStdShare = 0.05;

TwinParameter P(const std::string& name, double neutral, double step, double lo, double hi) {
  return {name, neutral, step, lo, hi};
}

// The wheels a kind's axle_misalignment takes (0: the Ackermann rear axle, no wheel index).
int Wheels(const std::string& kind) {
  if (kind == "differential_drive") return 2;
  if (kind == "omni3") return 3;
  if (kind == "mecanum") return 4;
  return 0;
}

std::vector<TwinCandidate> Library(const sim::Scenario& nominal, double max_shift_s) {
  std::vector<TwinCandidate> all;
  all.push_back({"wheel_radius_asymmetry", "wheel_radius_asymmetry", {}, {P("ratio_right_left", 1, 0.01, 0.8, 1.2)}});
  all.push_back({"wheel_radius_scale", "wheel_radius_scale", {}, {P("scale", 1, 0.01, 0.8, 1.2)}});
  all.push_back({"track_width_error", "track_width_error", {}, {P("track_error_m", 0, 0.01, -0.1, 0.1)}});
  // A differential drive's geometry as one effect: the common radius scale, the right/left ratio and the track fitted
  // together. Each alone, or one on top of another, absorbs what the others explain of the runs at hand (a turn is
  // both the ratio's and the track's, a line both the scale's and the ratio's); on runs of different drives together
  // the three are told apart.
  if (nominal.robot.kind == "differential_drive") {
    TwinCandidate geometry{"diff_drive_geometry", "diff_drive_geometry", {}, {}};
    geometry.parts = {all[0], all[1], all[2]};
    geometry.central = true;
    geometry.several_runs = true;
    for (const TwinCandidate& part : geometry.parts)
      geometry.free.insert(geometry.free.end(), part.free.begin(), part.free.end());
    all.push_back(geometry);
  }
  all.push_back({"odometry_scale_error", "odometry_scale_error", {}, {P("scale", 1, 0.01, 0.5, 1.5)}});
  if (nominal.robot.kind == "skid_steer")
    all.push_back({"skid_steer_track", "skid_steer_track", {}, {P("track_ratio", 1, 0.05, 0.7, 1.5)}});
  const int wheels = Wheels(nominal.robot.kind);
  for (int w = 0; w < wheels; ++w)
    all.push_back({"axle_misalignment wheel " + std::to_string(w),
                   "axle_misalignment",
                   {{"wheel", w}},
                   {P("yaw_deg", 0, 1.0, -20, 20)}});
  if (nominal.robot.kind == "ackermann")
    all.push_back({"axle_misalignment", "axle_misalignment", {}, {P("yaw_deg", 0, 0.25, -5, 5)}});
  all.push_back({"gyro_scale_error",
                 "gyro_scale_error",
                 {},
                 {P("scale_x", 1, 0.01, 0.5, 1.5), P("scale_y", 1, 0.01, 0.5, 1.5), P("scale_z", 1, 0.01, 0.5, 1.5)}});
  all.push_back(
      {"gyro_bias_drift",
       "gyro_bias_drift",
       {},
       {P("initial_x", 0, 1e-3, -0.5, 0.5), P("initial_y", 0, 1e-3, -0.5, 0.5), P("initial_z", 0, 1e-3, -0.5, 0.5)}});
  all.push_back({"magnetometer_motor_interference",
                 "magnetometer_motor_interference",
                 {},
                 {P("b_per_nm_x", 0, 1e-4, -1, 1), P("b_per_nm_y", 0, 1e-4, -1, 1), P("b_per_nm_z", 0, 1e-4, -1, 1)}});
  all.push_back({"steering_offset", "steering_offset", {}, {P("offset_rad", 0, 5e-3, -0.5, 0.5)}});
  all.push_back({"lateral_slip", "lateral_slip", {}, {P("contact_time_scale", 1, 0.05, 1, 4)}});
  TwinCandidate latency{"gps_latency", "gps_latency", {}, {P("latency_s", 0, 0, 0, std::min(1.0, max_shift_s))}};
  latency.time_shift = true;
  all.push_back(latency);
  const double imu_range = std::min(0.5, max_shift_s);
  TwinCandidate offset{"imu_time_offset", "imu_time_offset", {}, {P("offset_s", 0, 0, -imu_range, imu_range)}};
  offset.time_shift = true;
  all.push_back(offset);
  // The motion capture's clock against the drive (sim/scenario.h pose_time_offset): the pose stamped t is O's pose at
  // t - offset_s, so a negative value is wheel encoders that read behind the motion capture.
  TwinCandidate pose{"pose_time_offset", "pose_time_offset", {}, {P("offset_s", 0, 0, -imu_range, imu_range)}};
  pose.time_shift = true;
  all.push_back(pose);
  // The recorded drive inputs against the other sensors (sim/scenario.h drive_time_offset): the whole twin shifted.
  // A candidate with an IMU, whose rates time the drive; with one absolute stream and no IMU that stream's own clock
  // (pose_time_offset, gps_latency) says the same.
  TwinCandidate drive{"drive_time_offset", "drive_time_offset", {}, {P("offset_s", 0, 0, -imu_range, imu_range)}};
  drive.time_shift = true;
  if (nominal.sensors.imu) all.push_back(drive);
  // The recorded drive's clock against the others' as an offset at the replay's start and a rate (drive_time_offset
  // with drift_ppm): two free-running clocks part linearly, and a constant shift fitted on the first part of a run is
  // wrong on the last. Fitted by Levenberg-Marquardt: the replay reads its inputs between their rows, so the pose and
  // position windows' residuals are smooth in both. At a constant speed the rate trades with the wheels' scale; stops,
  // turns and runs of other drives tell them apart. Not with an IMU: its per-sample rates and forces time the drive so
  // sharply that the residuals are far from quadratic over the difference steps, and the fit stops near its start.
  TwinCandidate clock{"drive_clock_drift",
                      "drive_time_offset",
                      {},
                      {P("offset_s", 0, 0.02, -imu_range, imu_range), P("drift_ppm", 0, 2000, -1e4, 1e4)}};
  clock.central = true;
  clock.several_runs = true;
  if (!nominal.sensors.imu) all.push_back(clock);
  return all;
}

Eigen::VectorXd NeutralValues(const TwinCandidate& c) {
  Eigen::VectorXd theta(static_cast<Eigen::Index>(c.free.size()));
  for (std::size_t j = 0; j < c.free.size(); ++j) theta[static_cast<Eigen::Index>(j)] = c.free[j].neutral;
  return theta;
}

// Entries finite in `center`; elsewhere 0.
Eigen::VectorXd Masked(const Eigen::VectorXd& r, const Eigen::VectorXd& center) {
  Eigen::VectorXd out = r;
  for (Eigen::Index i = 0; i < r.size(); ++i)
    if (!std::isfinite(r[i]) || !std::isfinite(center[i])) out[i] = 0.0;
  return out;
}

// The fit's rows: the finite entries of `center` and the Jacobian's rows there, with their weights (per entry).
TwinFitRows Rows(const Layout& layout, const Eigen::VectorXd& center, const Eigen::MatrixXd& jacobian,
                 const std::vector<double>& weights) {
  TwinFitRows rows;
  std::vector<Eigen::Index> keep;
  for (const Series& s : layout.series)
    for (std::size_t i = 0; i < s.rows.size(); ++i)
      for (int c = 0; c < s.components(); ++c) {
        const Eigen::Index k = s.offset + static_cast<Eigen::Index>(i) * s.components() + c;
        if (!std::isfinite(center[k])) continue;
        keep.push_back(k);
        rows.weight.push_back(weights[static_cast<std::size_t>(k)]);
        rows.t.push_back(s.t[i]);
        rows.series.push_back(s.name);
      }
  rows.residuals.resize(static_cast<Eigen::Index>(keep.size()));
  rows.jacobian.resize(static_cast<Eigen::Index>(keep.size()), jacobian.cols());
  for (std::size_t j = 0; j < keep.size(); ++j) {
    rows.residuals[static_cast<Eigen::Index>(j)] = center[keep[j]];
    rows.jacobian.row(static_cast<Eigen::Index>(j)) = jacobian.row(keep[j]);
  }
  return rows;
}

// Candidates fitted together (one for a single candidate's fit): their free parameters concatenated in order.
struct Parts {
  std::vector<TwinCandidate> candidates;
  std::string label;  // the candidates' labels joined by " + "
  std::vector<TwinParameter> free;
  bool central = false;  // some candidate asks for central differences

  explicit Parts(std::vector<TwinCandidate> parts) : candidates(std::move(parts)) {
    for (const TwinCandidate& c : candidates) {
      central = central || c.central;
      label += (label.empty() ? "" : " + ") + c.label;
      free.insert(free.end(), c.free.begin(), c.free.end());
    }
  }
  // Per candidate, its effects at theta.
  std::vector<Patch> PerCandidate(const Eigen::VectorXd& theta) const {
    std::vector<Patch> out;
    Eigen::Index offset = 0;
    for (const TwinCandidate& c : candidates) {
      const Eigen::Index k = static_cast<Eigen::Index>(c.free.size());
      out.push_back(EffectsAt(c, theta.segment(offset, k)));
      offset += k;
    }
    return out;
  }
  Patch At(const Eigen::VectorXd& theta) const {
    Patch out;
    for (const Patch& p : PerCandidate(theta)) out.insert(out.end(), p.begin(), p.end());
    return out;
  }
};

Eigen::VectorXd Clamp(const Parts& parts, Eigen::VectorXd theta) {
  for (std::size_t j = 0; j < parts.free.size(); ++j) {
    const Eigen::Index k = static_cast<Eigen::Index>(j);
    theta[k] = std::clamp(theta[k], parts.free[j].lo, parts.free[j].hi);
  }
  return theta;
}

// The Jacobian of the residuals by the parameters at `theta` (residuals `center`): central differences when 2k runs
// fit in the threads or a candidate asks for them (TwinCandidate::central), else forward (backward at the upper bound;
// one-sided at either bound).
Result<Eigen::MatrixXd> Jacobian(const Parts& parts, const Eigen::VectorXd& theta, const Eigen::VectorXd& center,
                                 int threads, TwinEvaluator* evaluator) {
  const int k = static_cast<int>(parts.free.size());
  const bool central = parts.central || 2 * k <= std::max(2, threads);
  std::vector<Patch> runs;
  std::vector<std::pair<double, double>> deltas;  // per parameter: the + and - steps taken (0: none)
  for (int j = 0; j < k; ++j) {
    const TwinParameter& p = parts.free[static_cast<std::size_t>(j)];
    double plus = theta[j] + p.step <= p.hi ? p.step : 0.0;
    double minus = (central || plus == 0.0) && theta[j] - p.step >= p.lo ? p.step : 0.0;
    if (plus == 0.0 && minus == 0.0)
      return Status::Error(parts.label + ": " + p.name + "'s range is narrower than a step");
    for (const double d : {plus, -minus}) {
      if (d == 0.0) continue;
      Eigen::VectorXd at = theta;
      at[j] += d;
      runs.push_back(parts.At(at));
    }
    deltas.push_back({plus, minus});
  }
  const std::vector<Result<Eigen::VectorXd>> r = evaluator->Run(runs);
  for (const auto& x : r)
    if (!x.ok()) return Status::Error(parts.label + ": a perturbed twin: " + x.status().message());
  Eigen::MatrixXd J(center.size(), k);
  std::size_t next = 0;
  for (int j = 0; j < k; ++j) {
    const auto [plus, minus] = deltas[static_cast<std::size_t>(j)];
    const Eigen::VectorXd hi = plus > 0.0 ? Masked(r[next++].value(), center) : Masked(center, center);
    const Eigen::VectorXd lo = minus > 0.0 ? Masked(r[next++].value(), center) : Masked(center, center);
    J.col(j) = (hi - lo) / (plus + minus);
  }
  return J;
}

// The std of parameter j from the information H with the other `kept` parameters fitted along:
// 1 / sqrt(H_jj - H_jo H_oo^+ H_oj); infinite without information.
double ConditionalStd(const Eigen::MatrixXd& H, const std::vector<bool>& kept, int j) {
  std::vector<int> others;
  for (int o = 0; o < static_cast<int>(kept.size()); ++o)
    if (o != j && kept[static_cast<std::size_t>(o)]) others.push_back(o);
  double information = H(j, j);
  if (!others.empty()) {
    const Eigen::MatrixXd Hoo = H(others, others);
    const Eigen::VectorXd Hoj = H(others, j);
    information -= Hoj.dot(Hoo.completeOrthogonalDecomposition().solve(Hoj));
  }
  return information > 0.0 ? 1.0 / std::sqrt(information) : std::numeric_limits<double>::infinity();
}

// Which of c.free the Jacobian J (at the neutral values) informs: with the parameters in units of their ranges
// (hi - lo) and H = J^T J, the kept parameter of the largest ConditionalStd is held (at its neutral value) while that
// std exceeds kMaxInformedStdShare, and the rest judged again. A zero column (the parameter moves no residual) has no
// information; of two columns that move the residuals alike one is held.
std::vector<bool> Informed(const TwinCandidate& c, const Eigen::MatrixXd& J) {
  const int k = static_cast<int>(c.free.size());
  Eigen::MatrixXd Jr = J;
  for (int j = 0; j < k; ++j)
    Jr.col(j) *= c.free[static_cast<std::size_t>(j)].hi - c.free[static_cast<std::size_t>(j)].lo;
  const Eigen::MatrixXd H = Jr.transpose() * Jr;
  std::vector<bool> kept(static_cast<std::size_t>(k), true);
  for (;;) {
    int worst = -1;
    double worst_std = kMaxInformedStdShare;
    for (int j = 0; j < k; ++j) {
      if (!kept[static_cast<std::size_t>(j)]) continue;
      const double std_share = ConditionalStd(H, kept, j);
      if (std_share > worst_std) {
        worst = j;
        worst_std = std_share;
      }
    }
    if (worst < 0) return kept;
    kept[static_cast<std::size_t>(worst)] = false;
  }
}

// The outcome of FitLeastSquares.
struct LeastSquares {
  Eigen::VectorXd theta;
  TwinCovariance covariance;
  double chi2 = 0.0;
  Eigen::VectorXd residuals;
  int iterations = 0;
};

// Levenberg-Marquardt from `start` (residuals `at_start`), the parameters scaled by their steps. Stops when the
// Gauss-Newton step predicts, or the step taken makes, a decrease below kMinDecrease + kMinRelativeDecrease chi2 (a
// tenth of the chi-square unit that moves a parameter by one standard deviation, so at most a third of it away), after
// max_iterations, or when kMaxTries dampings do not decrease the cost. `first_jacobian`, when given, is the Jacobian at
// `start`.
Result<LeastSquares> FitLeastSquares(const Parts& parts, const Eigen::VectorXd& start, const Eigen::VectorXd& at_start,
                                     TwinEvaluator* evaluator, const FitSettings& settings,
                                     const Eigen::MatrixXd* first_jacobian) {
  const int k = static_cast<int>(parts.free.size());
  LeastSquares out;
  out.theta = start;
  Eigen::VectorXd scale(k);
  for (int j = 0; j < k; ++j) scale[j] = parts.free[static_cast<std::size_t>(j)].step;
  out.residuals = at_start;
  out.chi2 = SumOfSquares(at_start);
  double lambda = 1e-3;
  Eigen::MatrixXd J;
  for (out.iterations = 0; out.iterations < settings.max_iterations; ++out.iterations) {
    if (out.iterations == 0 && first_jacobian) {
      J = *first_jacobian;
    } else {
      auto jacobian = Jacobian(parts, out.theta, out.residuals, settings.threads, evaluator);
      if (!jacobian.ok()) return jacobian.status();
      J = jacobian.value();
    }
    const Eigen::MatrixXd Js = J * scale.asDiagonal();
    const Eigen::VectorXd r = Masked(out.residuals, out.residuals);
    const Eigen::MatrixXd H = Js.transpose() * Js;
    const Eigen::VectorXd g = Js.transpose() * r;
    const double enough = kMinDecrease + kMinRelativeDecrease * out.chi2;
    if (-g.dot(H.completeOrthogonalDecomposition().solve(-g)) < enough) break;
    double decrease = 0.0;
    for (int tries = 0; tries < kMaxTries && decrease <= 0.0; ++tries, lambda *= 10.0) {
      Eigen::MatrixXd A = H;
      A.diagonal() += lambda * H.diagonal().cwiseMax(1e-12);
      const Eigen::VectorXd trial = Clamp(parts, out.theta + scale.cwiseProduct(A.ldlt().solve(-g)));
      auto run = evaluator->Run({parts.At(trial)});
      if (!run[0].ok()) return Status::Error(parts.label + ": a trial twin: " + run[0].status().message());
      const double chi2 = SumOfSquares(Masked(run[0].value(), out.residuals));
      if (chi2 >= out.chi2) continue;
      decrease = out.chi2 - chi2;
      out.theta = trial;
      out.residuals = run[0].value();
      out.chi2 = chi2;
      lambda = std::max(1e-7, lambda / 100.0);
    }
    if (decrease < enough) break;
  }
  out.covariance = ComputeTwinCovariance(Rows(evaluator->layout(), out.residuals, J, evaluator->entry_weights()));
  return out;
}

// The time shift on the step grid: the chi-square at a coarse grid of 9 points over the range, then halving the
// spacing about the best until neighbouring steps; the value is the vertex of the parabola through the best step and
// its neighbours (within half a step of it), the covariance from the residuals' central difference there
// (FitCandidate).
Result<CandidateOutcome> SearchTimeShift(const TwinCandidate& c, const Eigen::VectorXd& base, TwinEvaluator* evaluator,
                                         const FitSettings& settings) {
  const TwinParameter& p = c.free.front();
  const double step = settings.physics_step_s;
  const long lo = static_cast<long>(std::ceil(p.lo / step - 1e-9)),
             hi = static_cast<long>(std::floor(p.hi / step + 1e-9));
  std::map<long, Eigen::VectorXd> r;
  std::map<long, double> chi2;
  r[0] = base;
  chi2[0] = SumOfSquares(base);
  const auto evaluate = [&](std::vector<long> shifts) -> Status {
    std::vector<long> todo;
    for (long s : shifts)
      if (s >= lo && s <= hi && !r.count(s) && std::find(todo.begin(), todo.end(), s) == todo.end()) todo.push_back(s);
    std::vector<Patch> runs;
    for (long s : todo) runs.push_back(EffectsAt(c, Eigen::VectorXd::Constant(1, static_cast<double>(s) * step)));
    const auto out = evaluator->Run(runs);
    for (std::size_t i = 0; i < todo.size(); ++i) {
      if (!out[i].ok()) return Status::Error(c.label + ": a shifted twin: " + out[i].status().message());
      r[todo[i]] = out[i].value();
      chi2[todo[i]] = SumOfSquares(Masked(out[i].value(), base));
    }
    return Status::Ok();
  };
  const auto best = [&] {
    return std::min_element(chi2.begin(), chi2.end(), [](const auto& a, const auto& b) { return a.second < b.second; })
        ->first;
  };
  std::vector<long> coarse;
  for (int i = 0; i <= 8; ++i) coarse.push_back(lo + static_cast<long>(std::lround((hi - lo) * i / 8.0)));
  if (Status s = evaluate(coarse); !s.ok()) return s;
  long spacing = std::max(1L, (hi - lo) / 8);
  int rounds = 0;
  for (long b = best();; b = best(), ++rounds) {
    spacing = std::max(1L, spacing / 2);
    if (Status s = evaluate({b - spacing, b + spacing}); !s.ok()) return s;
    if (spacing == 1 && best() == b) break;
  }
  const long b = best();
  CandidateOutcome out;
  out.iterations = rounds;
  out.residuals = r[b];
  out.chi2 = chi2[b];
  out.effects = EffectsAt(c, Eigen::VectorXd::Constant(1, static_cast<double>(b) * step));
  double vertex = 0.0;
  if (r.count(b - 1) && r.count(b + 1)) {
    const double curvature = chi2[b - 1] - 2.0 * chi2[b] + chi2[b + 1];
    if (curvature > 0.0) vertex = std::clamp(0.5 * (chi2[b - 1] - chi2[b + 1]) / curvature, -0.5, 0.5);
  }
  out.theta = Eigen::VectorXd::Constant(1, (static_cast<double>(b) + vertex) * step);
  const long up = r.count(b + 1) ? b + 1 : b, down = r.count(b - 1) ? b - 1 : b;
  Eigen::MatrixXd J(base.size(), 1);
  J.col(0) =
      up > down
          ? Eigen::VectorXd((Masked(r[up], r[b]) - Masked(r[down], r[b])) / (static_cast<double>(up - down) * step))
          : Eigen::VectorXd::Zero(base.size());
  const Eigen::VectorXd at_vertex = r[b] + J.col(0) * (vertex * step);
  out.covariance = ComputeTwinCovariance(Rows(evaluator->layout(), at_vertex, J, evaluator->entry_weights()));
  const double batch_std = BatchShiftStd(evaluator->layout(), r, step, J.col(0), kShiftBatches);
  out.covariance.batch = Eigen::MatrixXd::Constant(1, 1, batch_std * batch_std);
  return out;
}

// Student's t two-sided 95 % quantile for nu >= 2 degrees of freedom (Cornish-Fisher to 1/nu^3: 4.17 at nu = 2
// against 4.30, 3.16 at 3 against 3.18, within 0.1 % from 6 on).
double StudentT975(double nu) {
  nu = std::max(nu, 2.0);
  const double z = 1.959964, z3 = z * z * z, z5 = z3 * z * z, z7 = z5 * z * z;
  return z + (z3 + z) / (4.0 * nu) + (5.0 * z5 + 16.0 * z3 + 3.0 * z) / (96.0 * nu * nu) +
         (3.0 * z7 + 19.0 * z5 + 17.0 * z3 - 15.0 * z) / (384.0 * nu * nu * nu);
}

// The vertex of the parabola through (x0, y0), (x1, y1), (x2, y2), x0 < x1 < x2 and y1 the least, within [x0, x2].
double ParabolaVertex(double x0, double y0, double x1, double y1, double x2, double y2) {
  const double a = (x1 - x0) * (y1 - y2), b = (x1 - x2) * (y1 - y0);
  const double denominator = a - b;
  if (!(std::abs(denominator) > 0.0)) return x1;
  return std::clamp(x1 - 0.5 * ((x1 - x0) * a - (x1 - x2) * b) / denominator, x0, x2);
}

// Per span of each series' stamps (BatchShiftStd): its chi-square at each evaluated shift (in the map's order) and its
// information, over the entries finite at every shift.
struct Spans {
  std::vector<std::vector<double>> chi2;
  std::vector<double> information;
};
Spans SpanChiSquares(const Layout& layout, const std::map<long, Eigen::VectorXd>& residuals_at_step,
                     const Eigen::VectorXd& jacobian, int batches) {
  Spans out;
  out.chi2.assign(static_cast<std::size_t>(batches), std::vector<double>(residuals_at_step.size(), 0.0));
  out.information.assign(static_cast<std::size_t>(batches), 0.0);
  for (const Series& series : layout.series) {
    if (series.t.empty()) continue;
    const double span_s = SecondsBetween(series.t.front(), series.t.back());
    for (std::size_t i = 0; i < series.rows.size(); ++i) {
      const double share = span_s > 0.0 ? SecondsBetween(series.t.front(), series.t[i]) / span_s : 0.0;
      const auto k = static_cast<std::size_t>(std::clamp(static_cast<int>(share * batches), 0, batches - 1));
      for (int c = 0; c < series.components(); ++c) {
        const Eigen::Index e = series.offset + static_cast<Eigen::Index>(i) * series.components() + c;
        if (!std::all_of(residuals_at_step.begin(), residuals_at_step.end(),
                         [&](const auto& at) { return std::isfinite(at.second[e]); }))
          continue;
        std::size_t j = 0;
        for (const auto& at : residuals_at_step) out.chi2[k][j++] += at.second[e] * at.second[e];
        out.information[k] += jacobian[e] * jacobian[e];
      }
    }
  }
  return out;
}

// The std of the weighted mean of `theta` (weights `weight`, positive) from their scatter (BatchShiftStd's formula);
// 0 below 3 effective spans.
double WeightedBatchStd(const std::vector<double>& theta, std::vector<double> weight) {
  const double total = std::accumulate(weight.begin(), weight.end(), 0.0);
  double mean = 0.0, sum_w2 = 0.0;
  for (std::size_t k = 0; k < theta.size(); ++k) {
    weight[k] /= total;
    mean += weight[k] * theta[k];
    sum_w2 += weight[k] * weight[k];
  }
  const double effective = theta.empty() ? 0.0 : 1.0 / sum_w2;
  if (effective < 3.0) return 0.0;
  double sum = 0.0;
  for (std::size_t k = 0; k < theta.size(); ++k) sum += weight[k] * weight[k] * (theta[k] - mean) * (theta[k] - mean);
  return std::sqrt(sum / (1.0 - sum_w2)) * StudentT975(effective - 1.0) / 1.959964;
}

}  // namespace

double BatchShiftStd(const Layout& layout, const std::map<long, Eigen::VectorXd>& residuals_at_step, double step_s,
                     const Eigen::VectorXd& jacobian, int batches) {
  if (residuals_at_step.size() < 3 || batches < 2) return 0.0;
  const Spans spans = SpanChiSquares(layout, residuals_at_step, jacobian, batches);
  std::vector<double> shifts_s;
  for (const auto& at : residuals_at_step) shifts_s.push_back(static_cast<double>(at.first) * step_s);
  std::vector<double> theta, weight;
  for (std::size_t k = 0; k < spans.chi2.size(); ++k) {
    if (!(spans.information[k] > 0.0)) continue;
    const std::vector<double>& c = spans.chi2[k];
    const auto j = static_cast<std::size_t>(std::min_element(c.begin(), c.end()) - c.begin());
    theta.push_back(j == 0 || j + 1 == c.size()
                        ? shifts_s[j]
                        : ParabolaVertex(shifts_s[j - 1], c[j - 1], shifts_s[j], c[j], shifts_s[j + 1], c[j + 1]));
    weight.push_back(spans.information[k]);
  }
  return WeightedBatchStd(theta, weight);
}

TwinCandidate Reduced(const TwinCandidate& c, const std::vector<bool>& informed) {
  TwinCandidate out = c;
  out.free.clear();
  out.parts.clear();
  auto next = informed.begin();
  for (const TwinCandidate& part : c.parts) {
    const auto end = next + static_cast<std::ptrdiff_t>(part.free.size());
    out.parts.push_back(Reduced(part, std::vector<bool>(next, end)));
    next = end;
  }
  for (std::size_t j = 0; j < c.free.size(); ++j) {
    if (informed[j])
      out.free.push_back(c.free[j]);
    else
      out.fixed[c.free[j].name] = c.free[j].neutral;
  }
  return out;
}

std::vector<TwinCandidate> TwinCandidates(const sim::Scenario& nominal, double max_shift_s) {
  std::vector<TwinCandidate> out;
  for (const TwinCandidate& c : Library(nominal, max_shift_s)) {
    sim::Scenario trial = nominal;
    trial.effects.clear();
    Eigen::VectorXd theta(static_cast<Eigen::Index>(c.free.size()));
    for (std::size_t j = 0; j < c.free.size(); ++j)
      theta[static_cast<Eigen::Index>(j)] = std::clamp(c.free[j].neutral + 0.01, c.free[j].lo, c.free[j].hi);
    trial.effects = EffectsAt(c, theta);
    if (!trial.Validate()) out.push_back(c);
  }
  return out;
}

Patch EffectsAt(const TwinCandidate& c, const Eigen::VectorXd& theta) {
  if (c.parts.empty()) {
    sim::EffectOptions e;
    e.name = c.effect;
    e.parameters = c.fixed;
    for (std::size_t j = 0; j < c.free.size(); ++j) e.parameters[c.free[j].name] = theta[static_cast<Eigen::Index>(j)];
    return {e};
  }
  return Parts(c.parts).At(theta);
}

std::vector<std::string> SimulatorEffects(const TwinCandidate& c) {
  if (c.parts.empty()) return {c.effect};
  std::vector<std::string> out;
  for (const TwinCandidate& part : c.parts) out.push_back(part.effect);
  return out;
}

void ParallelFor(int n, int threads, const std::function<void(int)>& fn) {
  std::atomic<int> next{0};
  const auto worker = [&] {
    for (int i = next++; i < n; i = next++) fn(i);
  };
  std::vector<std::thread> pool;
  for (int k = 1; k < std::min(std::max(1, threads), n); ++k) pool.emplace_back(worker);
  worker();
  for (std::thread& t : pool) t.join();
}

double SummedWeight(const Layout& layout) {
  double sum = 0.0;
  for (const Series& s : layout.series) sum += s.weight * s.weight * static_cast<double>(s.size());
  return sum;
}

std::vector<double> EqualRunScales(const std::vector<double>& summed_weights) {
  double total = 0.0;
  for (double s : summed_weights) total += s;
  const double each = total / static_cast<double>(summed_weights.size());
  std::vector<double> out;
  for (double s : summed_weights) out.push_back(std::sqrt(each / s));
  return out;
}

Layout CombinedLayout(const std::vector<FitRun>& runs) {
  if (runs.size() == 1) return runs.front().layout;
  Layout out;
  if (!runs.empty()) out.origin = runs.front().layout.origin;
  for (const FitRun& run : runs) {
    for (Series s : run.layout.series) {
      s.name = run.name + ": " + s.name;
      s.offset += out.size;
      out.series.push_back(std::move(s));
    }
    for (const std::string& why : run.layout.left_out) out.left_out.push_back(run.name + ": " + why);
    out.size += run.layout.size;
  }
  return out;
}

namespace {

// The runs' residual vectors (one per run, in order) concatenated.
Eigen::VectorXd Concatenated(const std::vector<FitRun>& runs, const std::vector<Eigen::VectorXd>& per_run) {
  if (per_run.size() == 1) return per_run.front();
  Eigen::Index size = 0;
  for (const FitRun& run : runs) size += run.layout.size;
  Eigen::VectorXd out(size);
  Eigen::Index offset = 0;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    out.segment(offset, runs[i].layout.size) = per_run[i];
    offset += runs[i].layout.size;
  }
  return out;
}

}  // namespace

Eigen::VectorXd CombinedResiduals(const std::vector<FitRun>& runs, const std::vector<recording::Recording>& twins) {
  std::vector<Eigen::VectorXd> per_run;
  for (std::size_t i = 0; i < runs.size(); ++i)
    per_run.push_back(runs[i].scale * WhitenedResiduals(runs[i].layout, *runs[i].real, twins[i]));
  return Concatenated(runs, per_run);
}

std::vector<Result<Eigen::VectorXd>> TwinEvaluator::Run(const std::vector<Patch>& patches) {
  const std::size_t n_runs = runs_of_.size();
  std::vector<Result<Eigen::VectorXd>> each(patches.size() * n_runs, Result<Eigen::VectorXd>(Status::Error("not run")));
  ParallelFor(static_cast<int>(each.size()), threads_, [&](int i) {
    const FitRun& run = runs_of_[static_cast<std::size_t>(i) % n_runs];
    const Patch& patch = patches[static_cast<std::size_t>(i) / n_runs];
    sim::Scenario patched = base_;
    patched.duration_s = run.duration_s;
    patched.effects.insert(patched.effects.end(), patch.begin(), patch.end());
    Result<Eigen::VectorXd>& out = each[static_cast<std::size_t>(i)];
    try {
      auto twin = (*run.runner)(patched);
      out = twin.ok() ? Result<Eigen::VectorXd>(run.scale * WhitenedResiduals(run.layout, *run.real, twin.value()))
                      : twin.status();
    } catch (const std::exception& e) {
      out = Status::Error(std::string("the twin runner failed: ") + e.what());
    }
    if (!out.ok() && n_runs > 1) out = Status::Error(run.name + ": " + out.status().message());
  });
  runs_ += static_cast<int>(each.size());
  std::vector<Result<Eigen::VectorXd>> out(patches.size(), Result<Eigen::VectorXd>(Status::Error("not run")));
  for (std::size_t p = 0; p < patches.size(); ++p) {
    const auto first = each.begin() + static_cast<std::ptrdiff_t>(p * n_runs);
    const auto failed = std::find_if(first, first + static_cast<std::ptrdiff_t>(n_runs),
                                     [](const Result<Eigen::VectorXd>& r) { return !r.ok(); });
    std::vector<Eigen::VectorXd> per_run;
    if (failed == first + static_cast<std::ptrdiff_t>(n_runs))
      for (auto r = first; r != failed; ++r) per_run.push_back(std::move(*r).value());
    out[p] = failed != first + static_cast<std::ptrdiff_t>(n_runs)
                 ? failed->status()
                 : Result<Eigen::VectorXd>(Concatenated(runs_of_, per_run));
  }
  return out;
}

Result<ScoreTest> PredictedDrop(const TwinCandidate& c, const Eigen::VectorXd& base, TwinEvaluator* evaluator,
                                const FitSettings& settings) {
  Eigen::VectorXd theta = NeutralValues(c);
  if (c.time_shift) {
    const double shift_s = c.free.front().hi > 0.0 ? settings.physics_step_s : -settings.physics_step_s;
    theta[0] = shift_s;
    auto r = evaluator->Run({EffectsAt(c, theta)});
    if (!r[0].ok()) return Status::Error(c.label + ": a shifted twin: " + r[0].status().message());
    const Eigen::VectorXd d = (Masked(r[0].value(), base) - Masked(base, base)) / shift_s;
    const Eigen::VectorXd b = Masked(base, base);
    return ScoreTest{d.squaredNorm() > 0.0 ? std::pow(d.dot(b), 2) / d.squaredNorm() : 0.0, 1};
  }
  auto J = Jacobian(Parts({c}), theta, base, settings.threads, evaluator);
  if (!J.ok()) return J.status();
  const std::vector<bool> informed = Informed(c, J.value());
  std::vector<int> columns;
  for (std::size_t j = 0; j < informed.size(); ++j)
    if (informed[j]) columns.push_back(static_cast<int>(j));
  const Eigen::MatrixXd Ji = J.value()(Eigen::all, columns);
  const Eigen::VectorXd g = Ji.transpose() * Masked(base, base);
  const Eigen::MatrixXd H = Ji.transpose() * Ji;
  return ScoreTest{columns.empty() ? 0.0 : g.dot(H.completeOrthogonalDecomposition().solve(g)),
                   static_cast<int>(columns.size())};
}

Result<CandidateOutcome> FitCandidate(const TwinCandidate& c, const Eigen::VectorXd& base, TwinEvaluator* evaluator,
                                      const FitSettings& settings) {
  if (c.time_shift) {
    auto out = SearchTimeShift(c, base, evaluator, settings);
    if (out.ok()) out.value().informed.assign(1, true);
    return out;
  }
  const Eigen::VectorXd neutral = NeutralValues(c);
  auto J = Jacobian(Parts({c}), neutral, base, settings.threads, evaluator);
  if (!J.ok()) return J.status();
  const std::vector<bool> informed = Informed(c, J.value());
  const TwinCandidate fitted = Reduced(c, informed);
  CandidateOutcome out;
  out.theta = neutral;
  if (fitted.free.empty()) {  // nothing to fit: the neutral values, the base residuals
    out.residuals = base;
    out.chi2 = SumOfSquares(base);
  } else {
    // The Jacobian at the neutral values is the first iteration's when every parameter is fitted; with fewer, the
    // reduced candidate's own (central differences when they now fit in the threads).
    const bool all = fitted.free.size() == c.free.size();
    auto fit =
        FitLeastSquares(Parts({fitted}), NeutralValues(fitted), base, evaluator, settings, all ? &J.value() : nullptr);
    if (!fit.ok()) return fit.status();
    for (std::size_t j = 0, f = 0; j < c.free.size(); ++j)
      if (informed[j]) out.theta[static_cast<Eigen::Index>(j)] = fit.value().theta[static_cast<Eigen::Index>(f++)];
    out.covariance = fit.value().covariance;
    out.chi2 = fit.value().chi2;
    out.residuals = fit.value().residuals;
    out.iterations = fit.value().iterations;
  }
  out.effects = EffectsAt(c, out.theta);
  out.informed = informed;
  return out;
}

Result<JointOutcome> FitJointly(const std::vector<TwinCandidate>& parts, const Eigen::VectorXd& start,
                                const Eigen::VectorXd& at_start, TwinEvaluator* evaluator,
                                const FitSettings& settings) {
  for (const TwinCandidate& c : parts)
    if (c.time_shift) return Status::Error(c.label + ": a time shift is not refitted jointly");
  const Parts joint(parts);
  if (start.size() != static_cast<Eigen::Index>(joint.free.size()))
    return Status::Error(joint.label + ": the start has " + std::to_string(start.size()) + " values for " +
                         std::to_string(joint.free.size()) + " parameters");
  auto fit = FitLeastSquares(joint, start, at_start, evaluator, settings, nullptr);
  if (!fit.ok()) return fit.status();
  JointOutcome out;
  out.theta = fit.value().theta;
  out.covariance = fit.value().covariance;
  out.effects = joint.PerCandidate(out.theta);
  out.chi2 = fit.value().chi2;
  out.iterations = fit.value().iterations;
  return out;
}

}  // namespace roamlab::gap::internal
