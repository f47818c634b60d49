#include "tests/estimator/solver_testing.h"

#include <algorithm>
#include <memory>
#include <optional>

#include "estimator/marginalization.h"
#include "estimator/models/gps.h"
#include "tests/estimator/factor_testing.h"

namespace roamlab::estimator::testing {

MultiAntennaProblem::MultiAntennaProblem(double noise_sigma, std::uint32_t seed) {
  std::mt19937 rng(seed);
  truth = RandomPoint(Manifold::Pose(), &rng, 5.0);
  const Pose<double> T = PoseFromArray(truth.data());
  pose = graph.AddVariable(
      {"pose", Manifold::Pose(), Perturb(Manifold::Pose(), truth, 0.3, &rng), false, Time::FromSeconds(0.0)});
  const std::vector<Eigen::Vector3d> levers = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {-1, -1, 0.5}};
  std::normal_distribution<double> noise(0.0, noise_sigma);
  const VariableId bias =
      graph.AddVariable({"bias", Manifold::Euclidean(3), Eigen::Vector3d::Zero(), true, std::nullopt});
  for (const Eigen::Vector3d& lever : levers) {
    const VariableId l = graph.AddVariable({"lever", Manifold::Euclidean(3), lever, true, std::nullopt});
    for (int k = 0; k < 20; ++k) {
      const Eigen::Vector3d z =
          T.p_world_body + T.q_world_body * lever + Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
      graph.AddFactor(MakeFactor(GpsError(z)), {pose, l, bias},
                      Eigen::Matrix3d::Identity() * std::max(noise_sigma * noise_sigma, 1e-6), Loss::Trivial(), "gps",
                      Time::FromSeconds(0.0));
    }
  }
}

Eigen::VectorXd MultiAntennaProblem::Error() const {
  Eigen::VectorXd d(6);
  Manifold::Pose().Minus(graph.variable(pose).value.data(), truth.data(), d.data());
  return d;
}

void TieWithRandomPrior(const std::vector<VariableId>& ids, std::mt19937* rng, Graph* graph) {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<Manifold> manifolds;
  std::vector<Eigen::VectorXd> x0;
  int dim = 0;
  for (VariableId id : ids) {
    const Variable& v = graph->variable(id);
    manifolds.push_back(v.manifold);
    x0.push_back(Perturb(v.manifold, v.value, 0.1, rng));
    dim += v.manifold.tangent_dim();
  }
  const Eigen::MatrixXd J = Eigen::MatrixXd::NullaryExpr(dim, dim, [&] { return normal(*rng); });
  const Eigen::VectorXd r0 = Eigen::VectorXd::NullaryExpr(dim, [&] { return normal(*rng); });
  graph->AddFactor(std::make_unique<LinearPriorFactor>(manifolds, x0, J, r0), ids, Eigen::MatrixXd::Identity(dim, dim),
                   Loss::Trivial(), "test", Time());
}

}  // namespace roamlab::estimator::testing
