#include "estimator/odometry/parametric.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

#include "estimator/odometry/robust_linear.h"
#include "recording/wheel_kinematics.h"

namespace roamlab::estimator::odometry {
namespace {

int WheelIndex(const std::vector<std::string>& wheels, const std::string& name) {
  const auto it = std::find(wheels.begin(), wheels.end(), name);
  return it == wheels.end() ? -1 : static_cast<int>(it - wheels.begin());
}

Result<double> GeometryValue(const recording::Platform& platform, const std::string& key) {
  const auto it = platform.geometry.find(key);
  if (it == platform.geometry.end()) {
    return Status::Error("platform '" + platform.kind + "' has no geometry." + key);
  }
  if (!(it->second > 0.0 || key.find("angle") != std::string::npos)) {
    return Status::Error("platform geometry." + key + " must be positive");
  }
  return it->second;
}

Result<double> WheelRadius(const recording::Platform& platform, const std::string& wheel) {
  const std::string key = "wheel_radius_" + wheel + "_m";
  if (platform.geometry.count(key) > 0) return GeometryValue(platform, key);
  return GeometryValue(platform, "wheel_radius_m");
}

// Whether the platform uses the simulator's keys (recording/wheel_kinematics.h) rather than the per-wheel keys above:
// baseline_m, half_length_m, or wheel_distance_m without per-wheel angles.
bool UsesRecordingKeys(const recording::Platform& platform, const std::vector<std::string>& wheels) {
  const auto has = [&](const std::string& key) { return platform.geometry.count(key) > 0; };
  if (!has("wheel_radius_m")) return false;
  if (platform.kind == "differential_drive") return has("baseline_m") && !has("track_m");
  if (platform.kind == "mecanum") return has("half_length_m") && has("half_width_m");
  if (platform.kind == "omni3") return !wheels.empty() && !has("wheel_angle_" + wheels.front() + "_rad");
  return false;
}

// The tricycle's rows on its two columns <wheel>_cos_steering, <wheel>_sin_steering (training_data.h): with the
// steering offset o and the wheel-to-axle distance L, xi_x = r (cos o f_c - sin o f_s) and
// L xi_theta = r (sin o f_c + cos o f_s), i.e. rows [cos o, 0, L sin o] and [-sin o, 0, L cos o], both of radius r.
Result<WheelKinematics> TricycleKinematics(const recording::Platform& platform, WheelKinematics k) {
  const std::string suffix = "_cos_steering";
  const std::string& first = k.wheels.empty() ? suffix : k.wheels.front();
  const std::string wheel = first.size() > suffix.size() ? first.substr(0, first.size() - suffix.size()) : "";
  if (k.wheels.size() != 2 || wheel.empty() || k.wheels[0] != wheel + suffix ||
      k.wheels[1] != wheel + "_sin_steering") {
    return Status::Error("platform tricycle needs the columns <wheel>_cos_steering and <wheel>_sin_steering");
  }
  Result<double> distance = GeometryValue(platform, "wheel_to_axle_m");
  if (!distance.ok()) return distance.status();
  const auto offset = platform.geometry.find("steering_offset_rad");
  const double o = offset == platform.geometry.end() ? 0.0 : offset->second;
  if (!std::isfinite(o)) return Status::Error("platform geometry.steering_offset_rad must be finite");
  Result<double> radius = WheelRadius(platform, wheel);
  if (!radius.ok()) return radius.status();
  const double L = distance.value();
  k.J.row(0) << std::cos(o), 0.0, L * std::sin(o);
  k.J.row(1) << -std::sin(o), 0.0, L * std::cos(o);
  k.radius_m.setConstant(radius.value());
  return k;
}

}  // namespace

Pose2 ExpTwist(const Eigen::Vector3d& xi) {
  const double w = xi[2];
  if (std::abs(w) < 1e-9) return Pose2(xi[0] - 0.5 * xi[1] * w, xi[1] + 0.5 * xi[0] * w, w);
  const double s = std::sin(w);
  const double c1 = 1.0 - std::cos(w);
  return Pose2((xi[0] * s - xi[1] * c1) / w, (xi[0] * c1 + xi[1] * s) / w, w);
}

Pose2 WheelKinematics::Displacement(const Eigen::VectorXd& delta) const {
  const Eigen::VectorXd rim = radius_m.cwiseProduct(delta);
  const Eigen::Vector3d xi = J.completeOrthogonalDecomposition().solve(rim);
  const Pose2 q = ExpTwist(xi);
  return Compose(Compose(Inverse(sensor_pose), q), sensor_pose);
}

WheelKinematics DifferentialDrive(const std::vector<std::string>& wheels, double radius_right_m, double radius_left_m,
                                  double track_m, const Pose2& sensor_pose) {
  WheelKinematics k;
  k.kind = "differential_drive";
  k.wheels = wheels;
  k.J = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(wheels.size()), 3);
  k.radius_m = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(wheels.size()));
  const int right = WheelIndex(wheels, "right");
  const int left = WheelIndex(wheels, "left");
  ROAMLAB_CHECK(right >= 0 && left >= 0, "DifferentialDrive: wheels 'right' and 'left' required");
  k.J.row(right) << 1.0, 0.0, 0.5 * track_m;
  k.J.row(left) << 1.0, 0.0, -0.5 * track_m;
  k.radius_m[right] = radius_right_m;
  k.radius_m[left] = radius_left_m;
  k.sensor_pose = sensor_pose;
  return k;
}

