// Ackermann-steering odometer in measurement space (seed 000, eq. 15 inverted), with the tires' cornering compliance,
// the rear axle's thrust angle, the height of O above the ground contact and the driven tires' longitudinal slip: the
// body velocities between two poses predict the rear-wheel speed and the handlebar angle, and the error is the
// difference to the readings.
//
//   v^(O), omega^(O) = VelocitiesBetween(pose_k, pose_k+1, dt)          (eq. 7 inverted; middle of the interval)
//   v           = v^(O) + omega x (0, 0, -h) = (v^(O)_x - h omega_y, v^(O)_y + h omega_x, v^(O)_z)
//                                                                        the rear contact's velocity (h below O)
//   a_y         = v_x omega_z                                            lateral (centripetal) acceleration [m/s^2]
//   v_roll      = v_x cos(alpha) + v_y sin(alpha)                        rear wheels' rolling speed [m/s]
//   sigma       = 1 + s_f f_x + s_p g sin(theta)                         driven wheels' over-reading (slip)
//   z_v_hat     = v_roll sigma / k_v                                     k_v = kv_over_L * L
//   delta       = atan((L omega_z + v_y) / v_x) + c_front a_y            steered angle of the front wheels
//   z_theta_hat = (delta - k_gamma) / k_theta                           (eq. 15: omega_z = (k_v / L) v tan(delta))
//   e = [z_v_hat - z_v + w_v;  z_theta_hat - z_theta;  v_y - v_x tan(alpha) + c_rear a_y + w_lat;
//        v_z - d omega_y + w_vert] + eta                                 e in R^4
//
// Ground contact (h [m], d [m]; both 0 by default, eq. 15 at O). Eq. 15's constraints hold where the rear tires touch
// the ground, not at O when O is at the wheel centres, h = the wheel radius above the contact: a chassis pitching at
// omega_y moves O forward by h omega_y over the contact, and the wheel (its hub turns with the chassis) reads the
// contact's speed v^(O)_x - h omega_y; rolling at omega_x moves O sideways by -h omega_x without any tire slip. And
// on curved ground a chassis resting on both axles pitches with the chord between the contacts, while the rear
// contact moves along the ground's tangent: the two differ by half the angle the ground turns over the wheelbase, so
// the contact moves along O's z at d omega_y with d = L / 2 (crest: nose going down, omega_y > 0, v_z > 0).
// tools/atv_odometer_residuals.py regresses the MuJoCo ATV's noise-free readings on the rates: the speed row follows
// omega_y, the lateral row omega_x (besides a_y, the cornering compliance below) and the vertical row omega_y with
// d = L / 2, as this geometry predicts.
//
// Cornering compliance. Eq. 15 assumes rolling without side slip. Real tires (and MuJoCo's soft contacts) carry the
// centripetal force by slipping sideways in proportion to it: the rear axle drifts outwards, v_y = -c_rear a_y
// (c_rear [s], m/s of side slip per m/s^2), and the front wheels' velocity points c_front a_y (c_front [rad s^2/m])
// less into the turn than they are steered (understeer): the front axle moves along atan((L omega_z + v_y) / v_x).
// With c_front = c_rear = 0 (their defaults) this is eq. 15 with the non-holonomic constraints. On the MuJoCo ATV the
// two terms explain most of the contact's side velocity and of the steering row's residual
// (tools/atv_odometer_residuals.py fits them).
//
// Understeer as a slip velocity (option front_slip_velocity, default off). MuJoCo's soft contacts let a tire slip at a
// velocity proportional to the force it carries (as the rear axle's v_y = -c_rear a_y above), not at an angle: the
// front axle drifts outwards at c_front a_y [m/s] (c_front [s]), so it moves along atan((L omega_z + v_y) / v_x) while
// steered at
//   delta = atan((L omega_z + v_y + c_front a_y) / v_x),
// an angle c_front a_y / v_x = c_front omega_z to first order: the angle form's coefficient is this one over the speed
// at which the drive corners. On the MuJoCo ATV the slip-velocity coefficient is the same on drives that corner at
// different speeds, the angle form's is not (tools/atv_understeer_fit.py fits both, noise-free, at the contact).
//
// Rear-axle thrust angle alpha [rad] (a misaligned rear axle: both rear wheels turned about z by alpha, positive
// counter-clockwise). The rear wheels roll along d = (cos alpha, sin alpha) in O, so without side slip O's velocity
// is v_roll d: v_y = v_x tan(alpha) (the vehicle crabs: its course is its heading plus alpha) and the speed sensor
// reads v_roll = v . d. The front axle, L ahead, moves at (v_x, v_y + L omega_z), so the steering row keeps its form;
// with v_y = v_x tan(alpha) it says omega_z = v_x (tan(delta) - tan(alpha)) / L: at zero handlebar the vehicle turns
// at -v_x tan(alpha) / L. To first order that yaw rate is a steering offset (k_gamma = -alpha); what tells them apart
// is the crab, v_y, seen only against a heading reference that is not itself calibrated to the rear axle (with the
// IMU's misalignment free, a rotation of O by alpha absorbs the crab, and only alpha sin^2(delta), their difference on
// the steering row, is left). alpha = 0 (the default) is the model above.
//
// Coloured disturbance w = (w_v, w_lat, w_vert) [m/s] (slot disturbance, default 0 and constant): what the speed,
// lateral and vertical rows still see once the terms above are modelled is not white (suspension and terrain: on the
// MuJoCo ATV correlated over about a second, tools/atv_odometer_residuals.py). Declared time-varying with a
// first-order Gauss-Markov process per component (EST.yaml: process {type: gauss_markov, sigma: [...], tau_s: [...]}),
// w is one more state per pose that the IMU and the GPS can observe, instead of white noise that claims to average
// out over a second; eta keeps the white part.
//
// Why not the seed's form (ackermann_odometer.h, eqs. 7-8 with the readings as inputs): there the reading noise
// passes through the nonlinear model, so the error covariance of eq. 1 depends on the parameters, and the
// Gauss-Newton fixed point (which holds the covariance constant within an iteration) regresses the precise motion on
// noisy readings: an errors-in-variables bias. With sensor noise on, the seed form estimates kv_over_L low by more than
// its reported standard deviation (tests/estimator/calibration_test.cc); here the noise is additive on the readings,
// the covariance is constant, and the least-squares problem is the likelihood of the readings themselves.
//
// Longitudinal slip (the simulator's longitudinal_slip and slope_slip effects, sim/scenario.h). A driven tire carries
// its traction force by slipping: the wheel turns faster than the ground passes, v_wheel = v (1 + s) with the slip
// ratio s growing with the force. The recording has no force: the traction per unit mass is the forward specific force
// f_x = a_x + g sin(theta) [m/s^2] (aerodynamic drag and rolling resistance aside), read from the IMU (an input of the
// factor, in O: the accelerometer's reading turned by the believed mounting; 0 without the input), so s = s_f f_x with
// s_f (slot slip_per_mps2) [s^2/m]. slope_slip: a slip that follows the slope only, s = s_p g sin(theta), theta the
// pitch of O at the middle of the interval (sin(theta) = e_z^T R_mid e_x, positive nose up; from the poses, so no
// input), s_p (slot slope_slip_per_mps2) [s^2/m]. The two differ by the acceleration a_x, which only s_f follows. Both
// 0 (the defaults): the speed row above without slip. A constant error of f_x (the mounting's pitch error times g) only
// scales the speed row: kv_over_L absorbs it.
//
// Frames: O is the middle of the rear axle (x forward, z up). Measurements: z_v rear-wheel speed with the nominal
// wheel radius [m/s], z_theta handlebar angle [rad], both over [t_k, t_k+1]; input f_x [m/s^2]. Calibration:
// kv_over_L [1/m], k_theta [-], k_gamma [rad], c_front [rad s^2/m; s with front_slip_velocity], c_rear [s], alpha
// [rad], s_f [s^2/m], s_p [s^2/m], w [m/s]; the wheelbase L [m], h and d [m] are known. Noise eta =
// [sigma_v (m/s), sigma_theta (rad), lateral (m/s), vertical (m/s)], the last two the uncertainty of the non-holonomic
// assumptions (no unmodelled sideways slip, no motion off the ground). Eq. 15 says nothing about roll and pitch
// rates, and on hills they are not zero (the terrain tilts the vehicle): pretending they are pulls the estimated
// attitude flat and biases the IMU misalignment, so this form leaves them to the other sensors. Below
// kMinSteeringSpeed the steering angle does not affect the motion, so its error is zero (eta only).
// Variables: pose at t_k, pose at t_k+1 (PoseBlock), kv_over_L, k_theta, k_gamma, c_front, c_rear, alpha, s_f, s_p
// (ScalarBlock each), w (Vector3Block).
//
// Jacobians (Linearize; so3_jacobians.h for Jr, Jr^-1, Jl^-1 = (Jr^-1)^T). VelocitiesBetween computes
// phi = Log(q_k^-1 q_k+1), omega = phi / dt, q_mid = q_k Exp(phi / 2) and v = R_mid^T (p_k+1 - p_k) / dt, so
//   dphi/dtheta_k = -Jl^-1(phi),  dphi/dtheta_k+1 = Jr^-1(phi),  dv/dp_k = -R_mid^T / dt = -dv/dp_k+1,
//   dv/dtheta = [v]x eps/dtheta  ((R_mid Exp(eps))^T u = R_mid^T u + [R_mid^T u]x eps), where eps, the right
//   perturbation of q_mid, is (q_k Exp(d) Exp(psi + dpsi) = q_mid Exp(R(psi)^T d) Exp(Jr(psi) dpsi), psi = phi / 2)
//   eps/dtheta_k = R(phi/2)^T - Jr(phi/2) Jl^-1(phi) / 2,   eps/dtheta_k+1 = Jr(phi/2) Jr^-1(phi) / 2.
// The rows in the contact velocity v and omega_z, with delta = atan(r) + c_a a_y, r = (L omega_z + v_y + c_s a_y) /
// v_x (c_a = c_front, c_s = 0; with front_slip_velocity c_a = 0, c_s = c_front) and s = 1 / (1 + r^2) (steering
// row zero below kMinSteeringSpeed): de_v = sigma (cos(alpha) dv_x + sin(alpha) dv_y) / k_v + v_roll s_p g
// dsin(theta) / k_v with dsin(theta)/deps = -e_z^T R_mid [e_x]x;  k_theta de_theta = (c_a omega_z - s (r - c_s
// omega_z) / v_x) dv_x + s / v_x dv_y + (s (L / v_x + c_s) + c_a v_x) domega_z;  de_lat = (c_rear omega_z -
// tan(alpha)) dv_x + dv_y + c_rear v_x domega_z;  de_vert = dv_z - d domega_y; and dv/domega = [[0, -h, 0], [h, 0, 0],
// [0, 0, 0]]. Parameters: de_v/dkv_over_L = -v_roll sigma / (kv_over_L^2 L), de_theta/dk_theta = -(delta - k_gamma) /
// k_theta^2, de_theta/dk_gamma = -1 / k_theta, de_theta/dc_front = a_y / k_theta (s omega_z / k_theta with
// front_slip_velocity), de_lat/dc_rear = a_y,
// de_v/dalpha = (v_y cos(alpha) - v_x sin(alpha)) sigma / k_v, de_lat/dalpha = -v_x (1 + tan^2(alpha)),
// de_v/ds_f = v_roll f_x / k_v, de_v/ds_p = v_roll g sin(theta) / k_v; de/dw: ones at (speed, w_v), (lateral, w_lat),
// (vertical, w_vert).
#pragma once

