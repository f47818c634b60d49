#include "estimator/odometry/robust_linear.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Cholesky>

namespace roamlab::estimator::odometry {
namespace {

double Median(std::vector<double> values) {
  const std::size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(mid), values.end());
  return values[mid];
}

// Weighted least squares for one output: minimizes sum w_n (y_n - x_n^T b)^2. Returns false when singular.
bool WeightedLeastSquares(const Eigen::MatrixXd& X, const Eigen::VectorXd& y, const Eigen::VectorXd& w,
                          Eigen::VectorXd* b) {
  const Eigen::MatrixXd XtW = X.transpose() * w.asDiagonal();
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(XtW * X);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().array() > 0.0).all()) return false;
  *b = ldlt.solve(XtW * y);
  return b->allFinite();
}

}  // namespace

Result<HuberFit> FitHuberLinear(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y, const Eigen::MatrixXd& sigma,
                                const HuberOptions& options) {
  const Eigen::Index n = X.rows();
  const Eigen::Index m = X.cols();
  if (Y.rows() != n || Y.cols() != 3 || sigma.rows() != n || sigma.cols() != 3 || m < 1) {
    return Status::Error("Huber regression: X must be n x m, Y and sigma n x 3");
  }
  if (n <= m) return Status::Error("Huber regression: need more pairs than wheels");
  if (!X.allFinite() || !Y.allFinite() || !sigma.allFinite() || !(sigma.array() > 0.0).all()) {
    return Status::Error("Huber regression: data must be finite and sigma positive");
  }
  HuberFit fit;
  fit.W.resize(3, m);
  for (int i = 0; i < 3; ++i) {
    const Eigen::VectorXd y = Y.col(i);
    const Eigen::VectorXd inv_var = sigma.col(i).array().square().inverse();
    // Start from weighted least squares.
    Eigen::VectorXd b;
    if (!WeightedLeastSquares(X, y, inv_var, &b)) return Status::Error("Huber regression: singular wheel data");
    double scale = 1.0;
    int iteration = 0;
    for (; iteration < options.max_iterations; ++iteration) {
      // Whitened residuals u = (s - W delta) / sigma and their robust scale.
      const Eigen::VectorXd u = (y - X * b).cwiseQuotient(sigma.col(i));
      std::vector<double> abs_u(u.data(), u.data() + n);
      for (double& v : abs_u) v = std::abs(v);
      scale = std::max(1.4826 * Median(abs_u), 1e-12 * (1.0 + u.cwiseAbs().maxCoeff()));
      // Huber weights psi(u') / u' with u' = u / scale.
      Eigen::VectorXd w(n);
      for (Eigen::Index k = 0; k < n; ++k) {
        const double a = std::abs(u[k]) / scale;
        w[k] = inv_var[k] * (a <= options.c ? 1.0 : options.c / a);
      }
      Eigen::VectorXd b_new;
      if (!WeightedLeastSquares(X, y, w, &b_new)) return Status::Error("Huber regression: singular weighted design");
      const double change = (b_new - b).norm();
      b = b_new;
      if (change <= options.tolerance * (1.0 + b.norm())) break;
    }
    fit.W.row(i) = b.transpose();
    fit.scale[i] = scale;
    fit.iterations = std::max(fit.iterations, iteration + 1);
  }
  return fit;
}

std::vector<int> InlierRows(const HuberFit& fit, const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y,
                            const Eigen::MatrixXd& sigma, double threshold) {
  const Eigen::MatrixXd u =
      ((Y - X * fit.W.transpose()).array() / sigma.array()).rowwise() / fit.scale.transpose().array();
  std::vector<int> rows;
  for (Eigen::Index k = 0; k < X.rows(); ++k) {
    if (u.row(k).cwiseAbs().maxCoeff() <= threshold) rows.push_back(static_cast<int>(k));
  }
  return rows;
}

}  // namespace roamlab::estimator::odometry