Result<WheelKinematics> NominalKinematics(const recording::Platform& platform, const std::vector<std::string>& wheels) {
  const auto m = static_cast<Eigen::Index>(wheels.size());
  const auto require_wheels = [&](const std::vector<std::string>& names) -> Status {
    for (const std::string& name : names) {
      if (WheelIndex(wheels, name) < 0) {
        return Status::Error("platform '" + platform.kind + "' needs an encoder column '" + name + "'");
      }
    }
    return Status::Ok();
  };
  WheelKinematics k;
  k.kind = platform.kind;
  k.wheels = wheels;
  k.J = Eigen::MatrixXd::Zero(m, 3);
  k.radius_m.resize(m);
  // The simulator's geometry keys (recording/wheel_kinematics.h, wheels in index order): its rows, scaled to rim
  // speeds, J_i = r J_rates_twist_i.
  if (UsesRecordingKeys(platform, wheels)) {
    Result<recording::WheelKinematics> rows = recording::NominalWheelKinematics(platform);
    if (!rows.ok()) return rows.status();
    if (rows.value().wheels() != m) {
      return Status::Error("platform '" + platform.kind + "' needs " + std::to_string(rows.value().wheels()) +
                           " encoder columns");
    }
    const double radius = platform.geometry.at("wheel_radius_m");
    k.J = radius * rows.value().J_rates_twist;
    k.radius_m.setConstant(radius);
    return k;
  }
  if (platform.kind == "differential_drive") {
    if (Status s = require_wheels({"right", "left"}); !s.ok()) return s;
    if (m != 2) return Status::Error("platform differential_drive needs exactly two encoder columns");
    Result<double> track = GeometryValue(platform, "track_m");
    if (!track.ok()) return track.status();
    k.J.row(WheelIndex(wheels, "right")) << 1.0, 0.0, 0.5 * track.value();
    k.J.row(WheelIndex(wheels, "left")) << 1.0, 0.0, -0.5 * track.value();
  } else if (platform.kind == "omni3") {
    if (m != 3) return Status::Error("platform omni3 needs exactly three encoder columns");
    Result<double> distance = GeometryValue(platform, "wheel_distance_m");
    if (!distance.ok()) return distance.status();
    for (Eigen::Index i = 0; i < m; ++i) {
      Result<double> angle = GeometryValue(platform, "wheel_angle_" + wheels[i] + "_rad");
      if (!angle.ok()) return angle.status();
      // Positive wheel rotation moves the robot counter-clockwise (+1, default) or clockwise (-1).
      const std::string direction_key = "wheel_direction_" + wheels[i];
      const auto direction = platform.geometry.find(direction_key);
      const double sign = direction == platform.geometry.end() ? 1.0 : direction->second;
      if (sign != 1.0 && sign != -1.0) return Status::Error("platform geometry." + direction_key + " must be 1 or -1");
      k.J.row(i) << -sign * std::sin(angle.value()), sign * std::cos(angle.value()), sign * distance.value();
    }
  } else if (platform.kind == "mecanum") {
    if (Status s = require_wheels({"front_left", "front_right", "rear_left", "rear_right"}); !s.ok()) return s;
    if (m != 4) return Status::Error("platform mecanum needs exactly four encoder columns");
    Result<double> wheelbase = GeometryValue(platform, "wheelbase_m");
    if (!wheelbase.ok()) return wheelbase.status();
    Result<double> track = GeometryValue(platform, "track_m");
    if (!track.ok()) return track.status();
    const double arm = 0.5 * (wheelbase.value() + track.value());
    k.J.row(WheelIndex(wheels, "front_left")) << 1.0, -1.0, -arm;
    k.J.row(WheelIndex(wheels, "front_right")) << 1.0, 1.0, arm;
    k.J.row(WheelIndex(wheels, "rear_left")) << 1.0, 1.0, -arm;
    k.J.row(WheelIndex(wheels, "rear_right")) << 1.0, -1.0, arm;
  } else if (platform.kind == "omni4") {
    if (Status s = require_wheels({"front_left", "front_right", "rear_left", "rear_right"}); !s.ok()) return s;
    if (m != 4) return Status::Error("platform omni4 needs exactly four encoder columns");
    Result<double> wheelbase = GeometryValue(platform, "wheelbase_m");
    if (!wheelbase.ok()) return wheelbase.status();
    Result<double> track = GeometryValue(platform, "track_m");
    if (!track.ok()) return track.status();
    // Rim-speed rows: the rate rows of unit radii, in the layout's wheel order.
    const Eigen::Matrix<double, 4, 3> rows =
        recording::Omni4RatesFromTwist(Eigen::Vector4d::Ones(), wheelbase.value(), track.value());
    const char* order[] = {"front_left", "front_right", "rear_left", "rear_right"};
    for (int i = 0; i < 4; ++i) k.J.row(WheelIndex(wheels, order[i])) = rows.row(i);
  } else if (platform.kind == "tricycle") {
    return TricycleKinematics(platform, k);
  } else {
    return Status::Error("no nominal odometry model for platform kind '" + platform.kind +
                         "' (differential_drive, omni3, mecanum, omni4, tricycle)");
  }
  for (Eigen::Index i = 0; i < m; ++i) {
    Result<double> radius = WheelRadius(platform, wheels[i]);
    if (!radius.ok()) return radius.status();
    k.radius_m[i] = radius.value();
  }
  return k;
}

