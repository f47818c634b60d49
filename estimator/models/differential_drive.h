// Differential-drive wheel odometer in measurement space (seed 000, Section VI: a logical odometer built on the
// robot's forward kinematics, eqs. 5-8, with the wheel radii and the baseline as calibration parameters). The body
// velocities between two poses predict the two wheel rates, and the error is the difference to the encoder rates.
//
//   v^(O), omega^(O) = VelocitiesBetween(pose_k, pose_k+1, dt)        (eq. 7 inverted; middle of the interval)
//   z_L_hat = (v_x - omega_z B / 2) / r_L,   z_R_hat = (v_x + omega_z B / 2) / (rho r_R)
//   e = [z_L_hat - z_L;  z_R_hat - z_R;  v_y;  v_z;  omega_x;  omega_y] + eta                      e in R^6
//
// The forward kinematics that the seed's form (eqs. 5-8 with the readings as inputs) would use, and that the graph
// builder uses for a new pose's initial guess (eq. 7), is the inverse of the first two rows:
//   v_x = (rho r_R z_R + r_L z_L) / 2,   omega_z = (rho r_R z_R - r_L z_L) / B,   v_y = v_z = 0.
// Why measurement space: as for the Ackermann odometer (ackermann_velocity.h), the reading noise then stays additive
// and its covariance constant, so calibrating r_L, r_R and B is not biased by errors in variables. O is the middle of
// the wheel axle, so the odometer needs no displacement or misalignment (S = O).
//
// Frames: O at the middle of the wheel axle (x forward, z up). Measurements: z_L, z_R mean wheel rates over
// [t_k, t_k+1] [rad/s], positive rolling forward (the difference of two cumulative encoder angles over dt).
// Calibration: radius_left r_L [m], radius_right r_R [m], baseline B [m] (distance between the contact points; for a
// skid-steer robot the effective track, wider than the geometric one when the tires scrub in turns), and
// right_left_ratio rho [-] (default 1), a multiplier of r_R. rho lets a configuration that believes both wheels equal
// (radius_left and radius_right mapped to one parameter) free their ratio r_R_eff / r_L = rho on its own: the
// reality-gap diagnosis's wheel_radius_asymmetry candidate (gap/diagnose.h); freeing rho together with two separate
// radii leaves the product rho r_R unobservable. Deformed tires (the reality-gap diagnosis's wheel_deformation
// candidate): a tire that is not round rolls on a radius that depends on the wheel angle theta. For an oval (elliptic)
// tire of semi-axes r + d and r the centre's height above the contact, which is the ground speed per wheel rate, is
// sqrt((r+d)^2 cos^2 + r^2 sin^2) = r + d/2 + (d/2) cos 2(theta - phi) to first order in d: a mean radius (the radius
// slot) plus the second harmonic
//     r(theta) = r_mean + a cos 2 theta + b sin 2 theta,        deformation = (a, b) [m] per wheel, default 0,
// whose amplitude sqrt(a^2 + b^2) is half the ovality d. Over an interval the encoder turns the wheel from theta_k to
// theta_k+1, and the rim travels the integral of r(theta) dtheta, so the wheel row uses the interval's effective
// radius r_mean + a C + b S with C = (sin 2 theta_k+1 - sin 2 theta_k) / (2 dtheta) and S = -(cos 2 theta_k+1 -
// cos 2 theta_k) / (2 dtheta) (cos 2 theta and sin 2 theta at theta_k for dtheta -> 0): exact, and linear in (a, b).
// theta is the recording's cumulative encoder angle, whose zero is arbitrary; (a, b) absorb the phase.
// Noise eta = [sigma_wheel (rad/s), sigma_wheel, lateral (m/s), vertical (m/s), tilt (rad/s), tilt]: encoder
// quantization and slip on the wheel rows, the slack of the planar, non-holonomic assumptions (no sideways slip, no
// motion off the floor, no roll or pitch rate on a flat floor) on the others. Without the last two rows the pose's
// roll and pitch would be free between the samples of any other planar sensor (a scan matcher).
// Slip is not Gaussian: the configuration should give the stream a robust loss (seed Section VI).
// Variables: pose at t_k, pose at t_k+1 (PoseBlock), r_L, r_R, B, rho (ScalarBlock each), deformation_left,
// deformation_right (VectorBlock<2>). Jacobians by the jets
// (factor.h); tests/estimator/models/differential_drive_test.cc checks them against central differences.
#pragma once

