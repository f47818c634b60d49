// A range-to-beacon sensor as a user error model of roamlab's estimator (estimator/model_registry.h): a ranging
// antenna at lever arm S^(O) on the robot measures its distance to a beacon at a known position b^(W).
//
//   z_hat = |O^(W) + q_O^W S^(O) - b^(W)| + eta,      e = z_hat - z,      e, eta [m],  eta ~ N(0, sigma_m^2)
//
// In EST.yaml, once RegisterRangeBeaconModel() has run:
//   uwb_a:
//     model: range_beacon
//     source: uwb_a                          # an inputs stream with a range_m column [m]
//     noise: {sigma_m: 0.05}
//     options: {beacon_world: [10, 0, 2]}    # required: the beacon's position in W [m]
//     parameters: {lever_arm: antenna.lever_arm}   # the one slot, default [0, 0, 0]
// Each sample joins the pose nearest its stamp. The model is absolute: ranges to three beacons or more place the
// poses in W, so the first pose gets no gauge prior.
#pragma once

#include <tuple>

#include <Eigen/Core>

#include "common/status.h"
#include "estimator/geometry.h"
#include "estimator/manifold.h"

namespace beacon {

class RangeToBeaconError {
 public:
  using Blocks = std::tuple<roamlab::estimator::PoseBlock, roamlab::estimator::Vector3Block>;
  static constexpr int kResidualDim = 1;
  static constexpr int kNoiseDim = 1;
  static constexpr bool kAdditiveNoise = true;  // e = f(x) + eta

  RangeToBeaconError(const Eigen::Vector3d& beacon_world, double range_m)
      : beacon_world_(beacon_world), range_m_(range_m) {}

  template <typename T>
  bool operator()(const T* const* x, const T* noise, T* error) const {
    using roamlab::estimator::Vector3;
    using std::sqrt;  // and roamlab::estimator::sqrt for jets, by argument-dependent lookup
    const roamlab::estimator::Pose<T> pose = roamlab::estimator::PoseFromArray(x[0]);
    const Eigen::Map<const Vector3<T>> p_body_antenna(x[1]);
    const Vector3<T> d = pose.p_world_body + pose.q_world_body * p_body_antenna - beacon_world_.cast<T>();
    error[0] = sqrt(d.dot(d)) + noise[0] - T(range_m_);
    return true;
  }

 private:
  Eigen::Vector3d beacon_world_;
  double range_m_;
};

// Registers the model as "range_beacon" in the estimator's registry; later calls return the first call's status.
roamlab::Status RegisterRangeBeaconModel();

}  // namespace beacon
