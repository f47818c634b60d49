// Calibration via Gaussian-process regression, CGP (seed 001, Section III-A, Algorithm 1).
//
// The sensor motion model f: R^m -> R^3 maps the wheel rotations delta_jk over an interval to the exteroceptive
// sensor's planar displacement s_jk = f(delta_jk) + eps_jk (eq. 1). f gets a GP prior with a diagonal 3x3 kernel (the
// seed's matrix-valued kernel restricted to its diagonal): each output i in {x, y, theta} is an independent scalar GP
//
//   f_i ~ GP(mu_i(x), k_i(x, x')),   mu_i(x) = 0 or c_i^T x  (eq. 6, c_i is row i of C)
//   k_i = sf_i^2 exp(-1/2 sum_d (x_d - x'_d)^2 / l_id^2)      "rbf": eq. 7 with B_ii = diag(l_i^2)
//       | sl_i^2 <x, x'>                                       "linear": eq. 8 with a learned scale sl_i^2
//       | the sum of both                                      "rbf+linear"
//
// and the noise of output i at pair n is Sigma_n,ii + sn_i^2: the diagonal of the sensor's known covariance (eq. 2;
// its off-diagonal terms are dropped so that the outputs decouple) plus a learned white-noise variance sn_i^2 for what
// the sensor covariance leaves out (time-stamp jitter, unmodelled slip).
//
// Hyper-parameters (all of them, C included) maximize the log marginal likelihood
//   log p(y_i) = -1/2 r^T K^-1 r - 1/2 log|K| - n/2 log 2 pi,   r = y_i - mu_i(X),   K = K_i(X, X) + diag(noise)
// with the gradient d/dp = 1/2 tr((a a^T - K^-1) dK/dp), a = K^-1 r, and dlog p/dc_i = X^T a, by L-BFGS on
// log-parameters (positive ones) and plain c_i. The exact gradient costs O(n^3) per evaluation (one Cholesky and one
// inverse per output), so the optimization runs on a seeded random subset of at most `hyperparameter_subset` pairs
// (the "subset of data" approximation); the trained model then conditions on all n pairs: one Eigen LLT per output,
// kept for the predictive covariance (Algorithm 1, steps 4-5). With a linear mean, C is then re-estimated on all n
// pairs by generalized least squares, its exact maximum-likelihood value at the subset's kernel hyper-parameters.
//
// Prediction (Algorithm 1, steps 8-9): mean mu_i(x) + k_i(x, X) a_i costs O(n m) (O(m) for the linear kernel, whose
// k(x, X) a = sl^2 x^T (X^T a)); the variance k_i(x, x) - |L_i^-1 k_i(x, X)|^2 costs O(n^2).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "common/status.h"

