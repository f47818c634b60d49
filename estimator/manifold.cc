#include "estimator/manifold.h"

#include "common/check.h"

namespace roamlab::estimator {

std::string Manifold::Name() const {
  switch (kind_) {
    case ManifoldKind::kEuclidean:
      return "R" + std::to_string(ambient_dim_);
    case ManifoldKind::kQuaternion:
      return "S3";
    case ManifoldKind::kPose:
      return "SE3";
  }
  return "?";
}

void Manifold::Plus(const double* x, const double* delta, double* out) const {
  switch (kind_) {
    case ManifoldKind::kEuclidean:
      for (int i = 0; i < ambient_dim_; ++i) out[i] = x[i] + delta[i];
      return;
    case ManifoldKind::kQuaternion:
      QuaternionBlock::Plus<double>(x, delta, out);
      return;
    case ManifoldKind::kPose:
      PoseBlock::Plus<double>(x, delta, out);
      return;
  }
}

void Manifold::Minus(const double* x, const double* y, double* delta) const {
  switch (kind_) {
    case ManifoldKind::kEuclidean:
      for (int i = 0; i < ambient_dim_; ++i) delta[i] = x[i] - y[i];
      return;
    case ManifoldKind::kQuaternion: {
      const Eigen::Vector3d d = QuaternionLog<double>(QuaternionFromArray(y).conjugate() * QuaternionFromArray(x));
      for (int i = 0; i < 3; ++i) delta[i] = d[i];
      return;
    }
    case ManifoldKind::kPose: {
      for (int i = 0; i < 3; ++i) delta[i] = x[i] - y[i];
      const Eigen::Vector3d d =
          QuaternionLog<double>(QuaternionFromArray(y + 3).conjugate() * QuaternionFromArray(x + 3));
      for (int i = 0; i < 3; ++i) delta[3 + i] = d[i];
      return;
    }
  }
}

Eigen::VectorXd Manifold::Identity() const {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(ambient_dim_);
  if (kind_ == ManifoldKind::kQuaternion) x[0] = 1.0;
  if (kind_ == ManifoldKind::kPose) x[3] = 1.0;
  return x;
}

}  // namespace roamlab::estimator
