// Process models for time-varying calibration parameters (seed 000, Section III-B: "tracking online a limited set of
// time-varying calibration parameters ... such as gyroscope biases or slippage coefficients"). One instance of the
// parameter exists per time step (per pose, or per process.interval_s); these errors link the instances at t_k and
// t_k+1, however far apart.
//
// Random walk (Wiener process, dx/dt = w, w white with density sigma):
//   e = x(t_k+1) - x(t_k) + eta,                         eta ~ N(0, sigma^2 dt I)                 e, eta in R^N
// First-order Gauss-Markov process (dx/dt = -x / tau + w), exact discretization:
//   e = x(t_k+1) - exp(-dt / tau) x(t_k) + eta,          eta ~ N(0, sigma^2 (1 - exp(-2 dt / tau)) I)
// per component i with its own tau_i and sigma_i when the components are independent processes of different
// correlation times (eta's covariance then diagonal).
//
// Units: x in the parameter's own units [u]. dt = t_k+1 - t_k [s], tau = correlation time [s]. For the random walk,
// sigma is the random-walk density [u/sqrt(s)]; for the Gauss-Markov process, sigma is the stationary standard
// deviation [u] (the process's spread after many tau). NoiseVariance() turns a sigma into the per-component variance
// of eta, which the graph puts on the diagonal of the noise covariance.
// For dt << tau the Gauss-Markov process is a random walk of density sigma sqrt(2 / tau).
// Variables: value at t_k (VectorBlock<N>), value at t_k+1 (VectorBlock<N>).
#pragma once

#include <cmath>
#include <tuple>

#include <Eigen/Core>

#include "common/check.h"
#include "estimator/manifold.h"

namespace roamlab::estimator {

template <int N>
class RandomWalkError {
 public:
  using Blocks = std::tuple<VectorBlock<N>, VectorBlock<N>>;
  static constexpr int kResidualDim = N;
  static constexpr int kNoiseDim = N;
  static constexpr bool kAdditiveNoise = true;  // e = f(x) + eta

  // dt_s = t_k+1 - t_k > 0.
  explicit RandomWalkError(double dt_s) : dt_s_(dt_s) { ROAMLAB_CHECK(dt_s > 0.0, "random walk dt " << dt_s); }

  template <typename T>
  bool operator()(const T* const* x, const T* noise, T* error) const {
    for (int i = 0; i < N; ++i) error[i] = x[1][i] - x[0][i] + noise[i];
    return true;
  }

  // Variance of each noise component for a random-walk density sigma [u/sqrt(s)]: sigma^2 dt [u^2].
  double NoiseVariance(double sigma) const { return sigma * sigma * dt_s_; }
  double dt_s() const { return dt_s_; }

 private:
  double dt_s_;
};

template <int N>
class GaussMarkovError {
 public:
  using Blocks = std::tuple<VectorBlock<N>, VectorBlock<N>>;
  using Vector = Eigen::Matrix<double, N, 1>;
  static constexpr int kResidualDim = N;
  static constexpr int kNoiseDim = N;
  static constexpr bool kAdditiveNoise = true;  // e = f(x) + eta

  // dt_s = t_k+1 - t_k > 0, tau_s = correlation time > 0 (of every component, or of each).
  GaussMarkovError(double dt_s, double tau_s) : GaussMarkovError(dt_s, Vector::Constant(tau_s)) {}
  GaussMarkovError(double dt_s, const Vector& tau_s)
      : dt_s_(dt_s), tau_s_(tau_s), decay_((-dt_s / tau_s.array()).exp().matrix()) {
    ROAMLAB_CHECK(dt_s > 0.0 && (tau_s.array() > 0.0).all(),
                  "Gauss-Markov dt " << dt_s << " tau " << tau_s.transpose());
  }

  template <typename T>
  bool operator()(const T* const* x, const T* noise, T* error) const {
    for (int i = 0; i < N; ++i) error[i] = x[1][i] - T(decay_[i]) * x[0][i] + noise[i];
    return true;
  }

  // Variance of component i's noise for a stationary standard deviation sigma [u]: sigma^2 (1 - exp(-2 dt / tau_i)).
  double NoiseVariance(double sigma, int i = 0) const { return sigma * sigma * -std::expm1(-2.0 * dt_s_ / tau_s_[i]); }
  double dt_s() const { return dt_s_; }
  double tau_s(int i = 0) const { return tau_s_[i]; }
  // exp(-dt / tau_i), the factor applied to component i of the value at t_k.
  double decay(int i = 0) const { return decay_[i]; }

 private:
  double dt_s_;
  Vector tau_s_;
  Vector decay_;
};

}  // namespace roamlab::estimator
