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

bool IsWheeledPlatform(const std::string& kind) { return kind == "differential_drive"; }

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
  return Status::Error("platform kind '" + platform.kind + "' has no wheel kinematics (supported: differential_drive)");
}

}  // namespace roamlab::recording