Result<CensiCalibration> CalibrateDifferentialDrive(const TrainingSet& data) {
  const int right = WheelIndex(data.wheels, "right");
  const int left = WheelIndex(data.wheels, "left");
  if (right < 0 || left < 0) return Status::Error("Censi calibration needs wheels 'left' and 'right'");
  const int n = data.size();
  // Step 1: J21, J22 from the rotations (robust linear fit of s_theta on [delta_L, delta_R]).
  Eigen::MatrixXd X(n, 2);
  X.col(0) = data.delta.col(left);
  X.col(1) = data.delta.col(right);
  Result<HuberFit> rotation = FitHuberLinear(X, data.s, data.s_sigma);
  if (!rotation.ok()) return Status::Error("Censi calibration: " + rotation.status().message());
  const double J21 = rotation.value().W(2, 0);
  const double J22 = rotation.value().W(2, 1);
  if (!(J22 > 0.0) || !(J21 < 0.0)) return Status::Error("Censi calibration: the data show no usable rotation");
  // Step 2: M = sum G^T G over the pairs, phi = [l_x, l_y, b, cos l_theta, sin l_theta].
  Eigen::Matrix<double, 5, 5> M = Eigen::Matrix<double, 5, 5>::Zero();
  for (int k = 0; k < n; ++k) {
    const double dl = data.delta(k, left);
    const double dr = data.delta(k, right);
    const double th = J21 * dl + J22 * dr;
    const double nu = 0.5 * (J22 * dr - J21 * dl);  // forward travel / b
    const Pose2 c = ExpTwist(Eigen::Vector3d(nu, 0.0, th));
    const double cq = std::cos(th), sq = std::sin(th);
    const double sx = data.s(k, 0), sy = data.s(k, 1);
    Eigen::Matrix<double, 2, 5> G;
    G << 1.0 - cq, sq, -c[0], sx, -sy, -sq, 1.0 - cq, -c[1], sy, sx;
    M += G.transpose() * G;
  }
  const Eigen::Matrix3d A = M.topLeftCorner<3, 3>();
  const Eigen::Matrix<double, 3, 2> B = M.topRightCorner<3, 2>();
  const Eigen::LDLT<Eigen::Matrix3d> A_ldlt(A);
  if (A_ldlt.info() != Eigen::Success || !(A_ldlt.vectorD().array() > 0.0).all()) {
    return Status::Error("Censi calibration: the data do not constrain the sensor position and the track");
  }
  const Eigen::Matrix2d S = M.bottomRightCorner<2, 2>() - B.transpose() * A_ldlt.solve(B);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(S);
  Eigen::Vector2d phi2 = eig.eigenvectors().col(0).normalized();  // smallest eigenvalue first
  Eigen::Vector3d phi1 = -A_ldlt.solve(B * phi2);
  if (phi1[2] < 0.0) {
    phi1 = -phi1;
    phi2 = -phi2;
  }
  CensiCalibration out;
  out.track_m = phi1[2];
  if (!(out.track_m > 0.0)) return Status::Error("Censi calibration: no positive track fits the data");
  out.sensor_pose = Pose2(phi1[0], phi1[1], std::atan2(phi2[1], phi2[0]));
  // Step 3: the radii.
  out.radius_left_m = -J21 * out.track_m;
  out.radius_right_m = J22 * out.track_m;
  out.kinematics = DifferentialDrive(data.wheels, out.radius_right_m, out.radius_left_m, out.track_m, out.sensor_pose);
  return out;
}

}  // namespace roamlab::estimator::odometry
