#include "bench/ceres_peer.h"

#include <map>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>

#include <ceres/ceres.h>
#include <Eigen/Cholesky>

#include "common/check.h"
#include "estimator/factor.h"
#include "estimator/geometry.h"
#include "estimator/models/accelerometer.h"
#include "estimator/models/ackermann_velocity.h"
#include "estimator/models/gps.h"
#include "estimator/models/gyroscope.h"
#include "estimator/models/magnetometer.h"

// The models branch on the value of a scalar through ValueOf (estimator/jet.h); Ceres' jets find this one by
// argument-dependent lookup.
namespace ceres {
template <int N>
double ValueOf(const Jet<double, N>& x) {
  return x.a;
}
}  // namespace ceres

namespace roamlab::bench {
namespace {

using estimator::Quaternion;
using estimator::Vector3;

// roamlab's manifolds for Ceres: x [+] d = x Exp(d) (pose: translation added in W, rotation on the right).
struct PosePlus {
  template <typename T>
  bool Plus(const T* x, const T* d, T* out) const {
    for (int i = 0; i < 3; ++i) out[i] = x[i] + d[i];
    const Quaternion<T> q = estimator::QuaternionFromArray(x + 3);
    estimator::QuaternionToArray<T>(q * estimator::QuaternionExp<T>(Vector3<T>(d[3], d[4], d[5])), out + 3);
    return true;
  }
  template <typename T>
  bool Minus(const T* y, const T* x, T* out) const {
    for (int i = 0; i < 3; ++i) out[i] = y[i] - x[i];
    const Vector3<T> phi = estimator::QuaternionLog<T>(estimator::QuaternionFromArray(x + 3).conjugate() *
                                                       estimator::QuaternionFromArray(y + 3));
    for (int i = 0; i < 3; ++i) out[3 + i] = phi[i];
    return true;
  }
};

struct QuaternionPlus {
  template <typename T>
  bool Plus(const T* x, const T* d, T* out) const {
    estimator::QuaternionToArray<T>(
        estimator::QuaternionFromArray(x) * estimator::QuaternionExp<T>(Vector3<T>(d[0], d[1], d[2])), out);
    return true;
  }
  template <typename T>
  bool Minus(const T* y, const T* x, T* out) const {
    const Vector3<T> phi =
        estimator::QuaternionLog<T>(estimator::QuaternionFromArray(x).conjugate() * estimator::QuaternionFromArray(y));
    for (int i = 0; i < 3; ++i) out[i] = phi[i];
    return true;
  }
};

// L^-1 of one factor, shared between its cost function and the callback that refreshes it.
struct Whitening {
  Eigen::MatrixXd inverse_sqrt_covariance;
};

template <typename T, std::size_t>
using ConstPointer = const T*;

// Ceres functor of a roamlab error model: e(x, eta = 0) whitened by L^-1.
template <typename Model, typename Indices = std::make_index_sequence<std::tuple_size_v<typename Model::Blocks>>>
class ModelCost;

template <typename Model, std::size_t... I>
class ModelCost<Model, std::index_sequence<I...>> {
 public:
  ModelCost(const Model* model, const Whitening* whitening) : model_(model), whitening_(whitening) {}

  template <typename T>
  bool operator()(ConstPointer<T, I>... x, T* residual) const {
    const T* blocks[] = {x...};
    T noise[Model::kNoiseDim];
    for (auto& n : noise) n = T(0.0);
    T e[Model::kResidualDim];
    if (!(*model_)(blocks, noise, e)) return false;
    const Eigen::MatrixXd& W = whitening_->inverse_sqrt_covariance;
    for (int r = 0; r < Model::kResidualDim; ++r) {
      residual[r] = T(0.0);
      for (int c = 0; c <= r; ++c) residual[r] += W(r, c) * e[c];
    }
    return true;
  }

 private:
  const Model* model_;
  const Whitening* whitening_;
};

template <typename Model, std::size_t... I>
ceres::CostFunction* MakeCost(const Model* model, const Whitening* whitening, std::index_sequence<I...>) {
  return new ceres::AutoDiffCostFunction<ModelCost<Model>, Model::kResidualDim,
                                         std::tuple_element_t<I, typename Model::Blocks>::kAmbient...>(
      new ModelCost<Model>(model, whitening));
}

// The cost function of a factor whose model is Model, or null when it is another model.
template <typename Model>
ceres::CostFunction* TryModel(const estimator::Factor& factor, const Whitening* whitening) {
  const auto* f = dynamic_cast<const estimator::AutoDiffFactor<Model>*>(&factor);
  if (f == nullptr) return nullptr;
  return MakeCost(&f->model(), whitening, std::make_index_sequence<std::tuple_size_v<typename Model::Blocks>>());
}

// Recomputes L^-1 of the factors whose error covariance depends on the estimate (eq. 1) at every new linearization
// point, as roamlab does, and holds it while a trial point is evaluated.
class CovarianceCallback final : public ceres::EvaluationCallback {
 public:
  struct Entry {
    const estimator::FactorEntry* factor;
    std::vector<const double*> values;
    Whitening* whitening;
  };
  void Add(Entry entry) { entries_.push_back(std::move(entry)); }
  bool Refresh() {
    for (Entry& e : entries_) {
      const estimator::Factor& f = *e.factor->factor;
      Eigen::VectorXd error(f.residual_dim());
      Eigen::MatrixXd J_eta(f.residual_dim(), f.noise_dim());
      if (!f.Evaluate(e.values.data(), error.data(), nullptr, J_eta.data())) return false;
      const Eigen::LLT<Eigen::MatrixXd> llt(J_eta * e.factor->noise->covariance * J_eta.transpose());
      if (llt.info() != Eigen::Success) return false;
      e.whitening->inverse_sqrt_covariance =
          llt.matrixL().solve(Eigen::MatrixXd::Identity(f.residual_dim(), f.residual_dim()));
    }
    return true;
  }
  void PrepareForEvaluation(bool evaluate_jacobians, bool /*new_evaluation_point*/) override {
    if (evaluate_jacobians) Refresh();
  }

