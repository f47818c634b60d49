#include "gap/internal/effect_library.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <set>

#include "gap/internal/fit.h"

namespace roamlab::gap::internal {
namespace {

using estimator::EstimatorConfig;
using estimator::StreamConfig;

constexpr double kPi = 3.14159265358979323846;

// The configured streams the candidates attach to (the first of each model; every source of the repeated ones).
struct LibraryStreams {
  std::vector<std::string> gps, imu, pose;                                      // recording streams
  std::string gyro, ackermann, diff_drive, mecanum, magnetometer, pose_stream;  // configured streams
};

LibraryStreams FindStreams(const EstimatorConfig& config) {
  LibraryStreams s;
  for (const auto& [stream, sc] : config.streams) {
    if (sc.model == "absolute_pose") {
      s.pose.push_back(sc.sources.begin()->second);
      if (s.pose_stream.empty()) s.pose_stream = stream;
    }
    if (sc.model == "differential_drive" && s.diff_drive.empty()) s.diff_drive = stream;
    if (sc.model == "mecanum_drive" && s.mecanum.empty()) s.mecanum = stream;
    if (sc.model == "gps") s.gps.push_back(sc.sources.begin()->second);
    if (sc.model == "gyroscope" || sc.model == "accelerometer" || sc.model == "magnetometer")
      s.imu.push_back(sc.sources.begin()->second);
    if (sc.model == "gyroscope" && s.gyro.empty()) s.gyro = stream;
    if (sc.model == "ackermann" && s.ackermann.empty()) s.ackermann = stream;
    if (sc.model == "magnetometer" && sc.inputs.count("specific_force") && s.magnetometer.empty())
      s.magnetometer = stream;
  }
  std::sort(s.imu.begin(), s.imu.end());
  s.imu.erase(std::unique(s.imu.begin(), s.imu.end()), s.imu.end());
  return s;
}

bool IsFree(const EstimatorConfig& config, const std::string& name) {
  const auto it = config.parameters.find(name);
  return it != config.parameters.end() && it->second.free;
}

// The parameter `slot` of configured stream `stream` maps to.
std::string Slot(const EstimatorConfig& config, const std::string& stream, const std::string& slot) {
  return SlotParameter(stream, config.streams.at(stream), slot);
}

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

// Makes `c` free the 3-vector `parameter` of `stream`, reported per axis as prefix + x, y, z.
void FreeVector(const std::string& stream, const std::string& parameter, const std::string& prefix, Candidate* c) {
  c->stream = stream;
  c->free = {parameter};
  c->free_dof = 3;
  c->describe = [parameter, prefix](const auto& value, const auto& std, EffectEstimate* e) {
    for (int i = 0; i < 3; ++i) {
      const std::string key = prefix + "xyz"[i];
      e->parameters[key] = value.at(parameter)[i];
      if (std.count(parameter)) e->std[key] = std.at(parameter)[i];
    }
  };
}

// Time shifts: the GPS fixes stamped late (latency), the IMU's clock (its streams shifted together, or its shared
// time_offset_s fitted), an absolute pose stream stamped late against the master.
bool GpsLatency(const EstimatorConfig& config, const LibraryStreams& s, Candidate* c) {
  c->stream = "gps";
  for (const auto& [stream, sc] : config.streams)
    if (sc.model == "gps") c->stream = stream;
  c->shifted = s.gps;
  c->shift_parameter = "latency_s";
  return true;
}

bool ImuTimeOffset(const EstimatorConfig& config, const LibraryStreams& s, Candidate* c) {
  c->stream = s.gyro;
  c->shifted = s.imu;
  c->shift_parameter = "offset_s";
  // The gyroscope's and accelerometer's one time_offset_s parameter (the clock they share); streams with one each
  // keep the search on the grid of stamp shifts. The magnetometer keeps its own (the nominal models fix it at 0):
  // freed with the others it pulls the estimate toward 0.
  std::set<std::string> offsets;
  for (const auto& [stream, sc] : config.streams)
    if (sc.model == "gyroscope" || sc.model == "accelerometer")
      offsets.insert(SlotParameter(stream, sc, "time_offset_s"));
  if (offsets.size() == 1 && !IsFree(config, *offsets.begin())) {
    c->free = {*offsets.begin()};
    c->free_dof = 1;
  }
  return true;
}

// The absolute pose stream (motion capture, SLAM) stamped late against the master (the wheel encoders): its pose
// stamped t is the body's pose at t - offset.
bool PoseTimeOffset(const LibraryStreams& s, Candidate* c) {
  c->stream = s.pose_stream;
  c->shifted = s.pose;
  c->shift_parameter = "offset_s";
  return true;
}

// The Ackermann model's candidates; false when the slot is free already (or, for the axle, the gyroscope's mounting
// is not believed).
bool SteeringOffset(const EstimatorConfig& config, const LibraryStreams& s, Candidate* c) {
  const std::string p = Slot(config, s.ackermann, "k_gamma");
  if (IsFree(config, p)) return false;
  FreeOneSlot(s.ackermann, p, "offset_rad", 1.0, ConfiguredValue(config, p).value_or(Eigen::VectorXd::Zero(1))[0], c);
  return true;
}

// The rear axle's thrust angle alpha (models/ackermann_velocity.h: the rear axle rolls along alpha, so the vehicle
// crabs by alpha and turns at -v tan(alpha) / L at zero handlebar) freed from the nominal model's zero; reported as
// the simulator's axle_misalignment on the Ackermann rear axle, yaw_deg = alpha in degrees. Its turn is a steering
// offset's to first order (k_gamma = -alpha); only the crab tells them apart, and it shows only against a heading tied
// to the chassis: the candidate applies when the gyroscope's mounting is believed (its misalignment fixed). With it
// free, a rotation of O by alpha absorbs the crab, only alpha sin^2(delta) on the steering row is left, and the two
// candidates fit about equally well: this one would only duplicate steering_offset.
bool AxleMisalignment(const EstimatorConfig& config, const LibraryStreams& s, Candidate* c) {
  const std::string p = Slot(config, s.ackermann, "thrust_angle");
  if (IsFree(config, p) || s.gyro.empty() || IsFree(config, Slot(config, s.gyro, "misalignment"))) return false;
  FreeOneSlot(s.ackermann, p, "yaw_deg", 180.0 / kPi, 0.0, c);
  return true;
}

// The tires' cornering compliance (front, rear) freed from the nominal model's zero.
bool LateralSlip(const EstimatorConfig& config, const LibraryStreams& s, Candidate* c) {
  const std::string front = Slot(config, s.ackermann, "cornering_front");
  const std::string rear = Slot(config, s.ackermann, "cornering_rear");
  if (IsFree(config, front) || IsFree(config, rear)) return false;
  c->stream = s.ackermann;
  c->free = {front, rear};
  c->free_dof = 2;
  c->describe = [front, rear](const auto& value, const auto& std, EffectEstimate* e) {
    e->parameters["cornering_front_rads2pm"] = value.at(front)[0];
    e->parameters["cornering_rear_s"] = value.at(rear)[0];
    if (std.count(front)) e->std["cornering_front_rads2pm"] = std.at(front)[0];
    if (std.count(rear)) e->std["cornering_rear_s"] = std.at(rear)[0];
  };
  return true;
}

// The driven tires' slip (models/ackermann_velocity.h): the rear-wheel speed over-reads the ground speed by
// 1 + s_f f_x (longitudinal_slip: f_x the forward specific force read from the IMU, the traction per unit mass) or
// 1 + s_p g sin(pitch) (slope_slip: the slope alone, from the poses' attitude), the slot freed from zero and reported
// as the simulator's slip_per_mps2. The null is the baseline's value (what MuJoCo's soft contacts and the nominal
// model's other gaps put there without an effect).
bool Slip(const std::string& name, const EstimatorConfig& config, const LibraryStreams& s, Candidate* c) {
  const std::string p = Slot(config, s.ackermann, name == "slope_slip" ? "slope_slip_per_mps2" : "slip_per_mps2");
  if (IsFree(config, p)) return false;
  FreeOneSlot(s.ackermann, p, "slip_per_mps2", 1.0, 0.0, c);
  return true;
}

// gyro_scale_error: the per-axis scale k_s (models/gyroscope.h: z = k_s o omega + b + eta) freed from 1, reported as
// scale_x/y/z. gyro_bias_drift: the bias b [rad/s] freed from the nominal model's zero as one constant over the fitted
// part: a bias that wanders slowly is seen as its mean there, and the held-out test checks that the same value still
// explains the rest of the run. Reported as the simulator's initial_x/y/z.
bool Gyroscope(const std::string& name, const EstimatorConfig& config, const LibraryStreams& s, Candidate* c) {
  const bool scale = name == "gyro_scale_error";
  const std::string p = Slot(config, s.gyro, scale ? "scale" : "bias");
  if (IsFree(config, p)) return false;
  FreeVector(s.gyro, p, scale ? "scale_" : "initial_", c);
  return true;
}

// The right/left radius ratio rho (models/differential_drive.h): meaningful when the nominal model believes the
// wheels equal, i.e. maps both radius slots to one parameter.
bool WheelRadiusAsymmetry(const EstimatorConfig& config, const LibraryStreams& s, Candidate* c) {
  const std::string p = Slot(config, s.diff_drive, "right_left_ratio");
  if (IsFree(config, p) || Slot(config, s.diff_drive, "radius_left") != Slot(config, s.diff_drive, "radius_right"))
    return false;
  FreeOneSlot(s.diff_drive, p, "ratio_right_left", 1.0, 0.0, c);
  return true;
}

// Tires that are not round: both wheels' second harmonic of the rolling radius (a, b) freed from zero
// (models/differential_drive.h). Reported as the simulator's effect: the wheel with the larger amplitude (0 left,
// 1 right) and its ovality d = 2 sqrt(a^2 + b^2), std by first-order propagation.
bool WheelDeformation(const EstimatorConfig& config, const LibraryStreams& s, Candidate* c) {
  const std::string left = Slot(config, s.diff_drive, "deformation_left");
  const std::string right = Slot(config, s.diff_drive, "deformation_right");
  if (IsFree(config, left) || IsFree(config, right) || left == right) return false;
  c->stream = s.diff_drive;
  c->free = {left, right};
  c->free_dof = 4;
  c->describe = [left, right](const auto& value, const auto& std, EffectEstimate* e) {
    const Eigen::Vector2d l = value.at(left), r = value.at(right);
    const bool right_wheel = r.norm() > l.norm();
    const Eigen::Vector2d ab = right_wheel ? r : l;
    e->parameters["wheel"] = right_wheel ? 1.0 : 0.0;
    e->parameters["ovality_m"] = 2.0 * ab.norm();
    const std::string& p = right_wheel ? right : left;
    if (std.count(p) && ab.norm() > 0.0)
      e->std["ovality_m"] = 2.0 * std::hypot(ab[0] * std.at(p)[0], ab[1] * std.at(p)[1]) / ab.norm();
  };
  return true;
}

// A track width error: the slot `slot` of `stream` freed from its nominal geometry, reported as
// track_error_m = scale (value - nominal).
bool TrackWidth(const EstimatorConfig& config, const std::string& stream, const std::string& slot, double scale,
                Candidate* c) {
  const std::string p = Slot(config, stream, slot);
  const std::optional<Eigen::VectorXd> nominal = ConfiguredValue(config, p);
  if (IsFree(config, p) || !nominal || !std::isfinite((*nominal)[0])) return false;
  FreeOneSlot(stream, p, "track_error_m", scale, (*nominal)[0], c);
  return true;
}

// Whether candidate `name` applies to `config`; fills `c` when it does.
bool Applies(const std::string& name, const EstimatorConfig& config, const LibraryStreams& s, Candidate* c) {
  if (name == "gps_latency" && !s.gps.empty()) return GpsLatency(config, s, c);
  if (name == "imu_time_offset" && !s.imu.empty() && !s.gyro.empty()) return ImuTimeOffset(config, s, c);
  if (name == "pose_time_offset" && !s.pose.empty() && config.streams.count(config.master) &&
      config.streams.at(config.master).model != "absolute_pose")
    return PoseTimeOffset(s, c);
  if (name == "steering_offset" && !s.ackermann.empty()) return SteeringOffset(config, s, c);
  if (name == "axle_misalignment" && !s.ackermann.empty()) return AxleMisalignment(config, s, c);
  if ((name == "gyro_scale_error" || name == "gyro_bias_drift") && !s.gyro.empty())
    return Gyroscope(name, config, s, c);
  if (name == "wheel_radius_asymmetry" && !s.diff_drive.empty()) return WheelRadiusAsymmetry(config, s, c);
  if (name == "wheel_deformation" && !s.diff_drive.empty()) return WheelDeformation(config, s, c);
  // The effective track B of a differential drive (for a skid-steer robot, what makes the wheel speeds' difference
  // turn it at the rate it does), reported as the departure from the nominal geometry.
  if (name == "track_width_error" && !s.diff_drive.empty()) return TrackWidth(config, s.diff_drive, "baseline", 1.0, c);
  // The mecanum wheels' yaw lever arm K = lx + ly (models/mecanum_drive.h). The simulator's effect moves the wheels
  // apart along O's y by track_error_m, half on each side: ly, hence K, grows by track_error_m / 2
  // (sim/wheeled_robot.h ChangeTrack), so track_error_m = 2 (K - K_nominal) and its std is 2 std(K). (omni3 has no
  // such effect in the simulator, so no candidate.) K is told from the common radius only with a translation
  // reference (position fixes): the wheel rows give v / r and K omega_z / r, the gyroscope K / r; without one the fit
  // leaves K where it is and no std (NominalHolonomicConfig).
  if (name == "track_width_error" && !s.mecanum.empty()) return TrackWidth(config, s.mecanum, "lx_plus_ly", 2.0, c);
  if (name == "lateral_slip" && !s.ackermann.empty()) return LateralSlip(config, s, c);
  if ((name == "longitudinal_slip" && !s.ackermann.empty() &&
       config.streams.at(s.ackermann).inputs.count("specific_force")) ||
      (name == "slope_slip" && !s.ackermann.empty()))
    return Slip(name, config, s, c);
  // The magnetometer's bias per N m of drive torque k (models/magnetometer.h) freed from zero, on the proxy
  // tau_hat = c f_x (forward specific force, c = m r / 2 from the nominal vehicle): reported as the simulator's
  // b_per_nm_x/y/z directly. The proxy ignores rolling resistance (a constant: absorbed by b) and what else the torque
  // does than pull the vehicle (spinning the wheels up, slip), so k comes out a few per cent low.
  if (name == "magnetometer_motor_interference" && !s.magnetometer.empty()) {
    const std::string p = Slot(config, s.magnetometer, "b_per_drive_nm");
    if (IsFree(config, p)) return false;
    FreeVector(s.magnetometer, p, "b_per_nm_", c);
    return true;
  }
  return false;
}

}  // namespace

std::vector<Candidate> Library(const EstimatorConfig& config) {
  const LibraryStreams streams = FindStreams(config);
  std::vector<Candidate> out;
  for (const std::string& name : CandidateNames()) {
    Candidate c;
    c.name = name;
    if (Applies(name, config, streams, &c)) out.push_back(std::move(c));
  }
  return out;
}

void GuessGpsLatency(const EstimatorConfig& config, const std::vector<estimator::MeasurementResidual>& residuals,
                     const Conditions& conditions, std::vector<Candidate>* library) {
  for (Candidate& c : *library) {
    if (c.name != "gps_latency") continue;
    const auto noise = config.streams.at(c.stream).noise;
    const double sigma = noise.count("sigma_m") ? noise.at("sigma_m") : 1.0;
    const auto east = std::find(conditions.names.begin(), conditions.names.end(), "v_east_mps");
    const int ce = static_cast<int>(east - conditions.names.begin());
    double ev = 0.0, vv = 0.0;
    for (const estimator::MeasurementResidual& r : residuals) {
      if (r.stream != c.stream || !r.active || r.whitened.size() < 2 || conditions.t.empty()) continue;
      const Eigen::Vector2d v(conditions.At(ce, r.t), conditions.At(ce + 1, r.t));
      ev += sigma * r.whitened.head<2>().dot(v);
      vv += v.squaredNorm();
    }
    c.guess_s = vv > 0.0 ? ev / vv : 0.0;
  }
}

}  // namespace roamlab::gap::internal

namespace roamlab::gap {

const std::vector<std::string>& CandidateNames() {
  static const std::vector<std::string> names = {
      "gps_latency",       "imu_time_offset",   "pose_time_offset",  "steering_offset",
      "gyro_scale_error",  "gyro_bias_drift",   "lateral_slip",      "wheel_radius_asymmetry",
      "track_width_error", "wheel_deformation", "axle_misalignment", "magnetometer_motor_interference",
      "longitudinal_slip", "slope_slip"};
  return names;
}

}  // namespace roamlab::gap
