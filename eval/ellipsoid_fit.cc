#include "eval/ellipsoid_fit.h"

#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/SVD>

namespace roamlab::eval {

namespace {

// The symmetric square root of a symmetric positive semi-definite matrix.
Eigen::Matrix3d SymmetricSqrt(const Eigen::Matrix3d& S) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(S);
  return eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal() * eig.eigenvectors().transpose();
}

// The ellipsoid-specific fit (Li and Griffiths, 2004): min |D v|^2 subject to 4 J - I^2 = 1 on the quadratic part,
// I = a + b + c, J = ab + bc + ca - f^2 - g^2 - h^2, which only ellipsoids satisfy. With S = D^T D split at the six
// quadratic coefficients, v2 = -S22^-1 S21 v1 and C1^-1 (S11 - S12 S22^-1 S21) v1 = lambda v1, the solution being the
// eigenvector of the only positive eigenvalue. Empty when no eigenvalue is positive.
std::optional<Eigen::VectorXd> EllipsoidSpecific(const Eigen::MatrixXd& D) {
  const Eigen::MatrixXd S = D.transpose() * D;
  const Eigen::Matrix<double, 6, 6> S11 = S.topLeftCorner<6, 6>();
  const Eigen::Matrix<double, 6, 4> S12 = S.topRightCorner<6, 4>();
  const Eigen::Matrix4d S22 = S.bottomRightCorner<4, 4>();
  const Eigen::FullPivLU<Eigen::Matrix4d> lu22(S22);
  if (!lu22.isInvertible()) return std::nullopt;
  const Eigen::Matrix<double, 4, 6> T = -lu22.solve(S12.transpose());
  Eigen::Matrix<double, 6, 6> C1 = Eigen::Matrix<double, 6, 6>::Zero();
  C1.topLeftCorner<3, 3>() << -1, 1, 1, 1, -1, 1, 1, 1, -1;
  C1.bottomRightCorner<3, 3>() = -4.0 * Eigen::Matrix3d::Identity();
  const Eigen::Matrix<double, 6, 6> M = C1.inverse() * (S11 + S12 * T);
  const Eigen::EigenSolver<Eigen::Matrix<double, 6, 6>> eig(M);
  int best = -1;
  for (int i = 0; i < 6; ++i)
    if (eig.eigenvalues()[i].real() > 0.0 && (best < 0 || eig.eigenvalues()[i].real() > eig.eigenvalues()[best].real()))
      best = i;
  if (best < 0) return std::nullopt;
  const Eigen::Matrix<double, 6, 1> v1 = eig.eigenvectors().col(best).real();
  Eigen::VectorXd v(10);
  v << v1, T * v1;
  return v;
}

// The quadric's centre and shape M ((x - centre)^T M (x - centre) = 1); empty unless M is positive definite.
std::optional<std::pair<Eigen::Vector3d, Eigen::Matrix3d>> ToEllipsoid(const Eigen::VectorXd& v) {
  Eigen::Matrix3d Q;
  Q << v[0], v[5], v[4], v[5], v[1], v[3], v[4], v[3], v[2];
  const Eigen::Vector3d u(v[6], v[7], v[8]);
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(Q);
  if (!lu.isInvertible()) return std::nullopt;
  const Eigen::Vector3d centre = -lu.solve(u);
  const Eigen::Matrix3d M = Q / (centre.dot(Q * centre) - v[9]);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(M);
  if (!(eig.eigenvalues().minCoeff() > 0.0)) return std::nullopt;
  return std::make_pair(centre, M);
}

}  // namespace

Eigen::Matrix3d SymmetricFactor(const Eigen::Matrix3d& A) { return SymmetricSqrt(A * A.transpose()); }

