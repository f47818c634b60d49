// The approximate linear motion model f(delta) = W delta (seed 001, Section III-B), fitted by Huber-robust regression
// (eq. 9):
//
//   W = argmin_W  sum_(j,k)  sum_(i in x,y,theta)  rho_c((s_jk^i - [W delta_jk]_i) / (sigma_jk^i * scale_i))
//
// rho_c is Huber's loss (quadratic for |u| <= c, linear beyond). The rows of W separate, so each output is one
// M-estimation problem, solved by iteratively reweighted least squares: weights w = min(1, c / |u|), then the weighted
// normal equations sum w x x^T / sigma^2 W_i = sum w x s / sigma^2, until W stops changing. The sigma_jk^i are the
// sensor's standard deviations; since they only fix relative weights in practice, each output also gets a robust
// scale (1.4826 times the median absolute whitened residual, re-estimated at each iteration), so that c keeps its
// usual meaning (c = 1.345: 95 % efficiency under Gaussian noise).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "common/status.h"

namespace roamlab::estimator::odometry {

struct HuberOptions {
  double c = 1.345;  // Huber threshold in robust standard deviations
  int max_iterations = 100;
  double tolerance = 1e-10;  // relative change of W that stops IRLS
};

struct HuberFit {
  Eigen::MatrixXd W;      // 3 x m
  Eigen::Vector3d scale;  // robust scale of the whitened residuals, per output
  int iterations = 0;     // the largest over the outputs
};

// X: n x m wheel rotations, Y: n x 3 displacements, sigma: n x 3 standard deviations (> 0). Errors: sizes, fewer pairs
// than unknowns, non-finite data, a singular design.
Result<HuberFit> FitHuberLinear(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y, const Eigen::MatrixXd& sigma,
                                const HuberOptions& options = {});

// Rows whose whitened residual |s_i - [W delta]_i| / (sigma_i scale_i) is at most `threshold` in every output: the
// pairs that lie on the linear surface (the seed's Fig. 3 calls the others outliers). Used to drop gross outliers
// before fitting models with a Gaussian likelihood (CGP) or least squares (Censi et al.'s second step).
std::vector<int> InlierRows(const HuberFit& fit, const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y,
                            const Eigen::MatrixXd& sigma, double threshold);

}  // namespace roamlab::estimator::odometry
