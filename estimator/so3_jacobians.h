// Jacobians of the SO(3) exponential and logarithm, for the analytic Jacobians of the error models (their Linearize;
// the jets of factor.h stay the oracle). Conventions of geometry.h: right perturbation, full-angle rotation vectors.
//
// With theta = |phi|, [phi]x the skew matrix of phi and R(.) the rotation matrix of a quaternion or rotation vector:
//   Exp(phi + d)          = Exp(phi) Exp(Jr(phi) d) + O(d^2)
//   Exp(phi + d)          = Exp(Jl(phi) d) Exp(phi) + O(d^2)
//   Log(Exp(phi) Exp(d))  = phi + Jr^-1(phi) d + O(d^2)
//   Log(Exp(d) Exp(phi))  = phi + Jl^-1(phi) d + O(d^2)
// where
//   Jr(phi)    = I - (1 - cos theta) / theta^2 [phi]x + (theta - sin theta) / theta^3 [phi]x^2
//   Jr^-1(phi) = I + 1/2 [phi]x + (1 - (theta/2) cot(theta/2)) / theta^2 [phi]x^2         (theta < 2 pi)
//   Jl(phi) = Jr(-phi) = Jr(phi)^T,   Jl^-1(phi) = Jr^-1(phi)^T,   Jl(phi) = R(phi) Jr(phi).
// Two identities used throughout: a right perturbation moved across a rotation, q Exp(d) q^-1 = Exp(R(q) d), and the
// derivatives of a rotated vector, d(R Exp(d) v)/dd = -R [v]x and d((R Exp(d))^T v)/dd = [R^T v]x.
#pragma once

#include <cmath>

#include <Eigen/Core>

#include "estimator/geometry.h"

namespace roamlab::estimator {

// Below this angle [rad] the coefficients use their Taylor series (truncation error < 1e-15, no cancellation).
inline constexpr double kSo3SeriesAngle = 1e-3;

// Jr(phi): Exp(phi + d) = Exp(phi) Exp(Jr(phi) d) to first order in d.
inline Eigen::Matrix3d RightJacobianSO3(const Eigen::Vector3d& phi) {
  const double theta_sq = phi.squaredNorm();
  double a, b;  // (1 - cos theta) / theta^2 and (theta - sin theta) / theta^3
  if (theta_sq < kSo3SeriesAngle * kSo3SeriesAngle) {
    a = 0.5 - theta_sq / 24.0;
    b = 1.0 / 6.0 - theta_sq / 120.0;
  } else {
    const double theta = std::sqrt(theta_sq);
    const double s = std::sin(0.5 * theta);
    a = 2.0 * s * s / theta_sq;  // 1 - cos theta = 2 sin^2(theta/2), without the cancellation
    b = (theta - std::sin(theta)) / (theta_sq * theta);
  }
  const Eigen::Matrix3d phi_x = Skew<double>(phi);
  return Eigen::Matrix3d::Identity() - a * phi_x + b * phi_x * phi_x;
}

// Jr^-1(phi): Log(Exp(phi) Exp(d)) = phi + Jr^-1(phi) d to first order in d. Valid for |phi| < 2 pi (Log returns
// |phi| <= pi).
inline Eigen::Matrix3d InverseRightJacobianSO3(const Eigen::Vector3d& phi) {
  const double theta_sq = phi.squaredNorm();
  double c;  // (1 - (theta/2) cot(theta/2)) / theta^2 = 1/12 + theta^2/720 + ...
  if (theta_sq < kSo3SeriesAngle * kSo3SeriesAngle) {
    c = 1.0 / 12.0 + theta_sq / 720.0;
  } else {
    const double half = 0.5 * std::sqrt(theta_sq);
    c = (1.0 - half * std::cos(half) / std::sin(half)) / theta_sq;
  }
  const Eigen::Matrix3d phi_x = Skew<double>(phi);
  return Eigen::Matrix3d::Identity() + 0.5 * phi_x + c * phi_x * phi_x;
}

}  // namespace roamlab::estimator