#include <cmath>
#include <tuple>

#include <Eigen/Core>

#include "common/check.h"
#include "estimator/geometry.h"
#include "estimator/manifold.h"
#include "estimator/so3_jacobians.h"

namespace roamlab::estimator {

// AckermannVelocityError's options (header comment): where it takes its rows, h = contact_height_m and d =
// pitch_lever_m (the default 0, 0 is eq. 15 at O), and the form of the understeer: front_slip_velocity false (the
// default) c_front [rad s^2/m] an angle, true c_front [s] the front axle's side slip velocity per a_y.
struct AckermannOptions {
  double contact_height_m = 0.0;
  double pitch_lever_m = 0.0;
  bool front_slip_velocity = false;
};

class AckermannVelocityError {
 public:
  using Blocks = std::tuple<PoseBlock, PoseBlock, ScalarBlock, ScalarBlock, ScalarBlock, ScalarBlock, ScalarBlock,
                            ScalarBlock, ScalarBlock, ScalarBlock, Vector3Block>;
  static constexpr int kResidualDim = 4;
  static constexpr int kNoiseDim = 4;
  static constexpr bool kAdditiveNoise = true;      // e = f(x) + eta
  static constexpr double kMinSteeringSpeed = 0.2;  // [m/s]

  using Options = AckermannOptions;