#include <cmath>
#include <tuple>

#include <Eigen/Core>

#include "common/check.h"
#include "estimator/geometry.h"
#include "estimator/manifold.h"

namespace roamlab::estimator {

class DifferentialDriveError {
 public:
  using Blocks = std::tuple<PoseBlock, PoseBlock, ScalarBlock, ScalarBlock, ScalarBlock, ScalarBlock, VectorBlock<2>,
                            VectorBlock<2>>;
  static constexpr int kResidualDim = 6;
  static constexpr int kNoiseDim = 6;
  static constexpr bool kAdditiveNoise = true;  // e = f(x) + eta

  // z_left_radps, z_right_radps: mean wheel rates over the interval; dt_s = t_k+1 - t_k > 0; harmonics_left/right:
  // (C, S) of each wheel's interval (DeformationHarmonics; zero when the deformation slots are not used).
  DifferentialDriveError(double z_left_radps, double z_right_radps, double dt_s,
                         const Eigen::Vector2d& harmonics_left = Eigen::Vector2d::Zero(),
                         const Eigen::Vector2d& harmonics_right = Eigen::Vector2d::Zero())
      : z_left_radps_(z_left_radps),
        z_right_radps_(z_right_radps),
        dt_s_(dt_s),
        harmonics_left_(harmonics_left),
        harmonics_right_(harmonics_right) {
    ROAMLAB_CHECK(dt_s > 0.0, "differential drive dt " << dt_s);
  }

  // (C, S) of a wheel turning from theta0_rad to theta1_rad (header comment).
  static Eigen::Vector2d DeformationHarmonics(double theta0_rad, double theta1_rad) {
    const double d = theta1_rad - theta0_rad;
    if (std::abs(d) < 1e-9) return {std::cos(2.0 * theta0_rad), std::sin(2.0 * theta0_rad)};
    return {(std::sin(2.0 * theta1_rad) - std::sin(2.0 * theta0_rad)) / (2.0 * d),
            -(std::cos(2.0 * theta1_rad) - std::cos(2.0 * theta0_rad)) / (2.0 * d)};
  }

  template <typename T>
  bool operator()(const T* const* x, const T* noise, T* error) const {
    Vector3<T> v_body, omega_body;
    VelocitiesBetween<T>(PoseFromArray(x[0]), PoseFromArray(x[1]), T(dt_s_), &v_body, &omega_body);
    const T radius_left = x[2][0] + x[6][0] * harmonics_left_[0] + x[6][1] * harmonics_left_[1];
    const T radius_right = (x[3][0] + x[7][0] * harmonics_right_[0] + x[7][1] * harmonics_right_[1]) * x[5][0];
    const T half_turn = omega_body.z() * x[4][0] * T(0.5);
    error[0] = (v_body.x() - half_turn) / radius_left - T(z_left_radps_) + noise[0];
    error[1] = (v_body.x() + half_turn) / radius_right - T(z_right_radps_) + noise[1];
    error[2] = v_body.y() + noise[2];
    error[3] = v_body.z() + noise[3];
    error[4] = omega_body.x() + noise[4];
    error[5] = omega_body.y() + noise[5];
    return true;
  }

  // Forward kinematics: the body velocities of O from the wheel rates (header comment); radius_right_m is rho r_R.
  static void BodyVelocity(double z_left_radps, double z_right_radps, double radius_left_m, double radius_right_m,
                           double baseline_m, Eigen::Vector3d* v_body, Eigen::Vector3d* omega_body) {
    const double rim_left = radius_left_m * z_left_radps;
    const double rim_right = radius_right_m * z_right_radps;
    *v_body = Eigen::Vector3d(0.5 * (rim_right + rim_left), 0.0, 0.0);
    *omega_body = Eigen::Vector3d(0.0, 0.0, (rim_right - rim_left) / baseline_m);
  }

 private:
  double z_left_radps_;
  double z_right_radps_;
  double dt_s_;
  Eigen::Vector2d harmonics_left_, harmonics_right_;
};

}  // namespace roamlab::estimator
