#include "recording/wheel_kinematics.h"

#include <cmath>

#include <Eigen/Dense>

namespace roamlab::recording {

Eigen::Vector3d WheelKinematics::TwistFromRates(const Eigen::VectorXd& rates_radps) const {
  if (holonomic) return J_rates_twist.colPivHouseholderQr().solve(rates_radps);
  // Columns v_x and omega_z only.
  Eigen::MatrixXd J(J_rates_twist.rows(), 2);
  J << J_rates_twist.col(0), J_rates_twist.col(2);
  const Eigen::Vector2d twist = J.colPivHouseholderQr().solve(rates_radps);
  return Eigen::Vector3d(twist[0], 0.0, twist[1]);
}

bool IsWheeledPlatform(const std::string& kind) {
  return kind == "differential_drive" || kind == "omni3" || kind == "mecanum" || kind == "omni4";
}

Eigen::Matrix3d Omni3RatesFromTwist(const Eigen::Vector3d& radii_m, double distance_m) {
  constexpr double kPi = 3.14159265358979323846;
  Eigen::Matrix3d J;
  for (int i = 0; i < 3; ++i) {
    const double alpha = (60.0 + 120.0 * i) * kPi / 180.0;
    J.row(i) << -std::sin(alpha) / radii_m[i], std::cos(alpha) / radii_m[i], distance_m / radii_m[i];
  }
  return J;
}

Eigen::Matrix<double, 4, 3> MecanumRatesFromTwist(const Eigen::Vector4d& radii_m, double lx_plus_ly_m) {
  // Signs of v_y and of K omega_z per wheel (front left, front right, rear left, rear right).
  const double s_y[4] = {-1.0, 1.0, 1.0, -1.0};
  const double s_w[4] = {-1.0, 1.0, -1.0, 1.0};
  Eigen::Matrix<double, 4, 3> J;
  for (int i = 0; i < 4; ++i) J.row(i) << 1.0 / radii_m[i], s_y[i] / radii_m[i], s_w[i] * lx_plus_ly_m / radii_m[i];
  return J;
}

Eigen::Matrix<double, 4, 3> Omni4RatesFromTwist(const Eigen::Vector4d& radii_m, double wheelbase_m, double track_m) {
  const double c = 1.0 / std::sqrt(2.0);
  const double lever = (wheelbase_m + track_m) * c / 2.0;
  // Rolling directions (x, y) of front left, front right, rear left, rear right.
  const double d[4][2] = {{c, -c}, {-c, -c}, {c, c}, {-c, c}};
  Eigen::Matrix<double, 4, 3> J;
  for (int i = 0; i < 4; ++i) J.row(i) << d[i][0] / radii_m[i], d[i][1] / radii_m[i], -lever / radii_m[i];
  return J;
}

Eigen::Vector3d TricycleTwist(double wheel_rate_radps, double steering_rad, double radius_m, double wheel_to_axle_m) {
  const double rim_mps = radius_m * wheel_rate_radps;
  return Eigen::Vector3d(rim_mps * std::cos(steering_rad), 0.0, rim_mps * std::sin(steering_rad) / wheel_to_axle_m);
}

Result<WheelKinematics> NominalWheelKinematics(const Platform& platform) {
  const auto get = [&platform](const std::string& key, double* out) {
    const auto it = platform.geometry.find(key);
    if (it == platform.geometry.end() || !std::isfinite(it->second) || !(it->second > 0.0))
      return Status::Error("platform " + platform.kind + ": geometry '" + key + "' is missing or not positive");
    *out = it->second;
    return Status::Ok();
  };
  WheelKinematics k;
  if (platform.kind == "differential_drive") {
    double r = 0.0, baseline = 0.0;
    if (Status s = get("wheel_radius_m", &r); !s.ok()) return s;
    if (Status s = get("baseline_m", &baseline); !s.ok()) return s;
    k.J_rates_twist.resize(2, 3);
    k.J_rates_twist << 1.0 / r, 0.0, -0.5 * baseline / r,  //
        1.0 / r, 0.0, 0.5 * baseline / r;
    k.holonomic = false;
    return k;
  }
  if (platform.kind == "omni3") {
    double r = 0.0, distance = 0.0;
    if (Status s = get("wheel_radius_m", &r); !s.ok()) return s;
    if (Status s = get("wheel_distance_m", &distance); !s.ok()) return s;
    k.J_rates_twist = Omni3RatesFromTwist(Eigen::Vector3d::Constant(r), distance);
    k.holonomic = true;
    return k;
  }
  if (platform.kind == "mecanum") {
    double r = 0.0, lx = 0.0, ly = 0.0;
    if (Status s = get("wheel_radius_m", &r); !s.ok()) return s;
    if (Status s = get("half_length_m", &lx); !s.ok()) return s;
    if (Status s = get("half_width_m", &ly); !s.ok()) return s;
    k.J_rates_twist = MecanumRatesFromTwist(Eigen::Vector4d::Constant(r), lx + ly);
    k.holonomic = true;
    return k;
  }
  if (platform.kind == "omni4") {
    double r = 0.0, wheelbase = 0.0, track = 0.0;
    if (Status s = get("wheel_radius_m", &r); !s.ok()) return s;
    if (Status s = get("wheelbase_m", &wheelbase); !s.ok()) return s;
    if (Status s = get("track_m", &track); !s.ok()) return s;
    k.J_rates_twist = Omni4RatesFromTwist(Eigen::Vector4d::Constant(r), wheelbase, track);
    k.holonomic = true;
    return k;
  }
  return Status::Error("platform kind '" + platform.kind +
                       "' has no wheel kinematics (supported: differential_drive, omni3, mecanum, omni4)");
}

}  // namespace roamlab::recording