  // forward_specific_force_mps2: f_x, the IMU's specific force along O's x over the interval (0: no input).
  AckermannVelocityError(double z_v_mps, double z_theta_rad, double wheelbase_m, double dt_s, Options options = {},
                         double forward_specific_force_mps2 = 0.0)
      : z_v_mps_(z_v_mps),
        z_theta_rad_(z_theta_rad),
        wheelbase_m_(wheelbase_m),
        dt_s_(dt_s),
        options_(options),
        forward_specific_force_mps2_(forward_specific_force_mps2) {
    ROAMLAB_CHECK(wheelbase_m > 0.0 && dt_s > 0.0, "Ackermann wheelbase " << wheelbase_m << " dt " << dt_s);
  }

  template <typename T>
  bool operator()(const T* const* x, const T* noise, T* error) const {
    using std::abs;
    using std::atan;
    using std::cos;
    using std::sin;
    using std::tan;
    Vector3<T> v_odom, omega_body;
    const Pose<T> pose_k = PoseFromArray(x[0]);
    VelocitiesBetween<T>(pose_k, PoseFromArray(x[1]), T(dt_s_), &v_odom, &omega_body);
    const T h(options_.contact_height_m);
    const Vector3<T> v_body(v_odom.x() - h * omega_body.y(), v_odom.y() + h * omega_body.x(), v_odom.z());
    const T& kv_over_l = x[2][0];
    const T& k_theta = x[3][0];
    const T& k_gamma = x[4][0];
    const T& c_front = x[5][0];
    const T& c_rear = x[6][0];
    const T& alpha = x[7][0];
    const T& slip_f = x[8][0];
    const T& slip_p = x[9][0];
    const T* const w = x[10];
    const T a_y = v_body.x() * omega_body.z();
    const T v_roll = v_body.x() * cos(alpha) + v_body.y() * sin(alpha);
    // The pitch of O at the middle of the interval, as VelocitiesBetween's q_mid.
    const Quaternion<T> q_mid = pose_k.q_world_body * QuaternionExp<T>(omega_body * T(0.5 * dt_s_));
    const T sin_pitch = (q_mid * Vector3<T>::UnitX()).z();
    const T slip = T(1.0) + slip_f * T(forward_specific_force_mps2_) + slip_p * T(kStandardGravity) * sin_pitch;
    error[0] = v_roll * slip / (kv_over_l * T(wheelbase_m_)) - T(z_v_mps_) + w[0] + noise[0];
    if (std::abs(ValueOf(v_body.x())) >= kMinSteeringSpeed) {
      // The understeer as an angle (c_angle = c_front) or as the front axle's side slip velocity (c_slip = c_front).
      const T c_angle = options_.front_slip_velocity ? T(0.0) : c_front;
      const T c_slip = options_.front_slip_velocity ? c_front : T(0.0);
      const T delta = atan((T(wheelbase_m_) * omega_body.z() + v_body.y() + c_slip * a_y) / v_body.x()) + c_angle * a_y;
      error[1] = (delta - k_gamma) / k_theta - T(z_theta_rad_) + noise[1];
    } else {
      error[1] = noise[1];
    }
    error[2] = v_body.y() - v_body.x() * tan(alpha) + c_rear * a_y + w[1] + noise[2];
    error[3] = v_body.z() - T(options_.pitch_lever_m) * omega_body.y() + w[2] + noise[3];
    return true;
  }

