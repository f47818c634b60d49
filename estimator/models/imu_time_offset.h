// The IMU's readings with a time offset delta of the IMU's clock (the slot time_offset_s of the gyroscope,
// accelerometer and magnetometer models): the reading stamped t is the sensor's quantity at
// t - delta (as the simulator's imu_time_offset effect, sim/scenario.h). The samples keep the poses they attach to
// (problem.h); instead the reading is moved back to t to first order along the stream's own rate,
//
//   z(t + delta) = z(t) + delta z'(t),
//
// with z' the slope of the same stream's readings around t (problem.cc: a least-squares line over the samples within
// kReadingRateHalfWindow, computed once as data). Each model is the plain one (gyroscope.h, accelerometer.h,
// magnetometer.h) with delta (ScalarBlock, [s]) appended, and the same poses, so a free offset costs about what the
// plain models do. All three take their reading as z - b with b their bias block (the gyroscope's bias, the
// accelerometer's bias, the magnetometer's b), so the moved reading is the plain model at b - delta z':
//
//   e(x, delta) = e_plain(x with b -> b - delta z'),   d e / d delta = -(d e_plain / d b) z',
//
// at delta = 0 the plain model exactly. The pairing of the IMU's samples with the other streams' never changes and
// the chi-square is smooth in delta. Errors: the second-order remainder delta^2 z'' / 2 (a few master periods at the
// motion's bandwidth; beyond 0.1 s the diagnosis searches the offset on a grid of whole-master-period stamp
// shifts instead, gap/time_shift.cc), the slope's smoothing (a line over +-W passes a sine of angular frequency w
// at about 1 - (w W)^2 / 10), and the slope's noise. A symmetric line fit over 2n + 1 samples at rate f (n = W f)
// leaves the middle sample's own noise out and has
//   var(z') = 3 f^2 sigma^2 / (n (n + 1) (2n + 1)),
// so the moved reading carries an extra delta^2 var(z'), correlated between neighbouring samples; at 100 Hz and
// W = 0.3 s (n = 30) std(z') = 0.73 sigma / s: 0.022 sigma at |delta| = 30 ms (+0.05 % of the variance), 0.07 sigma
// at 0.1 s (+0.5 %). The slope's noise also biases delta towards zero (an error in the regressor: the estimate shrinks
// by about var(z' true) / var(z' measured)): a narrow window (W = 0.05 s: std(z') = 9.5 sigma / s) shrinks the
// estimate to a fraction of the offset, hence W = 0.3 s, as wide as the motion's bandwidth allows.
#pragma once

#include <array>
#include <tuple>
#include <type_traits>
#include <utility>

#include <Eigen/Core>

#include "estimator/factor.h"
#include "estimator/manifold.h"
#include "estimator/models/accelerometer.h"
#include "estimator/models/gyroscope.h"
#include "estimator/models/magnetometer.h"

namespace roamlab::estimator {

// Plain's variables, then delta. kBiasBlock: the index of Plain's block b through which it takes its reading as
// z - b (a Vector3Block).
template <typename Plain, int kBiasBlock>
class ReadingTimeOffsetError {
 public:
  using Blocks =
      decltype(std::tuple_cat(std::declval<typename Plain::Blocks>(), std::declval<std::tuple<ScalarBlock>>()));
  static constexpr int kResidualDim = Plain::kResidualDim;
  static constexpr int kNoiseDim = Plain::kNoiseDim;
  static constexpr bool kAdditiveNoise = internal::AdditiveNoise<Plain>::value;

  // z_rate: the reading's rate z' at its stamp [reading units / s].
  ReadingTimeOffsetError(Plain plain, const Eigen::Vector3d& z_rate) : plain_(std::move(plain)), z_rate_(z_rate) {}

  template <typename T>
  bool operator()(const T* const* x, const T* noise, T* error) const {
    const Vector3<T> b = Eigen::Map<const Vector3<T>>(x[kBiasBlock]) - x[kPlainBlocks][0] * z_rate_.cast<T>();
    std::array<const T*, kPlainBlocks> plain_x;
    for (int i = 0; i < kPlainBlocks; ++i) plain_x[i] = x[i];
    plain_x[kBiasBlock] = b.data();
    return plain_(plain_x.data(), noise, error);
  }

  // Plain's analytic Jacobians at the moved b, and d e / d delta = -(d e / d b) z'.
  bool Linearize(const double* const* x, double* error, double* const* jacobians, double* noise_jacobian) const {
    const Eigen::Vector3d b = Eigen::Map<const Eigen::Vector3d>(x[kBiasBlock]) - x[kPlainBlocks][0] * z_rate_;
    std::array<const double*, kPlainBlocks> plain_x;
    for (int i = 0; i < kPlainBlocks; ++i) plain_x[i] = x[i];
    plain_x[kBiasBlock] = b.data();
    if (jacobians == nullptr) return plain_.Linearize(plain_x.data(), error, nullptr, noise_jacobian);

    std::array<double*, kPlainBlocks> plain_jacobians;
    for (int i = 0; i < kPlainBlocks; ++i) plain_jacobians[i] = jacobians[i];
    Eigen::Matrix<double, kResidualDim, 3> J_b;
    if (jacobians[kPlainBlocks] != nullptr && plain_jacobians[kBiasBlock] == nullptr)
      plain_jacobians[kBiasBlock] = J_b.data();
    if (!plain_.Linearize(plain_x.data(), error, plain_jacobians.data(), noise_jacobian)) return false;
    if (jacobians[kPlainBlocks] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, kResidualDim, 1>> J_delta(jacobians[kPlainBlocks]);
      J_delta = -Eigen::Map<const Eigen::Matrix<double, kResidualDim, 3>>(plain_jacobians[kBiasBlock]) * z_rate_;
    }
    return true;
  }

 private:
  static constexpr int kPlainBlocks = static_cast<int>(std::tuple_size_v<typename Plain::Blocks>);
  static_assert(std::is_same_v<std::tuple_element_t<kBiasBlock, typename Plain::Blocks>, Vector3Block>);

  Plain plain_;
  Eigen::Vector3d z_rate_;
};

// Variables: GyroscopeError's (poses at t(k), t(k+1), q_body_sensor, bias, scale), delta.
using GyroscopeTimeOffsetError = ReadingTimeOffsetError<GyroscopeError, 3>;
// Variables: AccelerometerError's (poses at t(k-1), t(k), t(k+1), q_body_sensor, S^(O), bias, scale), delta.
using AccelerometerTimeOffsetError = ReadingTimeOffsetError<AccelerometerError, 5>;
// Variables: MagnetometerError's (pose at t(k), q_body_sensor, A, b, k), delta.
using MagnetometerTimeOffsetError = ReadingTimeOffsetError<MagnetometerError, 3>;

}  // namespace roamlab::estimator
