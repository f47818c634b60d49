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
//   skid_steer           the same rows, one per side (a side's wheels turn together): wheels 0 = left, 1 = right
//                        (with the encoder columns: `left`, `right`, or one per wheel front_left ... rear_right). B
//                        is the nominal track; turning, the tires scrub sideways, so the body turns slower than
//                        these rows say (the effective track is wider than B)
//   omni3                geometry: wheel_radius_m, wheel_distance_m (L, from O to each wheel's contact point)
//                        wheel i at alpha_i = 60, 180, 300 deg from x, rolling along the counter-clockwise tangent
//                        d_i = (-sin alpha_i, cos alpha_i) (omni rollers absorb the radial component):
//                        omega_i = (-sin alpha_i v_x + cos alpha_i v_y + L omega_z) / r
// Per-wheel keys (the OptiOdom importer's, importers/optiodom.h), read when the encoder columns are given: radius
// wheel_radius_<column>_m (else wheel_radius_m); differential_drive and skid_steer: columns `left` and `right` in any
// order, the track baseline_m (else track_m); omni3: wheel_angle_<column>_rad (alpha of that wheel) and
// wheel_direction_<column> (+1: a positive rotation pushes the body along the counter-clockwise tangent, as above;
// -1: along the clockwise one), omega_i = s_i (-sin alpha_i v_x + cos alpha_i v_y + L omega_z) / r_i.
//   mecanum              geometry: wheel_radius_m, half_length_m (lx), half_width_m (ly); wheels 0-3 front left,
//                        front right, rear left, rear right at (+-lx, +-ly), rolling along +x, 45 deg rollers in the
//                        X layout (models/mecanum.xml): with K = lx + ly
//                        omega_0 = (v_x - v_y - K omega_z) / r,  omega_1 = (v_x + v_y + K omega_z) / r,
//                        omega_2 = (v_x + v_y - K omega_z) / r,  omega_3 = (v_x - v_y + K omega_z) / r
//   omni4                geometry: wheel_radius_m, wheelbase_m (l1, front to back), track_m (l2, left to right);
//                        wheels 0-3 front left, front right, rear left, rear right at (+-l1/2, +-l2/2), omni rollers,
//                        the wheels turned 45 deg (the X layout of the OptiOdom robot), a positive rotation turning
//                        the robot clockwise: d_0 = (1, -1)/sqrt 2, d_1 = (-1, -1)/sqrt 2, d_2 = (1, 1)/sqrt 2,
//                        d_3 = (-1, 1)/sqrt 2; with K = (l1 + l2) / (2 sqrt 2)
//                        omega_i = (d_i . v - K omega_z) / r
// A tricycle (one steered and driven front wheel at distance L ahead of O, the centre of the unpowered rear axle) is
// not linear in its wheel rate alone: at steering angle delta (positive: turning counter-clockwise) the front rim
// speed v_w = r omega_w gives v_x = v_w cos delta, v_y = 0, omega_z = v_w sin delta / L (TricycleTwist).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "recording/recording.h"

namespace roamlab::recording {

struct WheelKinematics {
  Eigen::MatrixXd J_rates_twist;  // n x 3: wheel rates [rad/s] = J [v_x (m/s), v_y (m/s), omega_z (rad/s)]
  bool holonomic = false;         // false: v_y is zero by construction

  int wheels() const { return static_cast<int>(J_rates_twist.rows()); }
  // Least-squares body twist [v_x, v_y, omega_z] from wheel rates (n), v_y = 0 when not holonomic.
  Eigen::Vector3d TwistFromRates(const Eigen::VectorXd& rates_radps) const;
};

// Whether the platform kind is one of the wheeled kinds above.
bool IsWheeledPlatform(const std::string& kind);
// The nominal kinematics, rows in the wheel order above; errors name the missing or bad geometry key (without a file:
// the caller adds it).
Result<WheelKinematics> NominalWheelKinematics(const Platform& platform);
// The same with rows in the order of `columns` (the wheel_encoders stream's column names), reading the per-wheel keys
// above when present; empty columns: as NominalWheelKinematics(platform).
Result<WheelKinematics> NominalWheelKinematics(const Platform& platform, const std::vector<std::string>& columns);

// The rows above for given geometry (n x 3): omni3 with per-wheel radii r_i and distance L; mecanum with per-wheel
// radii and K = lx + ly. Shared with the estimator's error models, which take the geometry as parameters.
Eigen::Matrix3d Omni3RatesFromTwist(const Eigen::Vector3d& radii_m, double distance_m);
Eigen::Matrix<double, 4, 3> MecanumRatesFromTwist(const Eigen::Vector4d& radii_m, double lx_plus_ly_m);
// omni4 with per-wheel radii, wheelbase l1 and track l2.
Eigen::Matrix<double, 4, 3> Omni4RatesFromTwist(const Eigen::Vector4d& radii_m, double wheelbase_m, double track_m);
// Tricycle body twist [v_x, v_y, omega_z] at O from the front wheel's rate [rad/s], its steering angle [rad] (the
// true angle: a measured angle plus the steering offset), radius [m] and distance to the rear axle L [m].
Eigen::Vector3d TricycleTwist(double wheel_rate_radps, double steering_rad, double radius_m, double wheel_to_axle_m);

}  // namespace roamlab::recording