  // Analytic Jacobians (header comment), with Factor::Evaluate's layout and zero noise; fills only the requested
  // blocks. J_e_eta = I is left to AutoDiffFactor.
  bool Linearize(const double* const* x, double* error, double* const* jacobians, double* /*noise_jacobian*/) const {
    const Pose<double> pose_k = PoseFromArray(x[0]);
    const Pose<double> pose_k1 = PoseFromArray(x[1]);
    const double kv_over_l = x[2][0];
    const double k_theta = x[3][0];
    const double k_gamma = x[4][0];
    const double c_front = x[5][0];
    const double c_rear = x[6][0];
    const double alpha = x[7][0];
    const double slip_f = x[8][0];
    const double slip_p = x[9][0];
    const double* const w = x[10];
    const double cos_alpha = std::cos(alpha), sin_alpha = std::sin(alpha), tan_alpha = std::tan(alpha);

    // VelocitiesBetween, keeping the rotation vector and q_mid.
    const Eigen::Vector3d phi = QuaternionLog<double>(pose_k.q_world_body.conjugate() * pose_k1.q_world_body);
    const Eigen::Vector3d omega_body = phi / dt_s_;
    const Quaternion<double> q_mid = pose_k.q_world_body * QuaternionExp<double>(phi * 0.5);
    const Eigen::Vector3d v_odom = q_mid.conjugate() * ((pose_k1.p_world_body - pose_k.p_world_body) / dt_s_);
    const double h = options_.contact_height_m, d = options_.pitch_lever_m;
    const Eigen::Vector3d v_body(v_odom.x() - h * omega_body.y(), v_odom.y() + h * omega_body.x(), v_odom.z());

    // As operator().
    const double k_v = kv_over_l * wheelbase_m_;
    const double a_y = v_body.x() * omega_body.z();
    const double v_roll = v_body.x() * cos_alpha + v_body.y() * sin_alpha;
    const Eigen::Matrix3d R_mid = q_mid.toRotationMatrix();
    const double sin_pitch = R_mid(2, 0);
    const double slip = 1.0 + slip_f * forward_specific_force_mps2_ + slip_p * kStandardGravity * sin_pitch;
    error[0] = v_roll * slip / k_v - z_v_mps_ + w[0];
    const bool steering = std::abs(v_body.x()) >= kMinSteeringSpeed;
    // The understeer as an angle (c_angle = c_front) or as the front axle's side slip velocity (c_slip = c_front).
    const double c_angle = options_.front_slip_velocity ? 0.0 : c_front;
    const double c_slip = options_.front_slip_velocity ? c_front : 0.0;
    const double r = steering ? (wheelbase_m_ * omega_body.z() + v_body.y() + c_slip * a_y) / v_body.x() : 0.0;
    const double delta = steering ? std::atan(r) + c_angle * a_y : 0.0;
    error[1] = steering ? (delta - k_gamma) / k_theta - z_theta_rad_ : 0.0;
    error[2] = v_body.y() - v_body.x() * tan_alpha + c_rear * a_y + w[1];
    error[3] = v_body.z() - d * omega_body.y() + w[2];
    if (jacobians == nullptr) return true;

    // Rows of the residual in the motion: de/dv (4x3, v the contact's velocity) and de/domega (4x3) at fixed v.
    Eigen::Matrix<double, 4, 3> J_e_v = Eigen::Matrix<double, 4, 3>::Zero();
    Eigen::Matrix<double, 4, 3> J_e_omega = Eigen::Matrix<double, 4, 3>::Zero();
    auto J_e_omega_z = J_e_omega.col(2);
    J_e_v(0, 0) = slip * cos_alpha / k_v;
    J_e_v(0, 1) = slip * sin_alpha / k_v;
    J_e_v(2, 0) = c_rear * omega_body.z() - tan_alpha;
    J_e_v(2, 1) = 1.0;
    J_e_v(3, 2) = 1.0;
    J_e_omega_z[2] = c_rear * v_body.x();
    if (steering) {
      const double s = 1.0 / (1.0 + r * r);
      J_e_v(1, 0) = (c_angle * omega_body.z() - s * (r - c_slip * omega_body.z()) / v_body.x()) / k_theta;
      J_e_v(1, 1) = s / (v_body.x() * k_theta);
      J_e_omega_z[1] = (s * (wheelbase_m_ / v_body.x() + c_slip) + c_angle * v_body.x()) / k_theta;
    }
    // Through the contact velocity (dv/domega) and the vertical row's chord term; then v is O's velocity below.
    Eigen::Matrix3d J_v_omega = Eigen::Matrix3d::Zero();
    J_v_omega(0, 1) = -h;
    J_v_omega(1, 0) = h;
    J_e_omega += J_e_v * J_v_omega;
    J_e_omega(3, 1) -= d;

    // Poses: [dp, dtheta] through v (R_mid, and q_mid's perturbation eps) and omega (phi / dt).
    if (jacobians[0] != nullptr || jacobians[1] != nullptr) {
      const Eigen::Matrix3d R_mid_T = R_mid.transpose();
      // de/deps: through O's velocity, and through the pitch on the speed row (slope slip).
      Eigen::Matrix<double, 4, 3> J_e_eps = J_e_v * Skew<double>(v_odom);
      J_e_eps.row(0) -=
          (v_roll * slip_p * kStandardGravity / k_v) * R_mid.row(2) * Skew<double>(Eigen::Vector3d::UnitX());
      const Eigen::Matrix3d jr_inv = InverseRightJacobianSO3(phi);
      const Eigen::Matrix3d half_jr = 0.5 * RightJacobianSO3(phi * 0.5);
      const Eigen::Matrix<double, 4, 3> J_e_dp1 = J_e_v * R_mid_T / dt_s_;
      if (jacobians[0] != nullptr) {
        Eigen::Map<Eigen::Matrix<double, 4, 6>> J_e_pose_k(jacobians[0]);
        const Eigen::Matrix3d eps_theta =
            QuaternionExp<double>(phi * -0.5).toRotationMatrix() - half_jr * jr_inv.transpose();
        J_e_pose_k.leftCols<3>() = -J_e_dp1;
        J_e_pose_k.rightCols<3>() = J_e_eps * eps_theta - J_e_omega * (jr_inv.transpose() / dt_s_);
      }
      if (jacobians[1] != nullptr) {
        Eigen::Map<Eigen::Matrix<double, 4, 6>> J_e_pose_k1(jacobians[1]);
        J_e_pose_k1.leftCols<3>() = J_e_dp1;
        J_e_pose_k1.rightCols<3>() = J_e_eps * (half_jr * jr_inv) + J_e_omega * (jr_inv / dt_s_);
      }
    }

    // Calibration scalars.
    if (jacobians[2] != nullptr) {
      Eigen::Map<Eigen::Vector4d>{jacobians[2]} << -v_roll * slip / (kv_over_l * k_v), 0.0, 0.0, 0.0;
    }
    if (jacobians[3] != nullptr) {
      Eigen::Map<Eigen::Vector4d>{jacobians[3]} << 0.0, steering ? -(delta - k_gamma) / (k_theta * k_theta) : 0.0, 0.0,
          0.0;
    }
    if (jacobians[4] != nullptr) {
      Eigen::Map<Eigen::Vector4d>{jacobians[4]} << 0.0, steering ? -1.0 / k_theta : 0.0, 0.0, 0.0;
    }
    if (jacobians[5] != nullptr) {
      const double d_delta = options_.front_slip_velocity ? omega_body.z() / (1.0 + r * r) : a_y;
      Eigen::Map<Eigen::Vector4d>{jacobians[5]} << 0.0, steering ? d_delta / k_theta : 0.0, 0.0, 0.0;
    }
    if (jacobians[6] != nullptr) Eigen::Map<Eigen::Vector4d>{jacobians[6]} << 0.0, 0.0, a_y, 0.0;
    if (jacobians[7] != nullptr) {
      Eigen::Map<Eigen::Vector4d>{jacobians[7]} << (v_body.y() * cos_alpha - v_body.x() * sin_alpha) * slip / k_v, 0.0,
          -v_body.x() * (1.0 + tan_alpha * tan_alpha), 0.0;
    }
    if (jacobians[8] != nullptr) {
      Eigen::Map<Eigen::Vector4d>{jacobians[8]} << v_roll * forward_specific_force_mps2_ / k_v, 0.0, 0.0, 0.0;
    }
    if (jacobians[9] != nullptr) {
      Eigen::Map<Eigen::Vector4d>{jacobians[9]} << v_roll * kStandardGravity * sin_pitch / k_v, 0.0, 0.0, 0.0;
    }
    if (jacobians[10] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 4, 3>> J_e_w(jacobians[10]);
      J_e_w.setZero();
      J_e_w(0, 0) = J_e_w(2, 1) = J_e_w(3, 2) = 1.0;
    }
    return true;
  }

 private:
  double z_v_mps_;
  double z_theta_rad_;
  double wheelbase_m_;
  double dt_s_;
  Options options_;
  double forward_specific_force_mps2_;
};

}  // namespace roamlab::estimator
