// A non-holonomic vehicle's pseudo-measurement: a wheeled robot that neither slides sideways nor leaves the ground
// moves along its own x axis, so the body velocity of its reference point has no lateral (y) and no vertical (z)
// component. It needs no reading: it is the differential drive's and the Ackermann models' lateral and vertical rows
// without their wheels, for a configuration whose only motion sensor is the IMU (the IMU master).
//
//   v^(O), omega^(O) = VelocitiesBetween(pose_k, pose_k+1, dt)        (the middle of the interval)
//   v_P = v^(O) + omega^(O) x P^(O)                                   (the reference point P at lever arm P^(O))
//   e = [v_P,y;  v_P,z] + eta,      eta ~ N(0, diag(lateral_mps^2, vertical_mps^2))                     e in R^2
//
// Why: with the IMU the only motion sensor the body frame is the IMU's frame turned by its misalignment, and a free
// misalignment turns the body frame with it and changes no error (a gauge freedom). These rows tie the body's x axis
// to the direction of travel, which the GPS (or any absolute sensor) measures, so the misalignment's yaw and pitch
// become observable. Its roll does not: a turn of the body about its x axis leaves a velocity along x unchanged.
// P: the point whose velocity has no sideways component (a skid steer's centre of rotation, an Ackermann car's rear
// axle); default the body origin. Its x component is observable in turns (omega_z P_x moves v_P,y), its y and z only
// through the roll and pitch rates.
//
// In EST.yaml (one row per sample of its source stream, at the pose interval that holds the sample's stamp):
//   travel:
//     model: non_holonomic
//     source: imu                  # any stream: only its stamps are read
//     noise: {lateral_mps: 0.1, vertical_mps: 0.1}
//     parameters: {lever_arm: vehicle.lever_arm}   # optional, default [0, 0, 0]
// The noise is per row: n rows in one pose interval constrain it sqrt(n) times tighter than one. The slack is the
// vehicle's side slip and bounce (a skid steer scrubs sideways in turns).
// Variables: pose at t_k, pose at t_k+1 (PoseBlock), P^(O) (Vector3Block). Jacobians by the jets (factor.h);
// tests/estimator/models/non_holonomic_test.cc checks them against central differences.
#pragma once

#include <tuple>

#include <Eigen/Core>

#include "common/check.h"
#include "estimator/geometry.h"
#include "estimator/manifold.h"
#include "estimator/model_registry.h"

namespace roamlab::estimator {

class NonHolonomicError {
 public:
  using Blocks = std::tuple<PoseBlock, PoseBlock, Vector3Block>;
  static constexpr int kResidualDim = 2;
  static constexpr int kNoiseDim = 2;
  static constexpr bool kAdditiveNoise = true;  // e = f(x) + eta

  // dt_s = t_k+1 - t_k > 0.
  explicit NonHolonomicError(double dt_s) : dt_s_(dt_s) { ROAMLAB_CHECK(dt_s > 0.0, "non-holonomic dt " << dt_s); }

  template <typename T>
  bool operator()(const T* const* x, const T* noise, T* error) const {
    Vector3<T> v_body, omega_body;
    VelocitiesBetween<T>(PoseFromArray(x[0]), PoseFromArray(x[1]), T(dt_s_), &v_body, &omega_body);
    const Vector3<T> v_point = v_body + omega_body.cross(Eigen::Map<const Vector3<T>>(x[2]));
    error[0] = v_point.y() + noise[0];
    error[1] = v_point.z() + noise[1];
    return true;
  }

 private:
  double dt_s_;
};

// The registry's definition of the model "non_holonomic" (model_registry.cc registers it with the built-in models).
ErrorModelDefinition NonHolonomicModel();

}  // namespace roamlab::estimator
