#include "estimator/odometry/gaussian_process.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

#include "common/check.h"
#include "estimator/odometry/internal/lbfgs.h"

namespace roamlab::estimator::odometry {
namespace {

constexpr double kLog2Pi = 1.8378770664093453;  // log(2 pi)

// Covariance of one output over the rows of A and B without noise; with `rbf_part` not null, also the RBF part alone
// (needed by the length-scale and sf derivatives).
Eigen::MatrixXd KernelMatrix(const GpLayout& layout, const Eigen::VectorXd& p, const Eigen::MatrixXd& A,
                             const Eigen::MatrixXd& B, Eigen::MatrixXd* rbf_part) {
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(A.rows(), B.rows());
  if (layout.rbf) {
    // Squared distances with each input scaled by its length scale (eq. 7, B = diag(l^2)).
    Eigen::MatrixXd As = A;
    Eigen::MatrixXd Bs = B;
    for (int d = 0; d < layout.m; ++d) {
      const double inv_l = std::exp(-p[layout.log_length(d)]);
      As.col(d) *= inv_l;
      Bs.col(d) *= inv_l;
    }
    const Eigen::VectorXd a2 = As.rowwise().squaredNorm();
    const Eigen::VectorXd b2 = Bs.rowwise().squaredNorm();
    Eigen::MatrixXd d2 = -2.0 * As * Bs.transpose();
    d2.colwise() += a2;
    d2.rowwise() += b2.transpose();
    const double sf2 = std::exp(2.0 * p[layout.log_sf()]);
    Eigen::MatrixXd rbf = (-0.5 * d2.array().max(0.0)).exp() * sf2;
    K += rbf;
    if (rbf_part != nullptr) *rbf_part = std::move(rbf);
  }
  if (layout.linear_kernel) K += std::exp(2.0 * p[layout.log_sl()]) * (A * B.transpose());
  return K;
}

Eigen::VectorXd MeanVector(const GpLayout& layout, const Eigen::VectorXd& p, const Eigen::MatrixXd& X) {
  if (!layout.linear_mean) return Eigen::VectorXd::Zero(X.rows());
  return X * p.segment(layout.c(0), layout.m);
}

// Noise variance per pair: known plus learned.
Eigen::VectorXd NoiseDiagonal(const GpLayout& layout, const Eigen::VectorXd& p, const Eigen::VectorXd& noise_var) {
  return noise_var.array() + std::exp(2.0 * p[layout.log_sn()]);
}

// Rows `rows` of M.
Eigen::MatrixXd SelectRows(const Eigen::MatrixXd& M, const std::vector<int>& rows) {
  Eigen::MatrixXd out(static_cast<Eigen::Index>(rows.size()), M.cols());
  for (std::size_t i = 0; i < rows.size(); ++i) out.row(static_cast<Eigen::Index>(i)) = M.row(rows[i]);
  return out;
}

}  // namespace

const char* GpMeanName(GpMean mean) { return mean == GpMean::kZero ? "zero" : "linear"; }

const char* GpKernelName(GpKernel kernel) {
  switch (kernel) {
    case GpKernel::kRbf:
      return "rbf";
    case GpKernel::kLinear:
      return "linear";
    case GpKernel::kRbfPlusLinear:
      return "rbf+linear";
  }
  return "?";
}

bool ParseGpMean(const std::string& name, GpMean* mean) {
  if (name == "zero")
    *mean = GpMean::kZero;
  else if (name == "linear")
    *mean = GpMean::kLinear;
  else
    return false;
  return true;
}

bool ParseGpKernel(const std::string& name, GpKernel* kernel) {
  if (name == "rbf")
    *kernel = GpKernel::kRbf;
  else if (name == "linear")
    *kernel = GpKernel::kLinear;
  else if (name == "rbf+linear")
    *kernel = GpKernel::kRbfPlusLinear;
  else
    return false;
  return true;
}

std::string GpOptions::Validate() const {
  if (hyperparameter_subset < 0) return "hyperparameter_subset must be >= 0";
  if (max_iterations < 0) return "max_iterations must be >= 0";
  return "";
}

GpLayout::GpLayout(int inputs, GpMean mean, GpKernel kernel)
    : m(inputs),
      rbf(kernel != GpKernel::kLinear),
      linear_kernel(kernel != GpKernel::kRbf),
      linear_mean(mean == GpMean::kLinear) {}

int GpLayout::size() const { return log_sn() + 1 + (linear_mean ? m : 0); }

double GpLogMarginalLikelihood(const GpLayout& layout, const Eigen::MatrixXd& X, const Eigen::VectorXd& y,
                               const Eigen::VectorXd& noise_var, const Eigen::VectorXd& p, Eigen::VectorXd* gradient) {
  ROAMLAB_CHECK(
      X.cols() == layout.m && X.rows() == y.size() && y.size() == noise_var.size() && p.size() == layout.size(),
      "GpLogMarginalLikelihood: sizes");
  const Eigen::Index n = X.rows();
  // K = K(X, X) + diag(noise) and its Cholesky factor.
  Eigen::MatrixXd rbf;
  Eigen::MatrixXd K = KernelMatrix(layout, p, X, X, layout.rbf ? &rbf : nullptr);
  const Eigen::VectorXd noise = NoiseDiagonal(layout, p, noise_var);
  K.diagonal() += noise;
  const Eigen::LLT<Eigen::MatrixXd> llt(K);
  if (llt.info() != Eigen::Success) return -std::numeric_limits<double>::infinity();
  const Eigen::VectorXd r = y - MeanVector(layout, p, X);
  const Eigen::VectorXd a = llt.solve(r);
  const double log_det = 2.0 * llt.matrixLLT().diagonal().array().log().sum();
  const double value = -0.5 * r.dot(a) - 0.5 * log_det - 0.5 * static_cast<double>(n) * kLog2Pi;
  if (!std::isfinite(value)) return -std::numeric_limits<double>::infinity();
  if (gradient == nullptr) return value;

  // A = a a^T - K^-1; d log p / d q = 1/2 sum_ij A_ij dK_ij/dq for every kernel or noise parameter q.
  Eigen::MatrixXd A = llt.solve(Eigen::MatrixXd::Identity(n, n));
  A = a * a.transpose() - A;
  gradient->setZero(layout.size());
  if (layout.rbf) {
    // dK/dlog sf = 2 K_rbf; dK/dlog l_d = K_rbf (x_d - x'_d)^2 / l_d^2.
    const Eigen::ArrayXXd AK = A.array() * rbf.array();
    (*gradient)[layout.log_sf()] = AK.sum();
    for (int d = 0; d < layout.m; ++d) {
      const Eigen::VectorXd xd = X.col(d) * std::exp(-p[layout.log_length(d)]);
      Eigen::MatrixXd D2 = -2.0 * xd * xd.transpose();
      D2.colwise() += xd.cwiseAbs2();
      D2.rowwise() += xd.cwiseAbs2().transpose();
      (*gradient)[layout.log_length(d)] = 0.5 * (AK * D2.array()).sum();
    }
  }
  if (layout.linear_kernel) {
    // dK/dlog sl = 2 sl^2 X X^T: sum_ij A_ij (X X^T)_ij = tr(X^T A X).
    const double sl2 = std::exp(2.0 * p[layout.log_sl()]);
    (*gradient)[layout.log_sl()] = sl2 * (X.transpose() * A * X).trace();
  }
  // dK/dlog sn = 2 sn^2 I.
  (*gradient)[layout.log_sn()] = std::exp(2.0 * p[layout.log_sn()]) * A.trace();
  // d log p / dc = X^T a (the mean enters through r only).
  if (layout.linear_mean) gradient->segment(layout.c(0), layout.m) = X.transpose() * a;
  return value;
}

Eigen::VectorXd GpInitialParameters(const GpLayout& layout, const Eigen::MatrixXd& X, const Eigen::VectorXd& y) {
  Eigen::VectorXd p = Eigen::VectorXd::Zero(layout.size());
  const double n = static_cast<double>(X.rows());
  // Linear mean by (slightly regularized) least squares.
  Eigen::VectorXd r = y;
  if (layout.linear_mean) {
    Eigen::MatrixXd XtX = X.transpose() * X;
    XtX.diagonal().array() += 1e-9 * (XtX.trace() / layout.m + 1e-300);
    const Eigen::VectorXd c = XtX.ldlt().solve(X.transpose() * y);
    p.segment(layout.c(0), layout.m) = c;
    r = y - X * c;
  }
  const double y_scale2 = std::max(r.squaredNorm() / n, 1e-12);
  if (layout.rbf) {
    for (int d = 0; d < layout.m; ++d) {
      const double mean = X.col(d).mean();
      const double spread = std::sqrt((X.col(d).array() - mean).square().sum() / n);
      p[layout.log_length(d)] = std::log(std::max(spread, 1e-6));
    }
    p[layout.log_sf()] = 0.5 * std::log(y_scale2);
  }
  if (layout.linear_kernel) {
    const double x2 = std::max(X.rowwise().squaredNorm().mean(), 1e-12);
    p[layout.log_sl()] = 0.5 * std::log(y_scale2 / x2);
  }
  p[layout.log_sn()] = 0.5 * std::log(0.1 * y_scale2);
  return p;
}

GpOptimization MaximizeLogMarginalLikelihood(const GpLayout& layout, const Eigen::MatrixXd& X, const Eigen::VectorXd& y,
                                             const Eigen::VectorXd& noise_var, const Eigen::VectorXd& p0,
                                             int max_iterations) {
  // L-BFGS minimizes the negative log marginal likelihood.
  const auto cost = [&](const Eigen::VectorXd& p, Eigen::VectorXd* gradient) {
    const double value = GpLogMarginalLikelihood(layout, X, y, noise_var, p, gradient);
    if (!std::isfinite(value)) return std::numeric_limits<double>::infinity();
    if (gradient != nullptr) *gradient = -*gradient;
    return -value;
  };
  internal::LbfgsOptions options;
  options.max_iterations = max_iterations;
  const internal::LbfgsResult result = internal::MinimizeLbfgs(cost, p0, options);
  return GpOptimization{result.x, -result.value, result.iterations, result.evaluations};
}

Result<GaussianProcess> GaussianProcess::Train(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y,
                                               const Eigen::MatrixXd& noise_var, const GpOptions& options,
                                               const std::vector<Eigen::VectorXd>& fixed_parameters) {
  if (const std::string problem = options.Validate(); !problem.empty()) return Status::Error("GP: " + problem);
  const Eigen::Index n = X.rows();
  if (n < 2 || X.cols() < 1) return Status::Error("GP: need at least 2 training pairs with at least one input");
  if (Y.rows() != n || Y.cols() != 3 || noise_var.rows() != n || noise_var.cols() != 3) {
    return Status::Error("GP: targets and noise variances must be n x 3");
  }
  if (!X.allFinite() || !Y.allFinite() || !noise_var.allFinite() || (noise_var.array() < 0.0).any()) {
    return Status::Error("GP: training data must be finite with non-negative noise variances");
  }
  const GpLayout layout(static_cast<int>(X.cols()), options.mean, options.kernel);
  if (!fixed_parameters.empty() && (fixed_parameters.size() != 3 ||
                                    std::any_of(fixed_parameters.begin(), fixed_parameters.end(),
                                                [&](const Eigen::VectorXd& p) { return p.size() != layout.size(); }))) {
    return Status::Error("GP: fixed parameters must be three vectors of size " + std::to_string(layout.size()));
  }
  // The seeded subset for the hyper-parameter optimization.
  std::vector<int> subset(static_cast<std::size_t>(n));
  std::iota(subset.begin(), subset.end(), 0);
  if (options.hyperparameter_subset > 0 && n > options.hyperparameter_subset) {
    std::mt19937_64 rng(options.seed);
    std::shuffle(subset.begin(), subset.end(), rng);
    subset.resize(static_cast<std::size_t>(options.hyperparameter_subset));
    std::sort(subset.begin(), subset.end());
  }
  const Eigen::MatrixXd X_sub = SelectRows(X, subset);
  const Eigen::MatrixXd Y_sub = SelectRows(Y, subset);
  const Eigen::MatrixXd noise_sub = SelectRows(noise_var, subset);

  GaussianProcess gp;
  gp.mean_ = options.mean;
  gp.kernel_ = options.kernel;
  gp.X_ = X;
  for (int i = 0; i < 3; ++i) {
    // Hyper-parameters (Section III-A: maximum log marginal likelihood).
    Eigen::VectorXd p;
    double log_likelihood = 0.0;
    if (fixed_parameters.empty()) {
      const Eigen::VectorXd p0 = GpInitialParameters(layout, X_sub, Y_sub.col(i));
      const GpOptimization opt =
          MaximizeLogMarginalLikelihood(layout, X_sub, Y_sub.col(i), noise_sub.col(i), p0, options.max_iterations);
      p = opt.p;
      log_likelihood = opt.log_likelihood;
    } else {
      p = fixed_parameters[static_cast<std::size_t>(i)];
      log_likelihood = GpLogMarginalLikelihood(layout, X_sub, Y_sub.col(i), noise_sub.col(i), p, nullptr);
    }
    // Algorithm 1, steps 4-5: the factor of K + Sigma over all pairs and a = (K + Sigma)^-1 (s - mu).
    Eigen::MatrixXd K = KernelMatrix(layout, p, X, X, nullptr);
    K.diagonal() += NoiseDiagonal(layout, p, noise_var.col(i));
    Eigen::LLT<Eigen::MatrixXd> llt(K);
    if (llt.info() != Eigen::Success) {
      return Status::Error(std::string("GP: K + Sigma is not positive definite for output ") + "xyt"[i]);
    }
    // With a linear mean and hyper-parameters to optimize, C is re-estimated on all n pairs: at fixed kernel and noise
    // the log marginal likelihood is maximized in closed form by generalized least squares,
    // c = (X^T (K + Sigma)^-1 X)^-1 X^T (K + Sigma)^-1 y (the subset's c is only as good as the subset).
    if (layout.linear_mean && fixed_parameters.empty()) {
      const Eigen::MatrixXd KiX = llt.solve(X);
      const Eigen::LDLT<Eigen::MatrixXd> normal(X.transpose() * KiX);
      if (normal.info() == Eigen::Success && (normal.vectorD().array() > 0.0).all()) {
        p.segment(layout.c(0), layout.m) = normal.solve(KiX.transpose() * Y.col(i));
      }
    }
    gp.alpha_.push_back(llt.solve(Eigen::VectorXd(Y.col(i) - MeanVector(layout, p, X))));
    gp.factor_.push_back(std::move(llt));
    gp.p_.push_back(p);
    gp.log_likelihood_.push_back(log_likelihood);
  }
  gp.Precompute();
  return gp;
}

Result<GaussianProcess> GaussianProcess::FromParts(GpMean mean, GpKernel kernel, const Eigen::MatrixXd& X,
                                                   const std::vector<Eigen::VectorXd>& parameters,
                                                   const std::vector<Eigen::VectorXd>& weights) {
  const GpLayout layout(static_cast<int>(X.cols()), mean, kernel);
  if (X.rows() < 1 || X.cols() < 1 || !X.allFinite()) return Status::Error("GP: inputs empty or not finite");
  if (parameters.size() != 3 || weights.size() != 3) return Status::Error("GP: need three outputs");
  for (int i = 0; i < 3; ++i) {
    if (parameters[i].size() != layout.size() || !parameters[i].allFinite()) {
      return Status::Error("GP: output " + std::to_string(i) + " needs " + std::to_string(layout.size()) +
                           " finite hyper-parameters");
    }
    if (weights[i].size() != X.rows() || !weights[i].allFinite()) {
      return Status::Error("GP: output " + std::to_string(i) + " needs one finite weight per training input");
    }
  }
  GaussianProcess gp;
  gp.mean_ = mean;
  gp.kernel_ = kernel;
  gp.X_ = X;
  gp.p_ = parameters;
  gp.alpha_ = weights;
  gp.Precompute();
  return gp;
}

void GaussianProcess::Precompute() {
  const GpLayout layout(static_cast<int>(X_.cols()), mean_, kernel_);
  X_scaled_.clear();
  inverse_length_.clear();
  scaled_alpha_.clear();
  linear_weights_.clear();
  for (int i = 0; i < 3; ++i) {
    const Eigen::VectorXd& p = p_[static_cast<std::size_t>(i)];
    Eigen::VectorXd inverse_length = Eigen::VectorXd::Ones(layout.m);
    if (layout.rbf) {
      for (int d = 0; d < layout.m; ++d) inverse_length[d] = std::exp(-p[layout.log_length(d)]);
    }
    X_scaled_.push_back(X_ * inverse_length.asDiagonal());
    inverse_length_.push_back(inverse_length);
    scaled_alpha_.push_back(layout.rbf ? Eigen::VectorXd(std::exp(2.0 * p[layout.log_sf()]) * alpha_[i])
                                       : Eigen::VectorXd());
    Eigen::VectorXd w = Eigen::VectorXd::Zero(layout.m);
    if (layout.linear_mean) w += p.segment(layout.c(0), layout.m);
    if (layout.linear_kernel) w += std::exp(2.0 * p[layout.log_sl()]) * (X_.transpose() * alpha_[i]);
    linear_weights_.push_back(std::move(w));
  }
}

Eigen::Vector3d GaussianProcess::PredictMean(const Eigen::VectorXd& x) const {
  const GpLayout layout(static_cast<int>(X_.cols()), mean_, kernel_);
  ROAMLAB_CHECK(x.size() == layout.m, "PredictMean: input has " << x.size() << " entries, expected " << layout.m);
  Eigen::Vector3d mean;
  Eigen::ArrayXd d2(layout.rbf ? X_.rows() : 0);
  for (int i = 0; i < 3; ++i) {
    // Linear mean and linear kernel: (c + sl^2 X^T a)^T x, O(m).
    double value = linear_weights_[i].dot(x);
    if (layout.rbf) {
      // sum_n (sf^2 a_n) exp(-1/2 |x_n / l - x / l|^2), O(n m), vectorized.
      const Eigen::MatrixXd& Xs = X_scaled_[i];
      const Eigen::VectorXd xs = x.cwiseProduct(inverse_length_[i]);
      d2 = (Xs.col(0).array() - xs[0]).square();
      for (int d = 1; d < layout.m; ++d) d2 += (Xs.col(d).array() - xs[d]).square();
      value += (scaled_alpha_[i].array() * (-0.5 * d2).exp()).sum();
    }
    mean[i] = value;
  }
  return mean;
}

Eigen::Matrix3d GaussianProcess::PredictCovariance(const Eigen::VectorXd& x) const {
  ROAMLAB_CHECK(has_factor(), "PredictCovariance needs a model trained with GaussianProcess::Train");
  const GpLayout layout(static_cast<int>(X_.cols()), mean_, kernel_);
  ROAMLAB_CHECK(x.size() == layout.m, "PredictCovariance: input size");
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  const Eigen::MatrixXd xr = x.transpose();
  for (int i = 0; i < 3; ++i) {
    const Eigen::VectorXd& p = p_[static_cast<std::size_t>(i)];
    const Eigen::VectorXd k = KernelMatrix(layout, p, X_, xr, nullptr);
    const double kxx = KernelMatrix(layout, p, xr, xr, nullptr)(0, 0);
    const Eigen::VectorXd v = factor_[i].matrixL().solve(k);
    cov(i, i) = std::max(kxx - v.squaredNorm(), 0.0);
  }
  return cov;
}

}  // namespace roamlab::estimator::odometry
