// Small graphs shared by the solver, covariance, normal-equation and marginalization tests.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "estimator/graph.h"

namespace roamlab::estimator::testing {

// One pose seen by four GPS antennas at known, fixed lever arms: position and orientation are observable.
struct MultiAntennaProblem {
  Graph graph;
  VariableId pose;
  Eigen::VectorXd truth;

  // The pose starts at truth [+] N(0, 0.3^2); each antenna gives 20 readings with noise N(0, noise_sigma^2) per axis.
  MultiAntennaProblem(double noise_sigma, std::uint32_t seed);

  // The pose's value [-] truth.
  Eigen::VectorXd Error() const;
};

// A linear prior factor with random J and r0 (square, full rank almost surely) on `ids`, linearized at a point near
// their current values.
void TieWithRandomPrior(const std::vector<VariableId>& ids, std::mt19937* rng, Graph* graph);

}  // namespace roamlab::estimator::testing
