// Marginalization for fixed-lag tracking (seed 000, Section III-B, after Carlevaris-Bianco and Eustice): the factors
// on the variables leaving the window are linearized at the current estimate, the leaving variables are eliminated by
// a Schur complement, and what they said about the rest becomes one linear prior on their Markov blanket:
//
//   e_prior(x) = r0 + J [x_1 [-] x0_1; ...; x_n [-] x0_n],     J^T J = H_BB - H_Bm H_mm^-1 H_mB,
//                                                                J^T r0 = g_B - H_Bm H_mm^-1 g_m,
//
// with x0 the linearization point, so no information is thrown away (up to linearization).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "estimator/factor.h"
#include "estimator/graph.h"

namespace roamlab::estimator {

class LinearPriorFactor final : public Factor {
 public:
  LinearPriorFactor(std::vector<Manifold> manifolds, std::vector<Eigen::VectorXd> linearization_point,
                    Eigen::MatrixXd J, Eigen::VectorXd r0);
  int residual_dim() const override { return static_cast<int>(r0_.size()); }
  int noise_dim() const override { return static_cast<int>(r0_.size()); }
  const std::vector<Manifold>& manifolds() const override { return manifolds_; }
  // e = r0 + J dx with unit noise: whitened once (by the identity) instead of at every linearization.
  bool additive_noise() const override { return true; }
  bool Evaluate(const double* const* values, double* error, double* const* jacobians,
                double* noise_jacobian) const override;

 private:
  std::vector<Manifold> manifolds_;
  std::vector<Eigen::VectorXd> x0_;
  std::vector<int> offsets_;
  Eigen::MatrixXd J_;
  Eigen::VectorXd r0_;
};

class SolverWorkspace;

// Removes `leaving` (and every factor touching them) from the graph, replacing those factors by one linear prior on
// the free variables they also touched. Returns false (and changes nothing) if a factor cannot be linearized.
// `last_solve` (optional): the workspace of the solve that left the graph at its current values; the factors it
// linearized at exactly these values are taken from it instead of being linearized again (the same numbers).
bool Marginalize(const std::vector<VariableId>& leaving, Graph* graph, const SolverWorkspace* last_solve = nullptr);

}  // namespace roamlab::estimator