Result<EllipsoidFit> FitEllipsoid(const std::vector<Eigen::Vector3d>& samples, EllipsoidFitMethod method) {
  const int n = static_cast<int>(samples.size());
  if (n < 10) return Status::Error("ellipsoid fit: " + std::to_string(n) + " samples, at least 10 needed");
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& z : samples) {
    if (!z.allFinite()) return Status::Error("ellipsoid fit: a sample is not finite");
    mean += z;
  }
  mean /= n;
  double spread = 0.0;
  for (const Eigen::Vector3d& z : samples) spread += (z - mean).squaredNorm();
  spread = std::sqrt(spread / n);
  if (!(spread > 0.0)) return Status::Error("ellipsoid fit: the samples do not spread");

  // The design matrix on normalized samples x = (z - mean) / spread.
  Eigen::MatrixXd D(n, 10);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d x = (samples[static_cast<std::size_t>(i)] - mean) / spread;
    D.row(i) << x.x() * x.x(), x.y() * x.y(), x.z() * x.z(), 2 * x.y() * x.z(), 2 * x.x() * x.z(), 2 * x.x() * x.y(),
        2 * x.x(), 2 * x.y(), 2 * x.z(), 1.0;
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(D, Eigen::ComputeThinV);
  EllipsoidFit fit;
  std::optional<std::pair<Eigen::Vector3d, Eigen::Matrix3d>> ellipsoid;
  if (method == EllipsoidFitMethod::kGeneral) ellipsoid = ToEllipsoid(svd.matrixV().col(9));
  if (!ellipsoid) {
    const std::optional<Eigen::VectorXd> v = EllipsoidSpecific(D);
    if (v) ellipsoid = ToEllipsoid(*v);
    fit.constrained = true;
  }
  if (!ellipsoid)
    return Status::Error(
        "ellipsoid fit: neither the general quadric nor the ellipsoid-specific fit gives an ellipsoid");
  const Eigen::Vector3d centre_x = ellipsoid->first;
  Eigen::Matrix3d M = ellipsoid->second;

  // Back to raw units: x = (z - mean) / spread, so M_z = M / spread^2.
  fit.centre = mean + spread * centre_x;
  M /= spread * spread;
  fit.radius = std::pow(M.determinant(), -1.0 / 6.0);
  fit.correction = fit.radius * SymmetricSqrt(M);
  double sum = 0.0;
  for (const Eigen::Vector3d& z : samples) {
    const double r = (fit.correction * (z - fit.centre)).norm() - fit.radius;
    sum += r * r;
  }
  fit.rms_residual = std::sqrt(sum / n);
  return fit;
}

Eigen::Matrix3d EllipsoidCentreCovariance(const EllipsoidFit& fit, const std::vector<Eigen::Vector3d>& samples,
                                          double sigma) {
  // M's entries scaled by r^2 (about 1 for a near-sphere), so that all nine columns have comparable size.
  const double r2 = fit.radius * fit.radius;
  const Eigen::Matrix3d M = fit.correction * fit.correction / r2;
  Eigen::Matrix<double, 9, 9> information = Eigen::Matrix<double, 9, 9>::Zero();
  for (const Eigen::Vector3d& z : samples) {
    const Eigen::Vector3d y = z - fit.centre;
    const Eigen::Vector3d gradient = M * y;
    const double norm = gradient.norm();
    if (!(norm > 0.0)) continue;
    Eigen::Matrix<double, 9, 1> row;
    row << -gradient / norm, y.cwiseProduct(y) / (2.0 * norm * r2), y.y() * y.z() / (norm * r2),
        y.x() * y.z() / (norm * r2), y.x() * y.y() / (norm * r2);
    information.noalias() += row * row.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 9, 9>> eig(information);
  const double largest = eig.eigenvalues().maxCoeff();
  if (!(eig.eigenvalues().minCoeff() > 1e-12 * largest))
    return Eigen::Matrix3d::Constant(std::numeric_limits<double>::infinity());
  const Eigen::Matrix<double, 9, 9> covariance =
      eig.eigenvectors() * eig.eigenvalues().cwiseInverse().asDiagonal() * eig.eigenvectors().transpose();
  return sigma * sigma * covariance.topLeftCorner<3, 3>();
}

}  // namespace roamlab::eval
