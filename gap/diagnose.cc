#include "gap/diagnose.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <set>
#include <sstream>

#include "common/chi_square.h"
#include "sim/simulator.h"

namespace roamlab::gap {
namespace {

using estimator::EstimatorConfig;
using recording::Recording;
using recording::StreamType;

// One candidate of the library, as it applies to a configuration.
struct Candidate {
  std::string name;
  std::string stream;                        // configured stream whose dispersion scales its statistic
  // A parameter-slot effect: estimator parameters freed, and how their values become the effect's parameters.
  std::vector<std::string> free;
  std::function<void(const std::map<std::string, Eigen::VectorXd>& value,
                     const std::map<std::string, Eigen::VectorXd>& std, EffectEstimate* out)>
      describe;
  // A time-shift effect: recording streams whose stamps move by the parameter (t' = t - shift). With `free` as well,
  // a clock offset fitted as a parameter (imu_time_offset: the IMU's time_offset_s, models/imu_time_offset.h), the
  // stamps moving by whole master periods only when the offset is beyond the first-order model's range.
  std::vector<std::string> shifted;
  std::string shift_parameter;
  double guess_s = 0.0;                      // first guess of the shift
  int free_dof = 0;                          // tangent dimension of `free`
};

// Makes `c` free the one scalar slot `parameter` of `stream`, reported as the simulator's `reported` =
// scale (value - offset), its std scale std.
void FreeOneSlot(const std::string& stream, const std::string& parameter, const std::string& reported, double scale,
                 double offset, Candidate* c) {
  c->stream = stream;
  c->free = {parameter};
  c->free_dof = 1;
  c->describe = [parameter, reported, scale, offset](const auto& value, const auto& std, EffectEstimate* e) {
    e->parameters[reported] = scale * (value.at(parameter)[0] - offset);
    if (std.count(parameter)) e->std[reported] = std::abs(scale) * std.at(parameter)[0];
  };
}

// How the fit treats the calibration parameters.
enum class FitMode {
  kStaged,   // the configuration's stages from its initial values
  kWarm,     // one stage, every free parameter plus the candidate's, from given values
  kFixed,    // every parameter fixed at given values; poses only
};

struct FitSpec {
  FitMode mode = FitMode::kStaged;
  std::map<std::string, Eigen::VectorXd> values;   // warm / fixed values (names absent: the configuration's)
  std::set<std::string> extra_free;                 // freed on top of the configuration's free parameters
  std::map<std::string, double> shift_s;            // recording stream -> seconds subtracted from its stamps
  bool keep_residuals = false;
  bool observability = false;
  const Trajectory* initial = nullptr;              // warm-start poses (estimator/calibration.h)
};

struct FitOutcome {
  double chi2 = 0.0;
  int measurements = 0;
  std::map<std::string, Eigen::VectorXd> values;   // every configured parameter (free ones estimated)
  std::map<std::string, Eigen::VectorXd> std;      // free ones, when observability was asked for
  std::vector<estimator::MeasurementResidual> residuals;
  Trajectory trajectory;
};

// The part of a recording in [t0, t1], cut so that a time shift up to margin_s never changes which measurements
// attach (a changing count would move the chi-square by whole measurements): the master stream's sources (the poses)
// lose margin_s at both ends, so that shifted samples of the other streams on the master's grid still find as many
// poses; streams in `position` (fixes attached to one pose, which constrain no attitude) lose 2 margin_s before any
// shift, so that they all stay inside the poses' span.
Recording Slice(const Recording& in, double t0, double t1, const std::set<std::string>& master,
                const std::set<std::string>& position, double margin_s) {
  Recording out;
  out.format_version = in.format_version;
  out.platform = in.platform;
  out.origin = in.origin;
  out.provenance = in.provenance;
  for (const recording::Stream& s : in.streams) {
    const double m = master.count(s.info.name) ? margin_s : position.count(s.info.name) ? 2.0 * margin_s : 0.0;
    recording::Stream c;
    c.info = s.info;
    std::vector<Eigen::Index> rows;
    for (std::size_t i = 0; i < s.t.size(); ++i) {
      const double t = s.t[i].seconds();
      if (t >= t0 + m && t <= t1 - m) rows.push_back(static_cast<Eigen::Index>(i));
    }
    c.values.resize(static_cast<Eigen::Index>(rows.size()), s.values.cols());
    for (std::size_t k = 0; k < rows.size(); ++k) {
      c.t.push_back(s.t[static_cast<std::size_t>(rows[k])]);
      c.values.row(static_cast<Eigen::Index>(k)) = s.values.row(rows[k]);
      if (!s.text.empty()) c.text.push_back(s.text[static_cast<std::size_t>(rows[k])]);
    }
    out.streams.push_back(std::move(c));
  }
  return out;
}

Recording Shifted(const Recording& in, const std::map<std::string, double>& shift_s) {
  Recording out = in;
  for (recording::Stream& s : out.streams) {
    const auto it = shift_s.find(s.info.name);
    if (it == shift_s.end() || it->second == 0.0) continue;
    const std::int64_t ns = std::llround(it->second * 1e9);
    for (Time& t : s.t) t = Time::FromNanoseconds(t.nanoseconds() - ns);
  }
  return out;
}

// The value of parameter `name` in a configuration (its initial value, or the model slot's default).
std::optional<Eigen::VectorXd> ConfiguredValue(const EstimatorConfig& config, const std::string& name) {
  const auto it = config.parameters.find(name);
  if (it != config.parameters.end() && it->second.value) return *it->second.value;
  for (const auto& [stream, sc] : config.streams) {
    const estimator::ModelSpec* spec = estimator::FindModelSpec(sc.model);
    if (!spec) continue;
    for (const estimator::SlotSpec& slot : spec->slots) {
      const auto mapped = sc.parameters.find(slot.name);
      const std::string full = mapped != sc.parameters.end() ? mapped->second : stream + "." + slot.name;
      if (full == name) return slot.default_value;
    }
  }
  return std::nullopt;
}

// The parameter a stream's slot maps to.
std::string SlotParameter(const std::string& stream, const estimator::StreamConfig& sc, const std::string& slot) {
  const auto mapped = sc.parameters.find(slot);
  return mapped != sc.parameters.end() ? mapped->second : stream + "." + slot;
}

constexpr double kWarmInitialLambda = 1e-11;

// A clock offset fitted as a parameter (imu_time_offset): the largest the first-order model is trusted with. The fit
// is of the streams' timing conventions too (on the nominal ATV simulation about +0.04 s: the estimator holds a
// gyroscope reading over the interval after its stamp, the simulator reads the rate at it), so it holds those plus
// the imu_time_offset draws (0.02-0.05 s); at 0.06 s the 30 ms test case and the baseline fell to the grid.
constexpr double kFirstOrderOffsetS = 0.1;
constexpr double kProfileStepS = 0.01;   // the profile's step: a master period of the 100 Hz drives

Result<FitOutcome> Fit(const EstimatorConfig& nominal, const Recording& recording, const FitSpec& spec) {
  EstimatorConfig config = nominal;
  std::vector<std::string> free;
  for (const auto& [name, p] : config.parameters)
    if (p.free) free.push_back(name);
  for (const std::string& name : spec.extra_free) {
    estimator::ParameterConfig& p = config.parameters[name];
    if (!p.value) p.value = ConfiguredValue(nominal, name);
    if (!p.free) free.push_back(name);
    p.free = true;
  }
  for (const auto& [name, value] : spec.values) config.parameters[name].value = value;
  if (spec.mode != FitMode::kStaged) config.stages.clear();
  if (spec.mode == FitMode::kWarm) config.stages.push_back(free);
  if (spec.mode == FitMode::kFixed)
    for (auto& [name, p] : config.parameters) p.free = false;

  // A warm or fixed fit starts next to its minimum: the staged fits' initial damping (relative to diag(H)) would
  // dominate the weakly determined directions (a few calibration parameters that trade against each other) and
  // Levenberg-Marquardt would spend a dozen iterations cutting it by 3 per step while the cost barely moves, or stop
  // there on the function tolerance before the minimum. A damping that small still rises if a step is rejected.
  if (spec.mode != FitMode::kStaged) config.solver.initial_lambda = kWarmInitialLambda;
  estimator::CalibrationOptions options;
  options.keep_residuals = spec.keep_residuals;
  options.analyze_observability = spec.observability;
  options.initial_trajectory = spec.initial;
  auto result = estimator::Calibrate(config, Shifted(recording, spec.shift_s), options);
  if (!result.ok()) return result.status();
  FitOutcome out;
  out.chi2 = 2.0 * result.value().final_cost;
  for (const auto& [name, p] : config.parameters)
    if (p.value) out.values[name] = *p.value;
  for (const estimator::ParameterEstimate& p : result.value().parameters) {
    out.values[p.name] = p.estimate;
    if (spec.observability) out.std[p.name] = p.std;
  }
  for (const auto& [stream, c] : result.value().counts) out.measurements += c.attached - c.rejected;
  out.residuals = std::move(result.value().residuals);
  out.trajectory = std::move(result.value().trajectory);
  return out;
}

// The candidates that apply to `config` and `recording`.
std::vector<Candidate> Library(const EstimatorConfig& config) {
  std::vector<Candidate> out;
  const auto is_free = [&](const std::string& name) {
    const auto it = config.parameters.find(name);
    return it != config.parameters.end() && it->second.free;
  };
  std::vector<std::string> gps, imu, pose;
  std::string gyro, ackermann, diff_drive, mecanum, magnetometer, pose_stream;
  for (const auto& [stream, sc] : config.streams) {
    if (sc.model == "absolute_pose") {
      pose.push_back(sc.sources.begin()->second);
      if (pose_stream.empty()) pose_stream = stream;
    }
    if (sc.model == "differential_drive" && diff_drive.empty()) diff_drive = stream;
    if (sc.model == "mecanum_drive" && mecanum.empty()) mecanum = stream;
    if (sc.model == "gps") gps.push_back(sc.sources.begin()->second);
    if (sc.model == "gyroscope" || sc.model == "accelerometer" || sc.model == "magnetometer")
      imu.push_back(sc.sources.begin()->second);
    if (sc.model == "gyroscope" && gyro.empty()) gyro = stream;
    if (sc.model == "ackermann" && ackermann.empty()) ackermann = stream;
    if (sc.model == "magnetometer" && sc.inputs.count("specific_force") && magnetometer.empty()) magnetometer = stream;
  }
  std::sort(imu.begin(), imu.end());
  imu.erase(std::unique(imu.begin(), imu.end()), imu.end());

  for (const std::string& name : CandidateNames()) {
    Candidate c;
    c.name = name;
    if (name == "gps_latency" && !gps.empty()) {
      c.stream = "gps";
      for (const auto& [stream, sc] : config.streams)
        if (sc.model == "gps") c.stream = stream;
      c.shifted = gps;
      c.shift_parameter = "latency_s";
    } else if (name == "imu_time_offset" && !imu.empty() && !gyro.empty()) {
      c.stream = gyro;
      c.shifted = imu;
      c.shift_parameter = "offset_s";
      // The gyroscope's and accelerometer's one time_offset_s parameter (the clock they share); streams with one each
      // keep the search on the grid of stamp shifts. The magnetometer keeps its own (the nominal models fix it at 0):
      // freed with the others it pulled the estimate toward 0 (README, imu_time_offset).
      std::set<std::string> offsets;
      for (const auto& [stream, sc] : config.streams)
        if (sc.model == "gyroscope" || sc.model == "accelerometer")
          offsets.insert(SlotParameter(stream, sc, "time_offset_s"));
      if (offsets.size() == 1 && !is_free(*offsets.begin())) {
        c.free = {*offsets.begin()};
        c.free_dof = 1;
      }
    } else if (name == "pose_time_offset" && !pose.empty() && config.streams.count(config.master) &&
               config.streams.at(config.master).model != "absolute_pose") {
      // The absolute pose stream (motion capture, SLAM) stamped late against the master (the wheel encoders): its
      // pose stamped t is the body's pose at t - offset.
      c.stream = pose_stream;
      c.shifted = pose;
      c.shift_parameter = "offset_s";
    } else if (name == "steering_offset" && !ackermann.empty()) {
      const std::string p = SlotParameter(ackermann, config.streams.at(ackermann), "k_gamma");
      if (is_free(p)) continue;
      FreeOneSlot(ackermann, p, "offset_rad", 1.0, ConfiguredValue(config, p).value_or(Eigen::VectorXd::Zero(1))[0],
                  &c);
    } else if (name == "axle_misalignment" && !ackermann.empty()) {
      // The rear axle's thrust angle alpha (models/ackermann_velocity.h: the rear axle rolls along alpha, so the
      // vehicle crabs by alpha and turns at -v tan(alpha) / L at zero handlebar) freed from the nominal model's zero;
      // reported as the simulator's axle_misalignment on the Ackermann rear axle, yaw_deg = alpha in degrees. Its turn
      // is a steering offset's to first order (k_gamma = -alpha); only the crab tells them apart, and it shows only
      // against a heading tied to the chassis: the candidate applies when the gyroscope's mounting is believed
      // (its misalignment fixed). With it free, a rotation of O by alpha absorbs the crab, only alpha sin^2(delta)
      // on the steering row is left, and on the 30 s ATV drive both candidates fit to within a chi2 of 2
      // (README, tests/gap/axle_diagnose_slow_test.cc): the candidate would only duplicate steering_offset.
      const std::string p = SlotParameter(ackermann, config.streams.at(ackermann), "thrust_angle");
      if (is_free(p) || gyro.empty() || is_free(SlotParameter(gyro, config.streams.at(gyro), "misalignment")))
        continue;
      FreeOneSlot(ackermann, p, "yaw_deg", 180.0 / 3.14159265358979323846, 0.0, &c);
    } else if ((name == "gyro_scale_error" || name == "gyro_bias_drift") && !gyro.empty()) {
      // gyro_scale_error: the per-axis scale k_s (models/gyroscope.h: z = k_s o omega + b + eta) freed from 1,
      // reported as scale_x/y/z. gyro_bias_drift: the bias b [rad/s] freed from the nominal model's zero as one
      // constant over the fitted part: a bias that wanders slowly is seen as its mean there, and the
      // held-out test checks that the same value still explains the rest of the run. Reported as the simulator's
      // initial_x/y/z.
      const bool scale = name == "gyro_scale_error";
      const std::string p = SlotParameter(gyro, config.streams.at(gyro), scale ? "scale" : "bias");
      if (is_free(p)) continue;
      c.stream = gyro;
      c.free = {p};
      c.free_dof = 3;
      c.describe = [p, prefix = std::string(scale ? "scale_" : "initial_")](const auto& value, const auto& std,
                                                                            EffectEstimate* e) {
        for (int i = 0; i < 3; ++i) {
          const std::string key = prefix + "xyz"[i];
          e->parameters[key] = value.at(p)[i];
          if (std.count(p)) e->std[key] = std.at(p)[i];
        }
      };
    } else if (name == "wheel_radius_asymmetry" && !diff_drive.empty()) {
      // The right/left radius ratio rho (models/differential_drive.h): meaningful when the nominal model believes the
      // wheels equal, i.e. maps both radius slots to one parameter.
      const estimator::StreamConfig& sc = config.streams.at(diff_drive);
      const std::string p = SlotParameter(diff_drive, sc, "right_left_ratio");
      if (is_free(p) || SlotParameter(diff_drive, sc, "radius_left") != SlotParameter(diff_drive, sc, "radius_right"))
        continue;
      FreeOneSlot(diff_drive, p, "ratio_right_left", 1.0, 0.0, &c);
    } else if (name == "wheel_deformation" && !diff_drive.empty()) {
      // Tires that are not round: both wheels' second harmonic of the rolling radius (a, b) freed from zero
      // (models/differential_drive.h). Reported as the simulator's effect: the wheel with the larger amplitude
      // (0 left, 1 right) and its ovality d = 2 sqrt(a^2 + b^2), std by first-order propagation.
      const estimator::StreamConfig& sc = config.streams.at(diff_drive);
      const std::string left = SlotParameter(diff_drive, sc, "deformation_left");
      const std::string right = SlotParameter(diff_drive, sc, "deformation_right");
      if (is_free(left) || is_free(right) || left == right) continue;
      c.stream = diff_drive;
      c.free = {left, right};
      c.free_dof = 4;
      c.describe = [left, right](const auto& value, const auto& std, EffectEstimate* e) {
        const Eigen::Vector2d l = value.at(left), r = value.at(right);
        const bool right_wheel = r.norm() > l.norm();
        const Eigen::Vector2d ab = right_wheel ? r : l;
        e->parameters["wheel"] = right_wheel ? 1.0 : 0.0;
        e->parameters["ovality_m"] = 2.0 * ab.norm();
        const std::string& p = right_wheel ? right : left;
        if (std.count(p) && ab.norm() > 0.0)
          e->std["ovality_m"] = 2.0 * std::hypot(ab[0] * std.at(p)[0], ab[1] * std.at(p)[1]) / ab.norm();
      };
    } else if (name == "track_width_error" && !diff_drive.empty()) {
      // The effective track B (for a skid-steer robot, what makes the wheel speeds' difference turn it at the rate it
      // does), freed from the nominal geometry; reported as the departure from it.
      const std::string p = SlotParameter(diff_drive, config.streams.at(diff_drive), "baseline");
      const std::optional<Eigen::VectorXd> nominal = ConfiguredValue(config, p);
      if (is_free(p) || !nominal || !std::isfinite((*nominal)[0])) continue;
      FreeOneSlot(diff_drive, p, "track_error_m", 1.0, (*nominal)[0], &c);
    } else if (name == "track_width_error" && !mecanum.empty()) {
      // The mecanum wheels' yaw lever arm K = lx + ly (models/mecanum_drive.h) freed from the nominal geometry. The
      // simulator's effect moves the wheels apart along O's y by track_error_m, half on each side: ly, hence K,
      // grows by track_error_m / 2 (sim/wheeled_robot.h ChangeTrack), so track_error_m = 2 (K - K_nominal) and its
      // std is 2 std(K). (omni3 has no such effect in the simulator, so no candidate.) K is told from the common
      // radius only with a translation reference (position fixes): the wheel rows give v / r and K omega_z / r, the
      // gyroscope K / r; without one the fit leaves K where it is and no std (NominalHolonomicConfig).
      const std::string p = SlotParameter(mecanum, config.streams.at(mecanum), "lx_plus_ly");
      const std::optional<Eigen::VectorXd> nominal = ConfiguredValue(config, p);
      if (is_free(p) || !nominal || !std::isfinite((*nominal)[0])) continue;
      FreeOneSlot(mecanum, p, "track_error_m", 2.0, (*nominal)[0], &c);
    } else if (name == "lateral_slip" && !ackermann.empty()) {
      const std::string front = SlotParameter(ackermann, config.streams.at(ackermann), "cornering_front");
      const std::string rear = SlotParameter(ackermann, config.streams.at(ackermann), "cornering_rear");
      if (is_free(front) || is_free(rear)) continue;
      c.stream = ackermann;
      c.free = {front, rear};
      c.free_dof = 2;
      c.describe = [front, rear](const auto& value, const auto& std, EffectEstimate* e) {
        e->parameters["cornering_front_rads2pm"] = value.at(front)[0];
        e->parameters["cornering_rear_s"] = value.at(rear)[0];
        if (std.count(front)) e->std["cornering_front_rads2pm"] = std.at(front)[0];
        if (std.count(rear)) e->std["cornering_rear_s"] = std.at(rear)[0];
      };
    } else if ((name == "longitudinal_slip" && !ackermann.empty() &&
                config.streams.at(ackermann).inputs.count("specific_force")) ||
               (name == "slope_slip" && !ackermann.empty())) {
      // The driven tires' slip (models/ackermann_velocity.h): the rear-wheel speed over-reads the ground speed by
      // 1 + s_f f_x (longitudinal_slip: f_x the forward specific force read from the IMU, the traction per unit mass)
      // or 1 + s_p g sin(pitch) (slope_slip: the slope alone, from the poses' attitude), the slot freed from zero and
      // reported as the simulator's slip_per_mps2. The null is the baseline's value (what MuJoCo's soft contacts
      // and the nominal model's other gaps put there without an effect).
      const std::string p = SlotParameter(ackermann, config.streams.at(ackermann),
                                          name == "slope_slip" ? "slope_slip_per_mps2" : "slip_per_mps2");
      if (is_free(p)) continue;
      FreeOneSlot(ackermann, p, "slip_per_mps2", 1.0, 0.0, &c);
    } else if (name == "magnetometer_motor_interference" && !magnetometer.empty()) {
      // The magnetometer's bias per N m of drive torque k (models/magnetometer.h) freed from zero, on the proxy
      // tau_hat = c f_x (forward specific force, c = m r / 2 from the nominal vehicle): reported as the simulator's
      // b_per_nm_x/y/z directly. The proxy ignores rolling resistance (a constant: absorbed by b) and what else the
      // torque does than pull the vehicle (spinning the wheels up, slip): on the nominal ATV drive the true torque
      // regresses on f_x with slope 47.0 N m s^2/m against c = 49.6 (rho 0.992), so k comes out about 5 % low.
      const std::string p = SlotParameter(magnetometer, config.streams.at(magnetometer), "b_per_drive_nm");
      if (is_free(p)) continue;
      c.stream = magnetometer;
      c.free = {p};
      c.free_dof = 3;
      c.describe = [p](const auto& value, const auto& std, EffectEstimate* e) {
        for (int i = 0; i < 3; ++i) {
          const std::string key = std::string("b_per_nm_") + "xyz"[i];
          e->parameters[key] = value.at(p)[i];
          if (std.count(p)) e->std[key] = std.at(p)[i];
        }
      };
    } else {
      continue;
    }
    out.push_back(std::move(c));
  }
  return out;
}

// The master stream's sample period [s] (the pose grid).
double MasterPeriod(const EstimatorConfig& config, const Recording& recording) {
  const auto it = config.streams.find(config.master);
  if (it == config.streams.end() || it->second.sources.empty()) return 0.01;
  const recording::Stream* s = recording.Find(it->second.sources.begin()->second);
  if (!s || s->t.size() < 2) return 0.01;
  return SecondsBetween(s->t.front(), s->t.back()) / static_cast<double>(s->t.size() - 1);
}

// The state the rounds build on: accepted effects and their fits.
struct State {
  std::set<std::string> extra_free;
  std::map<std::string, double> shift_s;
  std::map<std::string, Eigen::VectorXd> train_values;
  Trajectory train_trajectory;
  double train_chi2 = 0.0;
  int train_measurements = 0;
  double heldout_chi2 = 0.0;
  std::map<std::string, StreamFit> heldout;
  std::map<std::string, ComponentLevel> heldout_components;
};

// A candidate fitted on the training part on top of `state`.
struct CandidateFit {
  EffectEstimate estimate;
  State next;
};

// Neutral value of an effect parameter (what the nominal model assumes).
double Neutral(const std::string& parameter) {
  return parameter.rfind("scale_", 0) == 0 || parameter.rfind("ratio_", 0) == 0 ? 1.0 : 0.0;
}

// The likelihood-ratio test and BIC of a fitted candidate, and its parameters relative to the baseline.
// Without a baseline the null hypothesis is the nominal model (parameters at their neutral values): LR = the chi2 drop
// ~ chi2(k). With one, the nominal model's own structure already moves the candidate's parameters on MuJoCo data
// without any effect (e.g. the tires' cornering compliance: c_rear = 0.008 +- 0.002 s on the nominal ATV
// simulation): the null hypothesis is then "the parameters take the baseline's values theta_0", and LR is its quadratic
// (Wald) form about the fit, sum ((theta - theta_0)^2 / (sigma^2 + sigma_0^2)) with both fits' standard deviations,
// ~ chi2(k); a theta_0 within 2 sigma_0 of neutral shows no structure, and the test is then against neutral with
// the fit's own variance (one noisy draw of nothing would only blur it). The parameters are always reported as
// departures from theta_0 plus the neutral value, both variances added (so that the reported std covers the error).
void Score(const Baseline* baseline, int measurements, EffectEstimate* e) {
  const double k = e->dof;
  e->lr = e->lr_raw;
  if (baseline && baseline->candidate_parameters.count(e->name)) {
    const auto base = baseline->candidate_parameters.find(e->name);
    if (baseline->candidate_lr.count(e->name)) e->baseline_lr = baseline->candidate_lr.at(e->name);
    double wald = 0.0;
    bool finite = true;
    for (auto& [name, value] : e->parameters) {
      // Parameters without a std are labels (wheel_deformation's wheel index), neither tested nor shifted.
      if (!base->second.count(name) || !e->std.count(name)) continue;
      const auto [theta0, sigma0] = base->second.at(name);
      e->baseline_parameters[name] = theta0;
      const double raw = value;
      const double raw_sigma = e->std.count(name) ? e->std.at(name) : NAN;
      // Reported: the departure from the baseline, both variances.
      value = raw - theta0 + Neutral(name);
      e->std[name] = std::hypot(raw_sigma, sigma0);
      // Tested: against theta_0 when the baseline shows structure (beyond 2 sigma_0 from neutral), else against
      // neutral with the fit's own variance (one noisy draw of nothing would only blur the test).
      const bool structure = std::abs(theta0 - Neutral(name)) > 2.0 * sigma0;
      const double null = structure ? theta0 : Neutral(name);
      const double sigma = structure ? std::hypot(raw_sigma, sigma0) : raw_sigma;
      finite = finite && std::isfinite(sigma) && sigma > 0.0;
      if (finite) wald += std::pow((raw - null) / sigma, 2);
    }
    e->lr = finite ? wald : 0.0;
  }
  e->lr_pvalue = e->lr > 0.0 ? 1.0 - ChiSquareCdf(e->lr, k) : 1.0;
  e->delta_bic = -e->lr + k * std::log(std::max(2, measurements));
}

}  // namespace

const std::vector<std::string>& CandidateNames() {
  static const std::vector<std::string> names = {
      "gps_latency",  "imu_time_offset",        "pose_time_offset",  "steering_offset",
      "gyro_scale_error", "gyro_bias_drift", "lateral_slip", "wheel_radius_asymmetry", "track_width_error",
      "wheel_deformation", "axle_misalignment", "magnetometer_motor_interference", "longitudinal_slip", "slope_slip"};
  return names;
}

namespace {

// A stream of the recording's `imu` with its noise and the IMU's shared misalignment and clock offset.
estimator::StreamConfig ImuStream(const std::string& model, const std::string& noise_key, double sigma) {
  estimator::StreamConfig stream;
  stream.model = model;
  stream.sources = {{"", "imu"}};
  stream.noise = {{noise_key, sigma}};
  stream.parameters = {{"misalignment", "imu.misalignment"}, {"time_offset_s", "imu.time_offset_s"}};
  return stream;
}

// The nominal model of a differential-drive scenario: the wheel encoders (master, differential_drive) with the
// robot's geometry measured on its model (sim::NominalPlatformGeometry): one radius for both wheels, free (the
// odometry's scale), the baseline fixed (a track_width_error is a departure from it), the right/left ratio at its
// default 1; the gyroscope (the yaw reference) with the scenario's noise and misalignment free. Encoder noise as
// configs/indoor_diffdrive_tracking.yaml (2048-tick quantization over 10 ms, the casters' slack), no robust loss
// (the chi-square comparisons need Gaussian costs).
Result<estimator::EstimatorConfig> NominalDiffDriveConfig(const sim::Scenario& scenario) {
  const sim::SensorOptions& s = scenario.sensors;
  if (!s.wheel_encoders) return Status::Error("the scenario has no wheel_encoders (the master stream)");
  if (!s.imu) return Status::Error("the differential-drive nominal model needs sensors.imu (the yaw reference)");
  auto geometry = sim::NominalPlatformGeometry(scenario);
  if (!geometry.ok()) return geometry.status();
  EstimatorConfig c;
  c.source_file = scenario.source_file.empty() ? "nominal configuration" : scenario.source_file + " (nominal)";
  c.master = "odometer";
  c.solver.max_iterations = 100;
  c.solver.function_tolerance = 1e-10;
  const auto param = [&](const std::string& name, const Eigen::VectorXd& value, bool free) {
    c.parameters[name].value = value;
    c.parameters[name].free = free;
  };
  estimator::StreamConfig odo;
  odo.model = "differential_drive";
  odo.sources = {{"", "wheel_encoders"}};
  odo.noise = {{"wheel_radps", 0.15}, {"lateral_mps", 0.02}, {"vertical_mps", 0.02}, {"tilt_radps", 0.1}};
  odo.parameters = {{"radius_left", "odometer.radius"}, {"radius_right", "odometer.radius"}};
  c.streams["odometer"] = odo;
  param("odometer.radius", Eigen::VectorXd::Constant(1, geometry.value().at("wheel_radius_m")), true);
  param("odometer.baseline", Eigen::VectorXd::Constant(1, geometry.value().at("baseline_m")), false);
  const Eigen::Quaterniond& q = s.imu->misalignment;
  param("imu.misalignment", (Eigen::VectorXd(4) << q.w(), q.x(), q.y(), q.z()).finished(), true);
  c.streams["gyroscope"] = ImuStream("gyroscope", "sigma_radps", s.imu->gyro_sigma_radps);
  c.stages.push_back({"imu.misalignment", "odometer.radius"});
  return c;
}

// The nominal model of an omni3 or mecanum scenario, as NominalDiffDriveConfig: the wheel encoders (master, the
// omni3_drive or mecanum_drive model) with the platform geometry measured on the robot's model
// (sim::NominalPlatformGeometry): one radius for all wheels, free (the odometry's scale), the yaw lever arm fixed
// (omni3 `distance` = wheel_distance_m; mecanum `lx_plus_ly` = half_length_m + half_width_m: a track_width_error is a
// departure from it); the gyroscope (the yaw reference) with the scenario's noise and misalignment free. Encoder noise
// as configs/indoor_omni_tracking.yaml (quantization plus the rollers' bumps; the rollers rock the chassis), no
// robust loss (the chi-square comparisons need Gaussian costs).
Result<estimator::EstimatorConfig> NominalHolonomicConfig(const sim::Scenario& scenario) {
  const sim::SensorOptions& s = scenario.sensors;
  const bool omni3 = scenario.robot.kind == "omni3";
  if (!s.wheel_encoders) return Status::Error("the scenario has no wheel_encoders (the master stream)");
  if (!s.imu)
    return Status::Error("the " + scenario.robot.kind + " nominal model needs sensors.imu (the yaw reference)");
  auto geometry = sim::NominalPlatformGeometry(scenario);
  if (!geometry.ok()) return geometry.status();
  const std::map<std::string, double>& g = geometry.value();
  EstimatorConfig c;
  c.source_file = scenario.source_file.empty() ? "nominal configuration" : scenario.source_file + " (nominal)";
  c.master = "odometer";
  c.solver.max_iterations = 100;
  c.solver.function_tolerance = 1e-10;
  const auto param = [&](const std::string& name, const Eigen::VectorXd& value, bool free) {
    c.parameters[name].value = value;
    c.parameters[name].free = free;
  };
  estimator::StreamConfig odo;
  odo.model = omni3 ? "omni3_drive" : "mecanum_drive";
  odo.sources = {{"", "wheel_encoders"}};
  odo.noise = {{"wheel_radps", 0.3}, {"vertical_mps", 0.02}, {"tilt_radps", 0.1}};
  for (int i = 0; i < (omni3 ? 3 : 4); ++i) odo.parameters["radius_" + std::to_string(i)] = "odometer.radius";
  c.streams["odometer"] = odo;
  param("odometer.radius", Eigen::VectorXd::Constant(1, g.at("wheel_radius_m")), true);
  if (omni3) {
    param("odometer.distance", Eigen::VectorXd::Constant(1, g.at("wheel_distance_m")), false);
  } else {
    param("odometer.lx_plus_ly", Eigen::VectorXd::Constant(1, g.at("half_length_m") + g.at("half_width_m")), false);
  }
  const Eigen::Quaterniond& q = s.imu->misalignment;
  param("imu.misalignment", (Eigen::VectorXd(4) << q.w(), q.x(), q.y(), q.z()).finished(), true);
  c.streams["gyroscope"] = ImuStream("gyroscope", "sigma_radps", s.imu->gyro_sigma_radps);
  c.stages.push_back({"imu.misalignment", "odometer.radius"});
  // An absolute position reference (an indoor positioning system, as sensors.gps) when the scenario has one: with
  // the encoders and the gyroscope alone the translation has no reference, and the wheel rows give only v / r and
  // K omega_z / r, so the gyroscope fixes K / r and nothing fixes r and K apart; the fixes fix v, hence r. Its lever
  // arm is fixed at the scenario's value (the antenna's mounting is believed).
  if (s.gps) {
    estimator::StreamConfig gps;
    gps.model = "gps";
    gps.sources = {{"", "gps"}};
    gps.noise = {{"sigma_m", s.gps->sigma_m}};
    c.streams["gps"] = gps;
    const Eigen::Vector3d& l = s.gps->lever_arm_m;
    param("gps.lever_arm", (Eigen::VectorXd(3) << l.x(), l.y(), l.z()).finished(), false);
  }
  return c;
}

}  // namespace

Result<estimator::EstimatorConfig> NominalConfig(const sim::Scenario& scenario) {
  if (scenario.robot.kind == "differential_drive") return NominalDiffDriveConfig(scenario);
  if (scenario.robot.kind == "omni3" || scenario.robot.kind == "mecanum") return NominalHolonomicConfig(scenario);
  if (scenario.robot.kind != "ackermann")
    return Status::Error("the nominal configuration is implemented for ackermann, differential_drive, omni3 and "
                         "mecanum robots only, not '" + scenario.robot.kind + "'");
  const sim::SensorOptions& s = scenario.sensors;
  if (!s.odometer) return Status::Error("the scenario has no odometer (the master stream)");
  EstimatorConfig c;
  c.source_file = scenario.source_file.empty() ? "nominal configuration" : scenario.source_file + " (nominal)";
  c.master = "odometer";
  c.solver.max_iterations = 100;
  c.solver.function_tolerance = 1e-10;
  const auto vec = [](std::initializer_list<double> v) {
    Eigen::VectorXd x(static_cast<Eigen::Index>(v.size()));
    Eigen::Index i = 0;
    for (double d : v) x[i++] = d;
    return x;
  };
  const auto param = [&](const std::string& name, const Eigen::VectorXd& value, bool free) {
    c.parameters[name].value = value;
    c.parameters[name].free = free;
  };
  std::vector<std::string> stage1, stage2;
  {
    estimator::StreamConfig odo;
    odo.model = "ackermann";
    odo.sources = {{"speed", "rear_wheel"}, {"steering", "steering"}};
    // lateral / vertical: eq. 15's non-holonomic assumptions on a suspended vehicle (configs/atv_calibration.yaml).
    odo.noise = {{"speed_mps", s.odometer->speed_sigma_mps},
                 {"steering_rad", s.odometer->steering_sigma_rad},
                 {"lateral_mps", 0.02},
                 {"vertical_mps", 0.1}};
    c.streams["odometer"] = odo;
    param("odometer.kv_over_L", vec({s.odometer->kv_over_L}), true);
    param("odometer.k_theta", vec({s.odometer->k_theta}), true);
    param("odometer.k_gamma", vec({s.odometer->k_gamma}), false);
    stage2.insert(stage2.end(), {"odometer.kv_over_L", "odometer.k_theta"});
  }
  if (s.imu) {
    const Eigen::Quaterniond& q = s.imu->misalignment;
    param("imu.misalignment", vec({q.w(), q.x(), q.y(), q.z()}), true);
    stage1.push_back("imu.misalignment");
    c.streams["gyroscope"] = ImuStream("gyroscope", "sigma_radps", s.imu->gyro_sigma_radps);
    c.streams["accelerometer"] = ImuStream("accelerometer", "sigma_mps2", s.imu->accel_sigma_mps2);
    // The longitudinal slip's input (models/ackermann_velocity.h; its slot fixed at zero nominally): the IMU's
    // specific force along O's forward axis, which the believed mounting puts at R(q)^T e_x in the IMU's frame.
    const Eigen::Vector3d forward_in_imu = q.conjugate() * Eigen::Vector3d::UnitX();
    c.streams["odometer"].inputs = {{"specific_force", "imu"}};
    c.streams["odometer"].options["forward_in_sensor"] = {forward_in_imu.x(), forward_in_imu.y(), forward_in_imu.z()};
    if (!s.imu->lever_arm_m.isZero(0.0)) {
      const Eigen::Vector3d& l = s.imu->lever_arm_m;
      param("accelerometer.lever_arm", vec({l.x(), l.y(), l.z()}), false);
    }
  }
  if (s.magnetometer && s.imu) {
    estimator::StreamConfig mag;
    mag.model = "magnetometer";
    mag.sources = {{"", "magnetometer"}};
    mag.noise = {{"sigma", s.magnetometer->sigma}};
    mag.parameters = {{"misalignment", "imu.misalignment"}};
    const Eigen::Vector3d& h = s.magnetometer->field_world;
    mag.options = {{"field_world", {h.x(), h.y(), h.z()}}};
    // The drive torque's proxy of the motor-interference slot (models/magnetometer.h), fixed at zero nominally: the
    // IMU's specific force, with c = m r / 2 (the rear wheels' common torque tau gives the traction 2 tau / r) from
    // the nominal vehicle's mass and rear tire radius.
    auto mass = sim::NominalVehicleMassKg(scenario);
    if (!mass.ok()) return mass.status();
    auto geometry = sim::NominalPlatformGeometry(scenario);
    if (!geometry.ok()) return geometry.status();
    mag.inputs = {{"specific_force", "imu"}};
    mag.options["drive_nm_per_mps2"] = {mass.value() * geometry.value().at("wheel_radius_m") / 2.0};
    c.streams["magnetometer"] = mag;
    const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> A = s.magnetometer->A;
    param("magnetometer.A", Eigen::Map<const Eigen::VectorXd>(A.data(), 9), true);
    const Eigen::Vector3d& b = s.magnetometer->b;
    param("magnetometer.b", vec({b.x(), b.y(), b.z()}), true);
    stage2.insert(stage2.end(), {"magnetometer.A", "magnetometer.b"});
  }
  if (s.gps) {
    estimator::StreamConfig gps;
    gps.model = "gps";
    gps.sources = {{"", "gps"}};
    gps.noise = {{"sigma_m", s.gps->sigma_m}};
    c.streams["gps"] = gps;
    const Eigen::Vector3d& l = s.gps->lever_arm_m;
    param("gps.lever_arm", vec({l.x(), l.y(), l.z()}), true);
    stage1.insert(stage1.begin(), "gps.lever_arm");
  }
  // Stages as configs/atv_calibration.yaml: attitude and lever arm, then the rest, then all jointly.
  std::vector<std::string> all = stage1;
  all.insert(all.end(), stage2.begin(), stage2.end());
  if (!stage1.empty()) c.stages.push_back(stage1);
  if (!stage2.empty()) c.stages.push_back(stage2);
  c.stages.push_back(all);
  return c;
}

double HeldoutExcess(const std::map<std::string, ComponentLevel>& components, const std::vector<std::string>& keys,
                     const std::map<std::string, double>& expected) {
  double excess = 0.0;
  for (const std::string& key : keys) {
    const auto c = components.find(key);
    if (c == components.end()) continue;
    const auto level = expected.find(key);
    const double nominal = level != expected.end() ? level->second : 1.0;
    excess += std::max(0.0, (c->second.chi2_per_dof - nominal) * c->second.count);
  }
  return excess;
}

double ExplainedShare(double heldout_drop, double remaining_excess) {
  if (!(heldout_drop > 0.0)) return 0.0;
  return heldout_drop / (heldout_drop + std::max(0.0, remaining_excess));
}

Baseline BaselineFrom(const Diagnosis& nominal_simulation) {
  Baseline b;
  b.component_levels = ComponentLevels(nominal_simulation.residuals);
  for (const auto& [key, level] : nominal_simulation.heldout_components_before)
    b.heldout_component_levels[key] = level.chi2_per_dof;
  b.streams = nominal_simulation.whole_run;
  for (const EffectEstimate& e : nominal_simulation.candidates) {
    b.candidate_lr[e.name] = e.lr_raw;
    for (const auto& [name, value] : e.parameters)
      b.candidate_parameters[e.name][name] = {value, e.std.count(name) ? e.std.at(name) : 0.0};
  }
  return b;
}

Result<Diagnosis> Diagnose(const EstimatorConfig& nominal_in, const Recording& recording,
                           const DiagnoseOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const auto say = [&](const std::string& line) {
    if (options.progress) options.progress(line);
  };
  EstimatorConfig nominal = nominal_in;
  nominal.gate_probability.reset();   // the same measurements in every fit
  Diagnosis out;

  // The recording's span (the master stream's) and the split into training and held-out parts.
  const auto master = nominal.streams.find(nominal.master);
  if (master == nominal.streams.end() || master->second.sources.empty())
    return Status::Error(nominal.source_file + ": master stream '" + nominal.master + "' is not configured");
  const recording::Stream* master_stream = recording.Find(master->second.sources.begin()->second);
  if (!master_stream || master_stream->t.size() < 10)
    return Status::Error("the recording has no (or too short a) '" + master->second.sources.begin()->second +
                         "' stream for the master '" + nominal.master + "'");
  const double t0 = master_stream->t.front().seconds();
  const double t1 = master_stream->t.back().seconds();
  const double t_split = t0 + options.train_fraction * (t1 - t0);
  out.train_end_s = t_split;
  const double period = MasterPeriod(nominal, recording);
  std::vector<Candidate> library = Library(nominal);
  std::set<std::string> master_sources, position;
  for (const auto& [role, source] : master->second.sources) master_sources.insert(source);
  for (const auto& [name, sc] : nominal.streams)
    if (sc.model == "gps") position.insert(sc.sources.begin()->second);
  const double margin = options.max_shift_s;
  const Recording whole = Slice(recording, t0, t1, master_sources, position, margin);
  const Recording train = Slice(recording, t0, t_split, master_sources, position, margin);
  const Recording test = Slice(recording, t_split, t1, master_sources, position, margin);

  // 1. Replay: the nominal self-calibration of the whole recording, with its residuals.
  say("replay: nominal self-calibration of the whole recording");
  FitSpec whole_spec;
  whole_spec.keep_residuals = true;
  auto whole_fit = Fit(nominal, whole, whole_spec);
  ++out.fits;
  if (!whole_fit.ok()) return Status::Error("nominal calibration: " + whole_fit.status().message());
  say("replay: chi2 " + std::to_string(whole_fit.value().chi2) + " over " +
      std::to_string(whole_fit.value().measurements) + " measurements");
  out.residuals = whole_fit.value().residuals;
  out.whole_run = StreamFits(out.residuals);
  out.nominal_parameters = whole_fit.value().values;
  out.conditions = ComputeConditions(whole_fit.value().trajectory, recording);

  // First guess of a GPS latency: the fix stamped t is p(t - tau), so e = z_hat - z ~ tau v(t) (eq. 9), and tau is
  // the least-squares slope of the residuals on the horizontal velocity.
  for (Candidate& c : library) {
    if (c.name != "gps_latency") continue;
    const auto noise = nominal.streams.at(c.stream).noise;
    const double sigma = noise.count("sigma_m") ? noise.at("sigma_m") : 1.0;
    const auto east = std::find(out.conditions.names.begin(), out.conditions.names.end(), "v_east_mps");
    const int ce = static_cast<int>(east - out.conditions.names.begin());
    double ev = 0.0, vv = 0.0;
    for (const estimator::MeasurementResidual& r : out.residuals) {
      if (r.stream != c.stream || !r.active || r.whitened.size() < 2 || out.conditions.t.empty()) continue;
      const Eigen::Vector2d v(out.conditions.At(ce, r.t), out.conditions.At(ce + 1, r.t));
      ev += sigma * r.whitened.head<2>().dot(v);
      vv += v.squaredNorm();
    }
    c.guess_s = vv > 0.0 ? ev / vv : 0.0;
  }

  // 2. Locate.
  const std::map<std::string, double> levels =
      options.baseline ? options.baseline->component_levels : std::map<std::string, double>{};
  out.located = Locate(out.residuals, out.conditions, levels);

  // The training and held-out nominal fits.
  auto train_fit = Fit(nominal, train, {});
  ++out.fits;
  if (!train_fit.ok()) return Status::Error("nominal calibration (training part): " + train_fit.status().message());
  State state;
  state.train_values = train_fit.value().values;
  out.training_parameters_before = state.train_values;
  state.train_trajectory = train_fit.value().trajectory;
  state.train_chi2 = train_fit.value().chi2;
  state.train_measurements = train_fit.value().measurements;
  Trajectory heldout_trajectory;
  // The held-out part with every parameter fixed at the training values of `s`: chi2, per stream and per component.
  struct HeldOut {
    double chi2 = 0.0;
    std::map<std::string, StreamFit> streams;
    std::map<std::string, ComponentLevel> components;
  };
  const auto heldout = [&](const State& s) -> Result<HeldOut> {
    FitSpec spec;
    spec.initial = heldout_trajectory.empty() ? nullptr : &heldout_trajectory;
    spec.mode = FitMode::kFixed;
    spec.values = s.train_values;
    spec.shift_s = s.shift_s;
    spec.keep_residuals = true;
    auto fit = Fit(nominal, test, spec);
    ++out.fits;
    if (!fit.ok()) return fit.status();
    if (heldout_trajectory.empty()) heldout_trajectory = fit.value().trajectory;
    return HeldOut{fit.value().chi2, StreamFits(fit.value().residuals), ComponentStatistics(fit.value().residuals)};
  };
  {
    auto h = heldout(state);
    if (!h.ok()) return Status::Error("held-out evaluation: " + h.status().message());
    state.heldout_chi2 = h.value().chi2;
    state.heldout = h.value().streams;
    state.heldout_components = h.value().components;
    out.before = state.heldout;
    out.heldout_components_before = state.heldout_components;
  }

  // 3. Name: score the candidates on top of the accepted ones; keep the best if it passes; repeat.
  const auto fit_candidate = [&](const Candidate& c, const State& base) -> Result<CandidateFit> {
    CandidateFit cf;
    cf.next = base;
    EffectEstimate& e = cf.estimate;
    e.name = c.name;
    double guess_s = c.guess_s;   // a time shift's first guess on the grid
    if (c.shifted.empty()) {
      e.dof = c.free_dof;
      FitSpec spec;
      spec.mode = FitMode::kWarm;
      spec.values = base.train_values;
      spec.extra_free = base.extra_free;
      spec.extra_free.insert(c.free.begin(), c.free.end());
      spec.shift_s = base.shift_s;
      spec.observability = true;
      spec.initial = &base.train_trajectory;
      auto fit = Fit(nominal, train, spec);
      ++out.fits;
      if (!fit.ok()) return fit.status();
      c.describe(fit.value().values, fit.value().std, &e);
      e.lr_raw = base.train_chi2 - fit.value().chi2;
      cf.next.extra_free = spec.extra_free;
      cf.next.train_values = fit.value().values;
      cf.next.train_trajectory = fit.value().trajectory;
      cf.next.train_chi2 = fit.value().chi2;
      return cf;
    }
    if (!c.free.empty()) {
      // A clock offset as a parameter, fitted with the full solver (the pairing of the samples never changes, so the
      // chi-square is smooth in it; std from the solver's covariance). Every pose follows the IMU's timing, and
      // Levenberg-Marquardt started at 0 creeps toward the offset (measured on the 30 s ATV drive with a 30 ms offset:
      // still near 0 at the 100-iteration cap), so it starts from a profile: fits with the offset held at multiples of
      // kProfileStepS, walked downhill, and the vertex of the parabola through the best three. When the walk reaches
      // the first-order model's range (kFirstOrderOffsetS) the offset is found as the other time shifts are, on the
      // grid of stamp shifts below: beyond its range the first-order term is no time shift (on the Husky, shifting
      // the stamps by whole periods and fitting the term on top ran on to -0.56 s and beyond against the grid's
      // -0.25 s).
      e.dof = 1;
      const std::string& p = c.free.front();
      const double h = kProfileStepS;
      const double start = base.train_values.count(p) ? base.train_values.at(p)[0] : 0.0;
      struct Point {
        double chi2 = 0.0;
        std::map<std::string, Eigen::VectorXd> values;
        Trajectory trajectory;
      };
      std::map<int, Point> profile;
      profile[0] = {base.train_chi2, base.train_values, base.train_trajectory};
      const auto at = [&](int j) -> Result<double> {
        if (profile.count(j)) return profile[j].chi2;
        int nearest = 0;
        for (const auto& [i, q] : profile)
          if (std::abs(i - j) < std::abs(nearest - j)) nearest = i;
        const Point& warm = profile.at(nearest);
        FitSpec spec;
        spec.mode = FitMode::kWarm;
        spec.values = warm.values;
        spec.values[p] = Eigen::VectorXd::Constant(1, start + j * h);
        spec.extra_free = base.extra_free;
        spec.shift_s = base.shift_s;
        spec.initial = &warm.trajectory;
        auto f = Fit(nominal, train, spec);
        ++out.fits;
        if (!f.ok()) return f.status();
        profile[j] = {f.value().chi2, f.value().values, f.value().trajectory};
        return f.value().chi2;
      };
      int best = 0;
      for (int direction : {1, -1}) {
        int j = best;
        while (std::abs(start + (j + direction) * h) <= kFirstOrderOffsetS + 0.5 * h) {
          auto f = at(j + direction);
          if (!f.ok()) return f.status();
          if (f.value() >= profile.at(j).chi2) break;
          j += direction;
        }
        if (profile.at(j).chi2 < profile.at(best).chi2) best = j;
      }
      if (profile.count(best - 1) && profile.count(best + 1)) {
        const double y0 = profile.at(best - 1).chi2, y1 = profile.at(best).chi2, y2 = profile.at(best + 1).chi2;
        const double curvature = y0 - 2.0 * y1 + y2;
        const double vertex =
            start + (best + (curvature > 0.0 ? std::clamp(0.5 * (y0 - y2) / curvature, -1.0, 1.0) : 0.0)) * h;
        FitSpec spec;
        spec.mode = FitMode::kWarm;
        spec.values = profile.at(best).values;
        spec.values[p] = Eigen::VectorXd::Constant(1, vertex);
        spec.extra_free = base.extra_free;
        spec.extra_free.insert(p);
        spec.shift_s = base.shift_s;
        spec.observability = true;
        spec.initial = &profile.at(best).trajectory;
        auto f = Fit(nominal, train, spec);
        ++out.fits;
        if (!f.ok()) return f.status();
        const FitOutcome& fit = f.value();
        const double coarse = base.shift_s.count(c.shifted.front()) ? base.shift_s.at(c.shifted.front()) : 0.0;
        e.parameters[c.shift_parameter] = coarse + fit.values.at(p)[0];
        e.std[c.shift_parameter] = fit.std.count(p) ? fit.std.at(p)[0] : std::numeric_limits<double>::quiet_NaN();
        e.lr_raw = base.train_chi2 - fit.chi2;
        cf.next.extra_free = base.extra_free;
        cf.next.extra_free.insert(p);
        cf.next.train_values = fit.values;
        cf.next.train_trajectory = fit.trajectory;
        cf.next.train_chi2 = fit.chi2;
        // An offset far beyond the first-order range is not reached from inside it: the reading moved along its
        // smoothed slope is a poor time shift there, and the fit settles on a small offset (the Husky's -0.25 s, found
        // on the grid, came out at -0.031 +- 0.008 s). So the stamp shifts at the range's ends are fitted too, and
        // when one of them beats the continuous fit the offset is searched on the grid from it (README,
        // imu_time_offset).
        const int k_edge = std::min(static_cast<int>(std::floor(margin / period)),
                                    static_cast<int>(std::ceil(kFirstOrderOffsetS / period)));
        double edge_s = 0.0, edge_chi2 = fit.chi2;
        for (int side : {-1, 1}) {
          FitSpec edge;
          edge.mode = FitMode::kWarm;
          edge.values = base.train_values;
          edge.extra_free = base.extra_free;
          edge.shift_s = base.shift_s;
          edge.initial = &base.train_trajectory;
          for (const std::string& s : c.shifted) edge.shift_s[s] = side * k_edge * period;
          auto g = Fit(nominal, train, edge);
          ++out.fits;
          if (!g.ok()) return g.status();
          if (g.value().chi2 < edge_chi2) {
            edge_chi2 = g.value().chi2;
            edge_s = side * k_edge * period;
          }
        }
        if (edge_s == 0.0) return cf;
        guess_s = edge_s;
        cf.next = base;
      }
      say("candidate " + c.name + ": beyond the first-order range, searched on the grid of stamp shifts");
    }
    // A time shift: chi2 on the grid k * period (where the shifted stamps fall on poses, so the nominal attachment
    // is exact), walking downhill from the first guess, then a parabola through the best point and its neighbours.
    e.dof = 1;
    struct GridFit {
      double chi2 = 0.0;
      std::map<std::string, Eigen::VectorXd> values;
      Trajectory trajectory;
    };
    std::map<int, GridFit> chi2_at;
    const int k_max = static_cast<int>(std::floor(margin / period));
    const auto at = [&](int k) -> Result<double> {
      if (chi2_at.count(k)) return chi2_at[k].chi2;
      // Warm-started from the nearest shift fitted so far (the poses follow the shifted stream, so the unshifted
      // fit is a poor start far from 0).
      int nearest = 0;
      for (const auto& [j, g] : chi2_at)
        if (std::abs(j - k) < std::abs(nearest - k)) nearest = j;
      const GridFit* from = &chi2_at.at(nearest);
      FitSpec spec;
      spec.mode = FitMode::kWarm;
      spec.values = from->values;
      spec.extra_free = base.extra_free;
      spec.shift_s = base.shift_s;
      spec.initial = &from->trajectory;
      for (const std::string& s : c.shifted) spec.shift_s[s] = k * period;
      auto fit = Fit(nominal, train, spec);
      ++out.fits;
      if (!fit.ok()) return fit.status();
      chi2_at[k] = {fit.value().chi2, fit.value().values, fit.value().trajectory};
      return fit.value().chi2;
    };
    // The first guess: the linearized effect of the shift on the nominal residuals , on the grid.
    int best = std::clamp(static_cast<int>(std::lround(guess_s / period)), -k_max, k_max);
    chi2_at[0] = {base.train_chi2, base.train_values, base.train_trajectory};
    if (auto f = at(best); !f.ok()) return f.status();
    for (int step : {1, -1}) {
      int k = best;
      for (int i = 0; i < 2 * k_max; ++i) {
        const int next = k + step;
        if (std::abs(next) > k_max) break;
        auto f = at(next);
        if (!f.ok()) return f.status();
        if (f.value() >= chi2_at[k].chi2) break;
        k = next;
      }
      if (chi2_at[k].chi2 < chi2_at[best].chi2) best = k;
    }
    // The chi-square on the grid is not smooth: moving a stream by one sample re-pairs its noise with the other
    // streams', which adds a jitter of tens to the chi-square of a 20 s drive (measured on the ATV's IMU). So a
    // parabola chi2(k) = a k^2 + b k + c is fitted by least squares to the best point and kHalfWindow points each
    // side, and the standard deviation of its vertex combines the curvature's (1 / sqrt(a) grid steps: cost = chi2 / 2
    // has second derivative a) and the vertex's own spread from the jitter (delta method on the fitted a, b).
    constexpr int kHalfWindow = 3;
    struct Parabola {
      double a = 0.0, b = 0.0, c = 0.0, jitter2 = 0.0;
      Eigen::Matrix3d XtX_inv = Eigen::Matrix3d::Zero();
    };
    // The least-squares parabola in u = k - center over the window center +- kHalfWindow (within the range).
    const auto window = [&](int center) -> Result<std::optional<Parabola>> {
      std::vector<int> ks;
      for (int k = center - kHalfWindow; k <= center + kHalfWindow; ++k) {
        if (std::abs(k) > k_max) continue;
        if (auto f = at(k); !f.ok()) return f.status();
        ks.push_back(k);
      }
      if (ks.size() < 4) return std::optional<Parabola>{};
      Eigen::MatrixXd X(static_cast<Eigen::Index>(ks.size()), 3);
      Eigen::VectorXd y(static_cast<Eigen::Index>(ks.size()));
      for (std::size_t i = 0; i < ks.size(); ++i) {
        const double u = ks[i] - center;
        X.row(static_cast<Eigen::Index>(i)) << u * u, u, 1.0;
        y[static_cast<Eigen::Index>(i)] = chi2_at[ks[i]].chi2;
      }
      Parabola q;
      q.XtX_inv = (X.transpose() * X).inverse();
      const Eigen::Vector3d abc = q.XtX_inv * X.transpose() * y;
      q.a = abc[0];
      q.b = abc[1];
      q.c = abc[2];
      const double dof = static_cast<double>(ks.size()) - 3.0;
      q.jitter2 = dof > 0.0 ? (y - X * abc).squaredNorm() / dof : 0.0;
      return std::optional<Parabola>{q};
    };
    // The walk stops at the first step uphill, which the jitter fakes where the minimum is flat (an IMU clock offset
    // of 0.096 s beside the nominal model's own 0.025 s: the walk stopped at 0.10 s, the minimum near 0.12 s, and the
    // window's parabola, its vertex clamped at the edge, gave 0.105 +- 0.096 s). So while the vertex lies beyond the
    // window's inner points, the window moves toward it (by at most kHalfWindow points, three times at most).
    auto parabola = window(best);
    if (!parabola.ok()) return parabola.status();
    for (int move = 0; move < 3 && parabola.value() && parabola.value()->a > 0.0; ++move) {
      const double u = -parabola.value()->b / (2.0 * parabola.value()->a);
      if (std::abs(u) <= kHalfWindow - 1) break;
      const double reach = kHalfWindow;
      const int next = std::clamp(best + static_cast<int>(std::lround(std::clamp(u, -reach, reach))), -k_max, k_max);
      if (next == best) break;
      best = next;
      parabola = window(best);
      if (!parabola.ok()) return parabola.status();
    }
    double k_hat = best;
    double chi2_min = chi2_at[best].chi2;
    double stdev = std::numeric_limits<double>::quiet_NaN();
    if (parabola.value() && parabola.value()->a > 0.0) {
      const Parabola& q = *parabola.value();
      const double u_hat = std::clamp(-q.b / (2.0 * q.a), -static_cast<double>(kHalfWindow),
                                      static_cast<double>(kHalfWindow));
      k_hat = best + u_hat;
      chi2_min = q.a * u_hat * u_hat + q.b * u_hat + q.c;
      const Eigen::Vector3d J(q.b / (2.0 * q.a * q.a), -1.0 / (2.0 * q.a), 0.0);
      const double vertex_var = q.jitter2 * J.dot(q.XtX_inv * J);
      stdev = period * std::sqrt(1.0 / q.a + vertex_var);
    }
    const double shift = k_hat * period;
    e.parameters[c.shift_parameter] = shift;
    e.std[c.shift_parameter] = stdev;
    e.lr_raw = base.train_chi2 - chi2_min;
    for (const std::string& s : c.shifted) cf.next.shift_s[s] = shift;
    // The state the next rounds build on: an actual fit at the chosen shift. The parabola's vertex chi2 is the test
    // statistic's, but it lies below what any one shift reaches by the jitter, and later candidates compared with it
    // would lose that much of their own drop.
    FitSpec spec;
    spec.mode = FitMode::kWarm;
    spec.values = chi2_at[best].values;
    spec.extra_free = base.extra_free;
    spec.shift_s = cf.next.shift_s;
    spec.initial = &chi2_at[best].trajectory;
    auto fit = Fit(nominal, train, spec);
    ++out.fits;
    if (!fit.ok()) return fit.status();
    cf.next.train_values = fit.value().values;
    cf.next.train_trajectory = fit.value().trajectory;
    cf.next.train_chi2 = fit.value().chi2;
    return cf;
  };

  // The located mismatch: the components found inconsistent over the whole run, measured on the held-out part
  // against the nominal model's held-out level (the baseline's).
  const std::map<std::string, double> heldout_levels =
      options.baseline ? options.baseline->heldout_component_levels : std::map<std::string, double>{};
  std::vector<std::string> located_keys;
  for (const LocatedComponent& lc : out.located)
    if (lc.inconsistent) located_keys.push_back(ComponentKey(lc.stream, lc.component));
  // The share is of the effects kept so far and the candidate together (their held-out drop from the nominal model):
  // a later effect that refines an explained mismatch (OptiOdom's wheel ratio after the track, the Husky's track after
  // the IMU's time offset, beside GPS structure no candidate models) is not judged against the whole remainder alone.
  const double nominal_heldout_chi2 = state.heldout_chi2;

  std::set<std::string> accepted, dropped;
  for (int round = 0; round < std::max(1, options.max_effects); ++round) {
    std::vector<CandidateFit> fits;
    std::vector<EffectEstimate> failed;
    for (const Candidate& c : library) {
      if (accepted.count(c.name) || dropped.count(c.name)) continue;
      say("candidate " + c.name + (round > 0 ? " (on top of the accepted effects)" : ""));
      auto cf = fit_candidate(c, state);
      if (!cf.ok()) {
        // A candidate whose fit fails (e.g. a gyroscope scale driven to 0 on an axis a short planar drive does not
        // excite) explains nothing: it is rejected and not tried again, the diagnosis goes on.
        EffectEstimate e;
        e.name = c.name;
        e.dof = c.shifted.empty() ? c.free_dof : 1;
        e.delta_bic = std::numeric_limits<double>::infinity();
        e.decision = "rejected: the fit failed (" + cf.status().message() + ")";
        say("candidate " + c.name + ": " + e.decision);
        failed.push_back(e);
        dropped.insert(c.name);
        continue;
      }
      EffectEstimate& e = cf.value().estimate;
      Score(options.baseline, state.train_measurements, &e);
      fits.push_back(std::move(cf).value());
    }
    if (fits.empty()) {
      if (round == 0) out.candidates = failed;
      break;
    }
    std::sort(fits.begin(), fits.end(), [](const CandidateFit& a, const CandidateFit& b) {
      return a.estimate.delta_bic < b.estimate.delta_bic;
    });
    // In order of Delta BIC, the first candidate that passes the likelihood-ratio test, BIC and the held-out test is
    // kept. One that fails the held-out test (a structure of the training part only, e.g. a clock offset that jumps
    // within the run) does not hide the next one, and is not tried again in the later rounds.
    CandidateFit* kept = nullptr;
    for (CandidateFit& f : fits) {
      const bool extra = kept && options.heldout_all_candidates && round == 0;
      if (options.max_effects <= round || (kept && !extra)) break;
      EffectEstimate& e = f.estimate;
      if (e.lr_pvalue >= options.alpha) {
        e.decision = "rejected: likelihood-ratio p above alpha";
        continue;
      }
      if (e.delta_bic >= options.max_delta_bic) {
        e.decision = "rejected: BIC does not favour it";
        continue;
      }
      // The parts were cut for shifts within the search range (Slice): beyond it, shifted fixes leave the poses' span
      // and the held-out comparison counts other measurements.
      const auto beyond = std::find_if(f.next.shift_s.begin(), f.next.shift_s.end(), [&](const auto& shift) {
        return std::abs(shift.second) > options.max_shift_s;
      });
      if (beyond != f.next.shift_s.end()) {
        if (extra) continue;   // evaluated for the record only: neither a decision nor a drop for the later rounds
        std::ostringstream decision;
        decision << "rejected: the fitted shift of " << beyond->first << " (" << beyond->second
                 << " s) is beyond the time-shift range +-" << options.max_shift_s << " s (--max-shift)";
        e.decision = decision.str();
        dropped.insert(e.name);
        continue;
      }
      auto h = heldout(f.next);
      if (!h.ok()) {
        // As a candidate whose training fit fails: rejected, and the diagnosis goes on.
        if (extra) continue;
        e.decision = "rejected: the held-out fit failed: " + h.status().message();
        dropped.insert(e.name);
        continue;
      }
      e.evaluated_heldout = true;
      e.heldout_improvement = state.heldout_chi2 > 0.0 ? 1.0 - h.value().chi2 / state.heldout_chi2 : 0.0;
      e.heldout_excess_before = HeldoutExcess(state.heldout_components, located_keys, heldout_levels);
      e.heldout_excess_after = HeldoutExcess(h.value().components, located_keys, heldout_levels);
      e.explained_share = ExplainedShare(nominal_heldout_chi2 - h.value().chi2, e.heldout_excess_after);
      if (extra) continue;   // evaluated for the record only; the decision was taken
      if (e.heldout_improvement <= options.min_heldout_improvement) {
        e.decision = "rejected: no improvement on the held-out part";
        dropped.insert(e.name);
        continue;
      }
      // A decoy's stream stays about as inconsistent as before: the effect explains too small a share of the
      // mismatch (a candidate the same structure pulls in would not explain more in a later round either).
      if (e.explained_share < options.min_explained_share) {
        e.decision = "rejected: explains too small a share of the held-out mismatch";
        dropped.insert(e.name);
        continue;
      }
      e.decision = "accepted";
      e.accepted = true;
      f.next.heldout_chi2 = h.value().chi2;
      f.next.heldout = h.value().streams;
      f.next.heldout_components = h.value().components;
      kept = &f;
    }
    for (CandidateFit& f : fits) {
      if (f.estimate.evaluated_heldout)
        say("candidate " + f.estimate.name + ": held-out chi2 " + std::to_string(100.0 * f.estimate.heldout_improvement) +
            " % lower, share of the held-out mismatch " + std::to_string(f.estimate.explained_share) + ": " +
            (f.estimate.decision.empty() ? "evaluated" : f.estimate.decision));
      if (f.estimate.decision.empty()) f.estimate.decision = "not the best candidate";
      if (round == 0) out.candidates.push_back(f.estimate);
    }
    if (round == 0) out.candidates.insert(out.candidates.end(), failed.begin(), failed.end());
    if (!kept) break;
    accepted.insert(kept->estimate.name);
    out.effects.push_back(kept->estimate);
    say("accepted " + kept->estimate.name);
    state = kept->next;
  }
  out.after = state.heldout;
  out.heldout_components_after = state.heldout_components;
  out.training_parameters_after = state.train_values;
  for (const std::string& name : state.extra_free) out.effect_parameters[name] = state.train_values.at(name);
  out.stream_shifts_s = state.shift_s;

  // Verdict. Without an accepted effect every inconsistent component is unexplained. With accepted effects, an
  // inconsistent component stays unexplained when the held-out part, fitted with the effects, is still inconsistent in
  // it against the nominal model's held-out level (the baseline's; Locate's rule) by an excess the stated noise can
  // tell from noise (SignificantExcess): structure that the named effects do not account for (an out-of-library
  // effect can pull a library parameter by a little and pass the tests, as an accelerometer gain error passes on to
  // the attitude and a gyroscope scale), so the verdict is then "unknown". The excess test keeps components whose
  // level is far below 1 (an oval tire's roll on a diff drive's gyroscope x: 1e-4 doubled) from overruling an effect
  // that explains what the likelihood sees.
  const LocateOptions locate_options;
  for (const LocatedComponent& lc : out.located) {
    if (!lc.inconsistent) continue;
    const std::string key = ComponentKey(lc.stream, lc.component);
    std::ostringstream line;
    line << key;
    if (!lc.correlates.empty())
      line << " depends on " << lc.correlates.front().condition << " (rho " << lc.correlates.front().rho << ")";
    if (!out.effects.empty()) {
      const auto after = out.heldout_components_after.find(key);
      if (after == out.heldout_components_after.end()) continue;
      const auto level = heldout_levels.find(key);
      const double expected = level != heldout_levels.end() ? level->second : 1.0;
      if (!Inconsistent(after->second, expected, locate_options.inconsistency_ratio) ||
          !SignificantExcess(after->second, expected))
        continue;
      line << "; held-out chi2/dof " << after->second.chi2_per_dof << " with the named effects (level " << expected
           << ")";
    }
    out.unexplained.push_back(line.str());
  }
  out.verdict = out.unexplained.empty() ? (out.effects.empty() ? "none" : "named") : "unknown";
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace roamlab::gap
