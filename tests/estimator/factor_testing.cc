#include "tests/estimator/factor_testing.h"

#include <algorithm>

#include "estimator/geometry.h"

namespace roamlab::estimator::testing {

Eigen::VectorXd RandomPoint(const Manifold& manifold, std::mt19937* rng, double scale) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::VectorXd x(manifold.ambient_dim());
  for (int i = 0; i < x.size(); ++i) x[i] = normal(*rng);
  switch (manifold.kind()) {
    case ManifoldKind::kEuclidean:
      x *= scale;
      break;
    case ManifoldKind::kQuaternion:
      x.normalize();
      break;
    case ManifoldKind::kPose:
      x.head<3>() *= scale;
      x.tail<4>().normalize();
      break;
  }
  return x;
}

Eigen::VectorXd Perturb(const Manifold& manifold, const Eigen::VectorXd& x, double sigma, std::mt19937* rng) {
  std::normal_distribution<double> normal(0.0, sigma);
  Eigen::VectorXd d(manifold.tangent_dim());
  for (int i = 0; i < d.size(); ++i) d[i] = normal(*rng);
  Eigen::VectorXd out(x.size());
  manifold.Plus(x.data(), d.data(), out.data());
  return out;
}

Linearization Evaluate(const Factor& factor, const std::vector<Eigen::VectorXd>& values) {
  const int m = factor.residual_dim();
  Linearization lin;
  lin.error.resize(m);
  std::vector<const double*> ptrs;
  std::vector<double*> jac_ptrs;
  for (std::size_t i = 0; i < values.size(); ++i) {
    ptrs.push_back(values[i].data());
    lin.jacobians.emplace_back(m, factor.manifolds()[i].tangent_dim());
  }
  for (auto& J : lin.jacobians) jac_ptrs.push_back(J.data());
  lin.noise_jacobian.resize(m, factor.noise_dim());
  EXPECT_TRUE(factor.Evaluate(ptrs.data(), lin.error.data(), jac_ptrs.data(), lin.noise_jacobian.data()));
  return lin;
}

std::vector<Eigen::MatrixXd> NumericJacobians(const Factor& factor, const std::vector<Eigen::VectorXd>& values,
                                              double h) {
  const int m = factor.residual_dim();
  std::vector<Eigen::MatrixXd> jacobians;
  for (std::size_t i = 0; i < values.size(); ++i) {
    const Manifold& manifold = factor.manifolds()[i];
    Eigen::MatrixXd J(m, manifold.tangent_dim());
    for (int k = 0; k < manifold.tangent_dim(); ++k) {
      std::vector<Eigen::VectorXd> plus = values, minus = values;
      Eigen::VectorXd d = Eigen::VectorXd::Zero(manifold.tangent_dim());
      d[k] = h;
      manifold.Plus(values[i].data(), d.data(), plus[i].data());
      d[k] = -h;
      manifold.Plus(values[i].data(), d.data(), minus[i].data());
      std::vector<const double*> pp, pm;
      for (std::size_t j = 0; j < values.size(); ++j) {
        pp.push_back(plus[j].data());
        pm.push_back(minus[j].data());
      }
      Eigen::VectorXd ep(m), em(m);
      EXPECT_TRUE(factor.Evaluate(pp.data(), ep.data(), nullptr, nullptr));
      EXPECT_TRUE(factor.Evaluate(pm.data(), em.data(), nullptr, nullptr));
      J.col(k) = (ep - em) / (2 * h);
    }
    jacobians.push_back(J);
  }
  return jacobians;
}

void ExpectJacobiansMatchNumeric(const Factor& factor, const std::vector<Eigen::VectorXd>& values, double tolerance) {
  const Linearization lin = Evaluate(factor, values);
  const std::vector<Eigen::MatrixXd> numeric = NumericJacobians(factor, values);
  for (std::size_t i = 0; i < values.size(); ++i) {
    const double scale = std::max(1.0, numeric[i].cwiseAbs().maxCoeff());
    EXPECT_LE((lin.jacobians[i] - numeric[i]).cwiseAbs().maxCoeff(), tolerance * scale)
        << "variable " << i << "\nanalytic\n" << lin.jacobians[i] << "\nnumeric\n" << numeric[i];
  }
}

}  // namespace roamlab::estimator::testing
