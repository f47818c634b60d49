// The estimation hyper-graph (seed 000, Section III-B): variables (poses and calibration parameters) and factors (one
// per measurement, connecting any number of variables).
//
// Variables and factors get stable integer ids; iteration is in id order, so solving is deterministic. A variable is
// fixed or free; fixed variables enter the errors but not the normal equations. A factor carries its model
// (factor.h), the covariance of its noise input (Sigma_eta of eq. 1), a robust loss, the name of the stream it came
// from (for per-stream statistics) and an `active` flag (chi-square gating switches outliers off; they stay counted).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/time.h"
#include "estimator/factor.h"
#include "estimator/id_table.h"
#include "estimator/loss.h"
#include "estimator/manifold.h"

namespace roamlab::estimator {

using VariableId = std::int64_t;
using FactorId = std::int64_t;

struct Variable {
  std::string name;  // e.g. "pose", "gps.lever_arm"
  Manifold manifold = Manifold::Euclidean(0);
  Eigen::VectorXd value;  // ambient representation
  bool fixed = false;
  std::optional<Time> stamp;  // poses and time-varying parameter instances
};

// The noise input of a factor: Sigma_eta and its Cholesky factor. A stream's factors mostly share one (a whole
// recording's would otherwise hold a million copies of a few matrices, each in its own heap blocks, read from memory
// one by one at every linearization).
struct NoiseModel {
  Eigen::MatrixXd covariance;       // noise_dim x noise_dim, Sigma_eta
  Eigen::MatrixXd sqrt_covariance;  // L (lower) with L L^T = Sigma_eta
  bool sqrt_diagonal = false;       // L is diagonal (independent noise components): whitening is a division
};

struct FactorEntry {
  std::unique_ptr<Factor> factor;
  std::vector<VariableId> variables;
  std::shared_ptr<const NoiseModel> noise;  // shared by the factors added with the same covariance
  Loss loss;
  std::string stream;
  Time stamp;
  bool active = true;
};

class Graph {
 public:
  VariableId AddVariable(Variable variable);
  // The variables' manifolds must match the factor's; the noise covariance must be noise_dim square and symmetric
  // positive definite (checked).
  FactorId AddFactor(std::unique_ptr<Factor> factor, std::vector<VariableId> variables,
                     Eigen::MatrixXd noise_covariance, Loss loss, std::string stream, Time stamp);

  // Removes a factor; removes a variable (no factor may still reference it).
  void RemoveFactor(FactorId id);
  void RemoveVariable(VariableId id);

  bool HasVariable(VariableId id) const { return variables_.count(id) != 0; }
  const Variable& variable(VariableId id) const;
  Variable& mutable_variable(VariableId id);
  const FactorEntry& factor(FactorId id) const;
  FactorEntry& mutable_factor(FactorId id);

  // In id order; walked as a std::map (begin, end, lower_bound), looked up by Find (id_table.h).
  const IdTable<Variable>& variables() const { return variables_; }
  const IdTable<FactorEntry>& factors() const { return factors_; }
  // Factors that reference a variable, in id order.
  std::vector<FactorId> FactorsOf(VariableId id) const;

 private:
  IdTable<Variable> variables_;
  IdTable<FactorEntry> factors_;
  IdTable<std::vector<FactorId>> factors_of_;  // by variable
  // The noise models of the last few distinct covariances added, the newest first (AddFactor shares them).
  std::vector<std::shared_ptr<const NoiseModel>> recent_noise_;
  // The model of `covariance` (checked symmetric positive definite): a recent one if equal, else a new one.
  std::shared_ptr<const NoiseModel> SharedNoise(Eigen::MatrixXd covariance, const std::string& stream);

  VariableId next_variable_ = 0;
  FactorId next_factor_ = 0;
};

}  // namespace roamlab::estimator