 private:
  std::vector<Entry> entries_;
};

}  // namespace

CeresPeerResult SolveWithCeres(const estimator::Graph& graph, const CeresPeerOptions& options) {
  CeresPeerResult out;
  CovarianceCallback callback;
  ceres::Problem::Options problem_options;
  problem_options.evaluation_callback = &callback;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  ceres::AutoDiffManifold<PosePlus, 7, 6> pose_manifold;
  ceres::AutoDiffManifold<QuaternionPlus, 4, 3> quaternion_manifold;

  // Parameter blocks: copies of the variables' values.
  std::map<estimator::VariableId, Eigen::VectorXd> values;
  for (const auto& [id, v] : graph.variables()) values[id] = v.value;

  // Residual blocks: one per active factor.
  std::vector<std::unique_ptr<Whitening>> whitenings;
  for (const auto& [fid, entry] : graph.factors()) {
    if (!entry.active) continue;
    ROAMLAB_CHECK(entry.loss.type == estimator::Loss::Type::kTrivial,
                  "the Ceres peer handles the trivial loss only (stream '" << entry.stream << "')");
    auto whitening = std::make_unique<Whitening>();
    std::vector<double*> blocks;
    for (estimator::VariableId v : entry.variables) blocks.push_back(values.at(v).data());
    if (entry.factor->additive_noise()) {
      const int m = entry.factor->residual_dim();
      whitening->inverse_sqrt_covariance =
          entry.noise->sqrt_covariance.triangularView<Eigen::Lower>().solve(Eigen::MatrixXd::Identity(m, m));
    } else {
      callback.Add({&entry, std::vector<const double*>(blocks.begin(), blocks.end()), whitening.get()});
    }
    ceres::CostFunction* cost = nullptr;
    const estimator::Factor& f = *entry.factor;
    if (cost == nullptr) cost = TryModel<estimator::AckermannVelocityError>(f, whitening.get());
    if (cost == nullptr) cost = TryModel<estimator::GyroscopeError>(f, whitening.get());
    if (cost == nullptr) cost = TryModel<estimator::AccelerometerError>(f, whitening.get());
    if (cost == nullptr) cost = TryModel<estimator::MagnetometerError>(f, whitening.get());
    if (cost == nullptr) cost = TryModel<estimator::GpsError>(f, whitening.get());
    ROAMLAB_CHECK(cost != nullptr, "the Ceres peer has no cost function for stream '" << entry.stream << "'");
    problem.AddResidualBlock(cost, nullptr, blocks);
    whitenings.push_back(std::move(whitening));
  }
  if (!callback.Refresh()) {
    out.termination = "error covariance not positive definite at the initial values";
    return out;
  }

  // Manifolds and fixed variables.
  for (const auto& [id, v] : graph.variables()) {
    double* x = values.at(id).data();
    if (!problem.HasParameterBlock(x)) continue;
    if (v.manifold.kind() == estimator::ManifoldKind::kPose) problem.SetManifold(x, &pose_manifold);
    if (v.manifold.kind() == estimator::ManifoldKind::kQuaternion) problem.SetManifold(x, &quaternion_manifold);
    if (v.fixed) problem.SetParameterBlockConstant(x);
  }

  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver_options.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  solver_options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  solver_options.initial_trust_region_radius = 1.0 / options.initial_lambda;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.function_tolerance = options.function_tolerance;
  solver_options.parameter_tolerance = options.parameter_tolerance;
  solver_options.num_threads = 1;
  solver_options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);

  out.seconds = summary.total_time_in_seconds;
  out.iterations = static_cast<int>(summary.iterations.size()) - 1;
  out.initial_cost = summary.initial_cost;
  out.final_cost = summary.final_cost;
  out.termination = summary.message;
  out.usable = summary.IsSolutionUsable();
  for (const auto& [id, v] : graph.variables())
    if (!v.fixed) out.values.emplace_back(id, values.at(id));
  return out;
}

}  // namespace roamlab::bench
