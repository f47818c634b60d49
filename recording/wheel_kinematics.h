// Nominal kinematics of a wheeled platform, from the recording's platform description (kind and geometry). Shared by
// the estimator (initial guesses), the evaluation (encoder-only velocities) and the simulator (the drivers' inverse
// kinematics), so that all three read the same geometry keys.
//
// A wheel i at p_i = (x_i, y_i) in O, rolling direction d_i (the direction in which its rim pushes the body when the
// wheel turns positive) and radius r_i turns at
//     omega_i = d_i . (v + omega_z e_z x p_i) / r_i = J_i [v_x, v_y, omega_z]^T          [rad/s]
// where v is the planar velocity of O in O [m/s] and omega_z the yaw rate [rad/s]. Omnidirectional and mecanum rollers
// absorb the component along the roller axis; a standard wheel cannot, so a differential drive has v_y = 0.
//
//   differential_drive   geometry: wheel_radius_m, baseline_m (distance between the wheel contact points)
//                        wheels: 0 = left at (0, +B/2), 1 = right at (0, -B/2), both rolling along +x:
//                        omega_left = (v_x - omega_z B/2) / r,  omega_right = (v_x + omega_z B/2) / r
#pragma once

#include <Eigen/Core>

#include "common/status.h"
#include "recording/recording.h"

namespace roamlab::recording {

struct WheelKinematics {
  Eigen::MatrixXd J_rates_twist;   // n x 3: wheel rates [rad/s] = J [v_x (m/s), v_y (m/s), omega_z (rad/s)]
  bool holonomic = false;          // false: v_y is zero by construction

  int wheels() const { return static_cast<int>(J_rates_twist.rows()); }
  // Least-squares body twist [v_x, v_y, omega_z] from wheel rates (n), v_y = 0 when not holonomic.
  Eigen::Vector3d TwistFromRates(const Eigen::VectorXd& rates_radps) const;
};

// Whether the platform kind is one of the wheeled kinds above.
bool IsWheeledPlatform(const std::string& kind);
// The nominal kinematics; errors name the missing or bad geometry key (without a file: the caller adds it).
Result<WheelKinematics> NominalWheelKinematics(const Platform& platform);

}  // namespace roamlab::recording
