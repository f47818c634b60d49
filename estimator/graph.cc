#include "estimator/graph.h"

#include <algorithm>

#include <Eigen/Cholesky>

#include "common/check.h"

namespace roamlab::estimator {

VariableId Graph::AddVariable(Variable variable) {
  ROAMLAB_CHECK(variable.value.size() == variable.manifold.ambient_dim(),
                "variable '" << variable.name << "' has " << variable.value.size() << " values for manifold "
                             << variable.manifold.Name());
  const VariableId id = next_variable_++;
  variables_.Add(id, std::move(variable));
  factors_of_.Add(id, {});
  return id;
}

std::shared_ptr<const NoiseModel> Graph::SharedNoise(Eigen::MatrixXd covariance, const std::string& stream) {
  constexpr std::size_t kRecent = 8;
  for (std::size_t i = 0; i < recent_noise_.size(); ++i) {
    const Eigen::MatrixXd& c = recent_noise_[i]->covariance;
    if (c.rows() == covariance.rows() && c.cols() == covariance.cols() && c == covariance) {
      std::rotate(recent_noise_.begin(), recent_noise_.begin() + static_cast<std::ptrdiff_t>(i),
                  recent_noise_.begin() + static_cast<std::ptrdiff_t>(i) + 1);
      return recent_noise_.front();
    }
  }
  // Unit noise (the marginalization's and the calibration's linear priors, added at every step of a window) is
  // positive definite and its own square root: no factorization needed.
  auto model = std::make_shared<NoiseModel>();
  const bool identity = covariance.isIdentity(0.0);
  if (identity) {
    model->sqrt_covariance = covariance;
  } else {
    const Eigen::LLT<Eigen::MatrixXd> llt(covariance);
    ROAMLAB_CHECK(covariance.isApprox(covariance.transpose()) && llt.info() == Eigen::Success,
                  "factor from '" << stream << "': noise covariance is not symmetric positive definite");
    model->sqrt_covariance = llt.matrixL();
  }
  model->sqrt_diagonal = true;
  for (int c = 0; c < model->sqrt_covariance.cols(); ++c)
    for (int r = c + 1; r < model->sqrt_covariance.rows(); ++r)
      model->sqrt_diagonal &= model->sqrt_covariance(r, c) == 0.0;
  model->covariance = std::move(covariance);
  if (recent_noise_.size() == kRecent) recent_noise_.pop_back();
  recent_noise_.insert(recent_noise_.begin(), std::move(model));
  return recent_noise_.front();
}

FactorId Graph::AddFactor(std::unique_ptr<Factor> factor, std::vector<VariableId> variables,
                          Eigen::MatrixXd noise_covariance, Loss loss, std::string stream, Time stamp) {
  ROAMLAB_CHECK(factor != nullptr, "null factor");
  ROAMLAB_CHECK(
      factor->manifolds().size() == variables.size(),
      "factor from '" << stream << "' takes " << factor->manifolds().size() << " variables, got " << variables.size());
  for (std::size_t i = 0; i < variables.size(); ++i) {
    const Variable& v = variable(variables[i]);
    ROAMLAB_CHECK(v.manifold == factor->manifolds()[i],
                  "factor from '" << stream << "': variable " << i << " ('" << v.name << "') is " << v.manifold.Name()
                                  << ", expected " << factor->manifolds()[i].Name());
  }
  ROAMLAB_CHECK(noise_covariance.rows() == factor->noise_dim() && noise_covariance.cols() == factor->noise_dim(),
                "factor from '" << stream << "': noise covariance is " << noise_covariance.rows() << "x"
                                << noise_covariance.cols() << ", expected " << factor->noise_dim());
  std::shared_ptr<const NoiseModel> noise = SharedNoise(std::move(noise_covariance), stream);
  const FactorId id = next_factor_++;
  for (VariableId v : variables) factors_of_.Find(v)->push_back(id);
  FactorEntry entry;
  entry.factor = std::move(factor);
  entry.variables = std::move(variables);
  entry.noise = std::move(noise);
  entry.loss = loss;
  entry.stream = std::move(stream);
  entry.stamp = stamp;
  factors_.Add(id, std::move(entry));
  return id;
}

void Graph::RemoveFactor(FactorId id) {
  const FactorEntry* entry = factors_.Find(id);
  ROAMLAB_CHECK(entry != nullptr, "no factor " << id);
  for (VariableId v : entry->variables) {
    std::vector<FactorId>& list = *factors_of_.Find(v);
    list.erase(std::remove(list.begin(), list.end(), id), list.end());
  }
  factors_.Erase(id);
}

void Graph::RemoveVariable(VariableId id) {
  const Variable* variable = variables_.Find(id);
  ROAMLAB_CHECK(variable != nullptr, "no variable " << id);
  const std::vector<FactorId>& factors = *factors_of_.Find(id);
  ROAMLAB_CHECK(factors.empty(), "variable '" << variable->name << "' still has " << factors.size() << " factors");
  factors_of_.Erase(id);
  variables_.Erase(id);
}

const Variable& Graph::variable(VariableId id) const {
  const Variable* v = variables_.Find(id);
  ROAMLAB_CHECK(v != nullptr, "no variable " << id);
  return *v;
}

Variable& Graph::mutable_variable(VariableId id) {
  Variable* v = variables_.Find(id);
  ROAMLAB_CHECK(v != nullptr, "no variable " << id);
  return *v;
}

const FactorEntry& Graph::factor(FactorId id) const {
  const FactorEntry* entry = factors_.Find(id);
  ROAMLAB_CHECK(entry != nullptr, "no factor " << id);
  return *entry;
}

FactorEntry& Graph::mutable_factor(FactorId id) {
  FactorEntry* entry = factors_.Find(id);
  ROAMLAB_CHECK(entry != nullptr, "no factor " << id);
  return *entry;
}

std::vector<FactorId> Graph::FactorsOf(VariableId id) const {
  const std::vector<FactorId>* factors = factors_of_.Find(id);
  ROAMLAB_CHECK(factors != nullptr, "no variable " << id);
  return *factors;
}

}  // namespace roamlab::estimator
