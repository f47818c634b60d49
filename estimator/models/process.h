// Process models for time-varying calibration parameters (seed 000, Section III-B: "tracking online a limited set of
// time-varying calibration parameters ... such as gyroscope biases or slippage coefficients"). One instance of the
// parameter exists per time step; these errors link the instances at t_k and t_k+1.
//
// Random walk (Wiener process, dx/dt = w, w white with density sigma):
//   e = x(t_k+1) - x(t_k) + eta,                         eta ~ N(0, sigma^2 dt I)                 e, eta in R^N
// First-order Gauss-Markov process (dx/dt = -x / tau + w), exact discretization:
//   e = x(t_k+1) - exp(-dt / tau) x(t_k) + eta,          eta ~ N(0, sigma^2 (1 - exp(-2 dt / tau)) I)
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
  static constexpr int kResidualDim = N;
  static constexpr int kNoiseDim = N;
  static constexpr bool kAdditiveNoise = true;  // e = f(x) + eta

  // dt_s = t_k+1 - t_k > 0, tau_s = correlation time > 0.
  GaussMarkovError(double dt_s, double tau_s) : dt_s_(dt_s), tau_s_(tau_s), decay_(std::exp(-dt_s / tau_s)) {
    ROAMLAB_CHECK(dt_s > 0.0 && tau_s > 0.0, "Gauss-Markov dt " << dt_s << " tau " << tau_s);
  }

  template <typename T>
  bool operator()(const T* const* x, const T* noise, T* error) const {
    for (int i = 0; i < N; ++i) error[i] = x[1][i] - T(decay_) * x[0][i] + noise[i];
    return true;
  }

  // Variance of each noise component for a stationary standard deviation sigma [u]: sigma^2 (1 - exp(-2 dt / tau)).
  double NoiseVariance(double sigma) const { return sigma * sigma * -std::expm1(-2.0 * dt_s_ / tau_s_); }
  double dt_s() const { return dt_s_; }
  double tau_s() const { return tau_s_; }
  // exp(-dt / tau), the factor applied to the value at t_k.
  double decay() const { return decay_; }

 private:
  double dt_s_;
  double tau_s_;
  double decay_;
};

}  // namespace roamlab::estimator
