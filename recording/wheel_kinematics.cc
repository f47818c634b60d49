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
  return kind == "differential_drive" || kind == "skid_steer" || kind == "omni3" || kind == "mecanum" ||
         kind == "omni4";
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

namespace {

// A positive, finite geometry value; errors name the key.
Status PositiveKey(const Platform& platform, const std::string& key, double* out) {
  const auto it = platform.geometry.find(key);
  if (it == platform.geometry.end() || !std::isfinite(it->second) || !(it->second > 0.0))
    return Status::Error("platform " + platform.kind + ": geometry '" + key + "' is missing or not positive");
  *out = it->second;
  return Status::Ok();
}

// The first of `keys` the geometry has (the last one when none, for the message).
std::string FirstPresent(const Platform& platform, const std::vector<std::string>& keys) {
  for (const std::string& key : keys)
    if (platform.geometry.count(key) > 0) return key;
  return keys.back();
}

// Wheel radius of a named column: wheel_radius_<column>_m, else wheel_radius_m.
Status ColumnRadius(const Platform& platform, const std::string& column, double* out) {
  return PositiveKey(platform, FirstPresent(platform, {"wheel_radius_" + column + "_m", "wheel_radius_m"}), out);
}

// The side of a differential_drive or skid_steer encoder column: -1 left (`left`, `*_left`), +1 right, 0 neither.
double Side(const std::string& column) {
  const auto ends = [&column](const std::string& suffix) {
    return column.size() >= suffix.size() && column.compare(column.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  if (column == "left" || ends("_left")) return -1.0;
  if (column == "right" || ends("_right")) return 1.0;
  return 0.0;
}

// differential_drive and skid_steer: the row of each column's side (`left` and `right`, or a skid steer's
// front_left ... rear_right), in the given order.
Result<WheelKinematics> TwoSides(const Platform& platform, const std::vector<std::string>& columns) {
  const std::vector<std::string> names = columns.empty() ? std::vector<std::string>{"left", "right"} : columns;
  const bool two = platform.kind == "differential_drive";
  bool named = !two || names.size() == 2, left = false, right = false;
  for (const std::string& c : names) {
    named = named && Side(c) != 0.0 && (!two || c == "left" || c == "right");
    left = left || Side(c) < 0.0;
    right = right || Side(c) > 0.0;
  }
  if (!named || !left || !right)
    return Status::Error("platform " + platform.kind + ": the encoder columns must be left and right" +
                         (platform.kind == "skid_steer" ? " (or front_left, front_right, rear_left, rear_right)" : ""));
  double baseline = 0.0;
  if (Status s = PositiveKey(platform, FirstPresent(platform, {"baseline_m", "track_m"}), &baseline); !s.ok()) return s;
  WheelKinematics k;
  k.J_rates_twist.resize(static_cast<Eigen::Index>(names.size()), 3);
  for (std::size_t i = 0; i < names.size(); ++i) {
    double r = 0.0;
    if (Status s = ColumnRadius(platform, columns.empty() ? std::string() : names[i], &r); !s.ok()) return s;
    k.J_rates_twist.row(static_cast<Eigen::Index>(i)) << 1.0 / r, 0.0, Side(names[i]) * 0.5 * baseline / r;
  }
  k.holonomic = false;
  return k;
}

// omni3 from the per-wheel angle and direction keys of `columns`.
Result<WheelKinematics> Omni3PerWheel(const Platform& platform, const std::vector<std::string>& columns) {
  if (columns.size() != 3) return Status::Error("platform omni3: needs three encoder columns");
  double distance = 0.0;
  if (Status s = PositiveKey(platform, "wheel_distance_m", &distance); !s.ok()) return s;
  WheelKinematics k;
  k.J_rates_twist.resize(3, 3);
  for (int i = 0; i < 3; ++i) {
    const std::string& c = columns[static_cast<std::size_t>(i)];
    double r = 0.0;
    if (Status s = ColumnRadius(platform, c, &r); !s.ok()) return s;
    const auto angle = platform.geometry.find("wheel_angle_" + c + "_rad");
    if (angle == platform.geometry.end() || !std::isfinite(angle->second))
      return Status::Error("platform omni3: geometry 'wheel_angle_" + c + "_rad' is missing or not finite");
    const auto direction = platform.geometry.find("wheel_direction_" + c);
    const double sign = direction == platform.geometry.end() ? 1.0 : direction->second;
    if (sign != 1.0 && sign != -1.0)
      return Status::Error("platform omni3: geometry 'wheel_direction_" + c + "' must be 1 or -1");
    const double a = angle->second;
    k.J_rates_twist.row(i) << -sign * std::sin(a) / r, sign * std::cos(a) / r, sign * distance / r;
  }
  k.holonomic = true;
  return k;
}

}  // namespace

Result<WheelKinematics> NominalWheelKinematics(const Platform& platform) {
  return NominalWheelKinematics(platform, {});
}

Result<WheelKinematics> NominalWheelKinematics(const Platform& platform, const std::vector<std::string>& columns) {
  const auto get = [&platform](const std::string& key, double* out) { return PositiveKey(platform, key, out); };
  const auto count = [&platform, &columns](int n) -> Status {
    if (columns.empty() || static_cast<int>(columns.size()) == n) return Status::Ok();
    return Status::Error("platform " + platform.kind + ": needs " + std::to_string(n) + " encoder columns, not " +
                         std::to_string(columns.size()));
  };
  WheelKinematics k;
  if (platform.kind == "differential_drive" || platform.kind == "skid_steer") return TwoSides(platform, columns);
  if (platform.kind == "omni3") {
    if (!columns.empty() && platform.geometry.count("wheel_angle_" + columns.front() + "_rad") > 0)
      return Omni3PerWheel(platform, columns);
    if (Status s = count(3); !s.ok()) return s;
    double r = 0.0, distance = 0.0;
    if (Status s = get("wheel_radius_m", &r); !s.ok()) return s;
    if (Status s = get("wheel_distance_m", &distance); !s.ok()) return s;
    k.J_rates_twist = Omni3RatesFromTwist(Eigen::Vector3d::Constant(r), distance);
    k.holonomic = true;
    return k;
  }
  if (platform.kind == "mecanum") {
    if (Status s = count(4); !s.ok()) return s;
    double r = 0.0, lx = 0.0, ly = 0.0;
    if (Status s = get("wheel_radius_m", &r); !s.ok()) return s;
    if (Status s = get("half_length_m", &lx); !s.ok()) return s;
    if (Status s = get("half_width_m", &ly); !s.ok()) return s;
    k.J_rates_twist = MecanumRatesFromTwist(Eigen::Vector4d::Constant(r), lx + ly);
    k.holonomic = true;
    return k;
  }
  if (platform.kind == "omni4") {
    if (Status s = count(4); !s.ok()) return s;
    double r = 0.0, wheelbase = 0.0, track = 0.0;
    if (Status s = get("wheel_radius_m", &r); !s.ok()) return s;
    if (Status s = get("wheelbase_m", &wheelbase); !s.ok()) return s;
    if (Status s = get("track_m", &track); !s.ok()) return s;
    k.J_rates_twist = Omni4RatesFromTwist(Eigen::Vector4d::Constant(r), wheelbase, track);
    k.holonomic = true;
    return k;
  }
  return Status::Error("platform kind '" + platform.kind +
                       "' has no wheel kinematics (supported: differential_drive, skid_steer, omni3, mecanum, omni4)");
}

}  // namespace roamlab::recording