namespace roamlab::estimator::odometry {

enum class GpMean { kZero, kLinear };
enum class GpKernel { kRbf, kLinear, kRbfPlusLinear };

// "zero" | "linear" and "rbf" | "linear" | "rbf+linear"; Parse* return false for other names.
const char* GpMeanName(GpMean mean);
const char* GpKernelName(GpKernel kernel);
bool ParseGpMean(const std::string& name, GpMean* mean);
bool ParseGpKernel(const std::string& name, GpKernel* kernel);

struct GpOptions {
  GpMean mean = GpMean::kLinear;
  GpKernel kernel = GpKernel::kRbf;
  int hyperparameter_subset = 400;  // pairs used to optimize hyper-parameters; 0 = all
  int max_iterations = 200;         // L-BFGS iterations per output
  std::uint64_t seed = 1;           // subset selection
  std::string Validate() const;     // "" when valid
};

// Which hyper-parameters one output has and where they sit in its parameter vector p:
//   [log l_1 .. log l_m, log sf]  (rbf)   [log sl]  (linear kernel)   [log sn]   [c_1 .. c_m]  (linear mean)
struct GpLayout {
  int m = 0;
  bool rbf = false;
  bool linear_kernel = false;
  bool linear_mean = false;
  GpLayout(int inputs, GpMean mean, GpKernel kernel);
  int size() const;
  int log_length(int d) const { return d; }
  int log_sf() const { return m; }
  int log_sl() const { return rbf ? m + 1 : 0; }
  int log_sn() const { return (rbf ? m + 1 : 0) + (linear_kernel ? 1 : 0); }
  int c(int d) const { return log_sn() + 1 + d; }
};

// Log marginal likelihood of one output and, when `gradient` is not null, its gradient with respect to p (sized
// layout.size()). X: n x m inputs, y: n targets, noise_var: n known noise variances (>= 0). Returns -infinity when
// K is not positive definite.
double GpLogMarginalLikelihood(const GpLayout& layout, const Eigen::MatrixXd& X, const Eigen::VectorXd& y,
                               const Eigen::VectorXd& noise_var, const Eigen::VectorXd& p, Eigen::VectorXd* gradient);

// Initial hyper-parameters from the data: c by least squares, length scales from the input spread, variances from
// the residual spread.
Eigen::VectorXd GpInitialParameters(const GpLayout& layout, const Eigen::MatrixXd& X, const Eigen::VectorXd& y);

// Result of maximizing the log marginal likelihood of one output.
struct GpOptimization {
  Eigen::VectorXd p;
  double log_likelihood = 0.0;
  int iterations = 0;
  int evaluations = 0;
};
GpOptimization MaximizeLogMarginalLikelihood(const GpLayout& layout, const Eigen::MatrixXd& X, const Eigen::VectorXd& y,
                                             const Eigen::VectorXd& noise_var, const Eigen::VectorXd& p0,
                                             int max_iterations);

// The trained CGP model f: R^m -> R^3.
class GaussianProcess {
 public:
  // Optimizes the hyper-parameters (unless `fixed_parameters` has three vectors) and conditions on all pairs.
  // X: n x m wheel rotations [rad]; Y: n x 3 displacements [m, m, rad]; noise_var: n x 3 known variances.
  // Errors: sizes, fewer than 2 pairs, non-finite data, a factorization that fails.
  static Result<GaussianProcess> Train(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y,
                                       const Eigen::MatrixXd& noise_var, const GpOptions& options,
                                       const std::vector<Eigen::VectorXd>& fixed_parameters = {});

  // A model from stored parts (see parameters(), inputs(), weights()): predicts the mean without refactoring;
  // the covariance needs Train.
  static Result<GaussianProcess> FromParts(GpMean mean, GpKernel kernel, const Eigen::MatrixXd& X,
                                           const std::vector<Eigen::VectorXd>& parameters,
                                           const std::vector<Eigen::VectorXd>& weights);

  // Predictive mean (eq. 5, Algorithm 1 step 8), x sized m.
  Eigen::Vector3d PredictMean(const Eigen::VectorXd& x) const;
  // Predictive covariance of f(x) (Algorithm 1 step 9; diagonal). CHECKs that the model was trained here.
  Eigen::Matrix3d PredictCovariance(const Eigen::VectorXd& x) const;
  bool has_factor() const { return !factor_.empty(); }

  GpMean mean() const { return mean_; }
  GpKernel kernel() const { return kernel_; }
  int inputs_dimension() const { return static_cast<int>(X_.cols()); }
  const Eigen::MatrixXd& inputs() const { return X_; }
  const std::vector<Eigen::VectorXd>& parameters() const { return p_; }           // per output, layout order
  const std::vector<Eigen::VectorXd>& weights() const { return alpha_; }          // per output: (K + Sigma)^-1 r
  const std::vector<double>& log_likelihoods() const { return log_likelihood_; }  // per output, on the subset

 private:
  GaussianProcess() = default;
  void Precompute();  // scaled inputs and X^T a for fast prediction

  GpMean mean_ = GpMean::kLinear;
  GpKernel kernel_ = GpKernel::kRbf;
  Eigen::MatrixXd X_;
  std::vector<Eigen::VectorXd> p_;
  std::vector<Eigen::VectorXd> alpha_;
  std::vector<double> log_likelihood_;
  std::vector<Eigen::LLT<Eigen::MatrixXd>> factor_;
  // Per output: X_ / l (columns scaled by the inverse length scales), and the linear-part weights.
  std::vector<Eigen::MatrixXd> X_scaled_;
  std::vector<Eigen::VectorXd> inverse_length_;  // 1 / l per input
  std::vector<Eigen::VectorXd> scaled_alpha_;    // sf^2 a (rbf only)
  std::vector<Eigen::VectorXd> linear_weights_;  // c_i + sl_i^2 X^T a_i
};

}  // namespace roamlab::estimator::odometry
