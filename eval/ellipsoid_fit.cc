#include "eval/ellipsoid_fit.h"

#include <cmath>
#include <string>

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

}  // namespace

Eigen::Matrix3d SymmetricFactor(const Eigen::Matrix3d& A) { return SymmetricSqrt(A * A.transpose()); }

Result<EllipsoidFit> FitEllipsoid(const std::vector<Eigen::Vector3d>& samples) {
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
  const Eigen::VectorXd v = svd.matrixV().col(9);
  Eigen::Matrix3d Q;
  Q << v[0], v[5], v[4], v[5], v[1], v[3], v[4], v[3], v[2];
  const Eigen::Vector3d u(v[6], v[7], v[8]);
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(Q);
  if (!lu.isInvertible()) return Status::Error("ellipsoid fit: the quadric has no centre (too little coverage)");
  const Eigen::Vector3d centre_x = -lu.solve(u);
  const double k = centre_x.dot(Q * centre_x) - v[9];
  Eigen::Matrix3d M = Q / k;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(M);
  if (!(eig.eigenvalues().minCoeff() > 0.0))
    return Status::Error("ellipsoid fit: the quadric is not an ellipsoid (too little coverage of orientations)");

  // Back to raw units: x = (z - mean) / spread, so M_z = M / spread^2.
  EllipsoidFit fit;
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

}  // namespace roamlab::eval
