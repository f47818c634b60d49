#include "estimator/solver.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "common/interrupt.h"
#include "estimator/internal/normal_equations.h"

namespace roamlab::estimator {

std::string SolverOptions::Validate() const {
  if (max_iterations < 0) return "max_iterations must be >= 0";
  if (!(function_tolerance >= 0.0)) return "function_tolerance must be >= 0";
  if (!(model_tolerance >= 0.0)) return "model_tolerance must be >= 0";
  if (!(step_tolerance >= 0.0)) return "step_tolerance must be >= 0";
  if (!(time_budget_s > 0.0)) return "time_budget_s must be > 0";
  if (!(initial_lambda > 0.0)) return "initial_lambda must be > 0";
  if (!(relinearize_threshold >= 0.0)) return "relinearize_threshold must be >= 0";
  if (relinearize_threshold > 0.0 && method != Method::kGaussNewton)
    return "relinearize_threshold needs method gauss_newton";
  return "";
}

const char* TerminationName(Termination termination) {
  switch (termination) {
    case Termination::kFunctionTolerance:
      return "function_tolerance";
    case Termination::kModelTolerance:
      return "model_tolerance";
    case Termination::kStepTolerance:
      return "step_tolerance";
    case Termination::kMaxIterations:
      return "max_iterations";
    case Termination::kTimeBudget:
      return "time_budget";
    case Termination::kNoFreeVariables:
      return "no_free_variables";
    case Termination::kFailure:
      return "failure";
  }
  return "unknown";
}

std::vector<VariableId> FreeVariableOrder(const Graph& graph) {
  // Stamped variables by (key, rank, id): a pose at its stamp (rank 1); an instance at the stamp of the next instance
  // of its parameter (rank 0: before the pose that starts it), the newest at the end. Instances of one parameter are
  // created in time order, so the next one is the next of that name in id order. (With one instance per pose this is
  // each pose followed by its instances, their id order.)
  struct Stamped {
    std::int64_t key;
    int rank;
    VariableId id;
    bool fixed;
  };
  std::vector<Stamped> stamped;
  std::vector<VariableId> others;
  std::vector<std::pair<const std::string*, std::size_t>> newest;  // per parameter: its last instance so far
  for (const auto& [id, v] : graph.variables()) {
    if (!v.stamp.has_value()) {
      if (!v.fixed) others.push_back(id);
      continue;
    }
    if (v.name == "pose") {
      stamped.push_back({v.stamp->nanoseconds(), 1, id, v.fixed});
      continue;
    }
    const std::string& name = v.name;  // a structured binding cannot be captured in C++17
    const auto same = std::find_if(newest.begin(), newest.end(), [&](const auto& n) { return *n.first == name; });
    if (same != newest.end()) {
      stamped[same->second].key = v.stamp->nanoseconds();
      same->second = stamped.size();
    } else {
      newest.emplace_back(&v.name, stamped.size());
    }
    stamped.push_back({std::numeric_limits<std::int64_t>::max(), 0, id, v.fixed});
  }
  std::sort(stamped.begin(), stamped.end(), [](const Stamped& a, const Stamped& b) {
    return std::tie(a.key, a.rank, a.id) < std::tie(b.key, b.rank, b.id);
  });
  std::vector<VariableId> order;
  order.reserve(stamped.size() + others.size());
  for (const Stamped& s : stamped)
    if (!s.fixed) order.push_back(s.id);
  order.insert(order.end(), others.begin(), others.end());
  return order;
}

namespace {

double TangentNorm(const std::vector<Variable*>& variables) {
  double sq = 0.0;
  for (const Variable* variable : variables) {
    const Variable& v = *variable;
    if (v.manifold.kind() == ManifoldKind::kEuclidean) sq += v.value.squaredNorm();
    if (v.manifold.kind() == ManifoldKind::kPose) sq += v.value.head<3>().squaredNorm();
  }
  return std::sqrt(sq);
}

// Which variables Levenberg-Marquardt's next step damps (SolverOptions::damping). With kParameters: the constant
// parameters only (the poses and other time-stamped states undamped) after a full step the model predicted well;
// every variable after a shortened or rejected step, and for the rest of the solve once the states alone were not
// positive definite (a pose no row constrains in some direction). With kAll: every variable, always.
//
// Why: Marquardt's lambda diag(H) acts on every pose alike, and a chain of poses tied only by relative rows (a
// stretch dead-reckoned on wheels and IMU between absolute fixes) has curvatures along its long-wavelength modes (the
// chain bending as a whole, carrying the wheel parameters with it) of order (pi / N)^2 of its diagonal over N poses:
// a damping of 1e-2 shortens the step along them thousands of times, and the solve crawls for hundreds of iterations
// to a minimum the undamped states reach in tens. The states' rows tie each pose to its neighbours and to the
// parameters, so with the parameters' step held back the states' step is the Gauss-Newton one given it. After a step
// the model overestimated the damping must reach the states too: raised on the parameters alone it would shorten
// nothing where the states' own step is what overshoots (the damping then climbs to its limit).
class DampingScope {
 public:
  using Damping = internal::NormalEquations::Damping;
  explicit DampingScope(SolverOptions::Damping option) : every_variable_(option == SolverOptions::Damping::kAll) {}
  Damping next() const { return next_; }
  void AfterStep(bool full_step_accepted) {
    next_ = full_step_accepted && !every_variable_ ? Damping::kConstantsOnly : Damping::kAll;
  }
  void StatesNotPositiveDefinite() {
    every_variable_ = true;
    next_ = Damping::kAll;
  }

 private:
  bool every_variable_;
  Damping next_ = every_variable_ ? Damping::kAll : Damping::kConstantsOnly;
};

// Solves the damped system, raising the damping up to ten times while the matrix is not positive definite.
bool SolveWithDamping(internal::NormalEquations* system, double* lambda, DampingScope* scope, Eigen::VectorXd* dx) {
  bool solved = system->Solve(*lambda, dx, scope->next());
  if (!solved && *lambda > 0.0 && scope->next() == DampingScope::Damping::kConstantsOnly) {
    scope->StatesNotPositiveDefinite();
    solved = system->Solve(*lambda, dx, scope->next());
  }
  for (int retry = 0; !solved && retry < 10; ++retry) {
    *lambda = std::max(*lambda * 10.0, 1e-9);
    solved = system->Solve(*lambda, dx, scope->next());
  }
  return solved;
}

// The free variables' values, concatenated, and back.
void SaveValues(const std::vector<Variable*>& free_variables, std::vector<double>* saved) {
  saved->clear();
  for (const Variable* v : free_variables)
    saved->insert(saved->end(), v->value.data(), v->value.data() + v->value.size());
}
void RestoreValues(const std::vector<double>& saved, const std::vector<Variable*>& free_variables) {
  const double* from = saved.data();
  for (Variable* v : free_variables) {
    std::copy(from, from + v->value.size(), v->value.data());
    from += v->value.size();
  }
}

// After a rejected Levenberg-Marquardt step dx: the cost along t * dx is fitted by the parabola through the cost at
// t = 0, its slope g^T dx there and the cost at t = 1, and the step is shortened to the parabola's minimum (t in
// [0.05, 0.9]). Where the quadratic model's curvature along dx is too low (a weak parameter whose errors are bilinear
// in it and in many poses: the IMU's misalignment beside second differences of positions), the measured curvature
// gives the length the model got wrong without another factorization. Returns the shortened step when it lowers the
// cost by more than 1e-3 of the model's decrease for it (with the values left there), otherwise nullopt (with the
// values restored).
std::optional<Eigen::VectorXd> ShortenedStep(internal::NormalEquations* system, const Graph& graph,
                                             const Eigen::VectorXd& dx, double old_cost, double trial_cost,
                                             const std::vector<double>& saved,
                                             const std::vector<Variable*>& free_variables, double* short_cost) {
  const double slope = system->gradient().dot(dx);
  const double bend = trial_cost - old_cost - slope;
  if (!(slope < 0.0 && bend > 0.0)) return std::nullopt;
  const double t = std::clamp(-slope / (2.0 * bend), 0.05, 0.9);
  Eigen::VectorXd short_dx = t * dx;
  system->Update(short_dx, free_variables);
  const double predicted = system->ModelDecrease(short_dx);
  if (system->CostWithLastWhitening(graph, short_cost) && predicted > 0.0 &&
      old_cost - *short_cost > 1e-3 * predicted)
    return short_dx;
  RestoreValues(saved, free_variables);
  return std::nullopt;
}

// The tolerance an accepted step met (function, model, then step), if any.
std::optional<Termination> ToleranceMet(const SolverOptions& options, double old_cost, double actual, double predicted,
                                        double step_norm, const std::vector<Variable*>& free_variables) {
  if (std::abs(actual) <= options.function_tolerance * old_cost) return Termination::kFunctionTolerance;
  if (std::abs(actual - predicted) <= options.model_tolerance * old_cost) return Termination::kModelTolerance;
  if (step_norm <= options.step_tolerance * (TangentNorm(free_variables) + options.step_tolerance))
    return Termination::kStepTolerance;
  return std::nullopt;
}

// An interruption ends a solve where it is noticed: before the first linearization, within a linearization (which
// then fails: NormalEquations looks every 4096 factors), at the top of an iteration and after its factorization. On a
// slow or loaded machine one iteration over a whole drive takes seconds. The values are those of an unfinished solve.
// Returns whether one arrived, then with the summary marked failed at `iteration`.
bool StopOnInterrupt(int iteration, SolverSummary* summary) {
  if (!InterruptRequested()) return false;
  summary->termination = Termination::kFailure;
  summary->message = InterruptedError().message() + " at iteration " + std::to_string(iteration);
  return true;
}

// Levenberg-Marquardt's damping after an accepted step: raised as after a rejection when the step was shortened (the
// model overestimated the decrease), otherwise scaled by the gain ratio actual / predicted (Nielsen's rule).
void AdaptDampingAfterStep(bool shortened, double actual, double predicted, double* lambda, double* nu) {
  if (shortened) {
    *lambda *= *nu;
    *nu *= 2.0;
    return;
  }
  const double rho = actual / predicted;
  *lambda *= std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * rho - 1.0, 3));
  *nu = 2.0;
}

}  // namespace

SolverWorkspace::SolverWorkspace() : system_(std::make_unique<internal::NormalEquations>()) {}
SolverWorkspace::~SolverWorkspace() = default;
int SolverWorkspace::analyses() const { return system_->analyses(); }
long SolverWorkspace::evaluations() const { return system_->evaluations(); }
long SolverWorkspace::carries() const { return system_->carries(); }
const internal::WhitenedFactor* SolverWorkspace::Linearization(FactorId id, std::uint64_t want_mask) const {
  return system_->LinearizationAt(id, want_mask);
}

const std::vector<double>* SolverWorkspace::Products(FactorId id, std::uint64_t want_mask) const {
  return system_->KeptProductsAt(id, want_mask);
}

SolverSummary Solve(const SolverOptions& options, Graph* graph, CovarianceRequest* covariance,
                    SolverWorkspace* workspace) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
  SolverSummary summary;
  const std::string invalid = options.Validate();
  if (!invalid.empty()) {
    summary.message = "invalid solver options: " + invalid;
    return summary;
  }
  const auto interrupted = [&summary](int iteration) { return StopOnInterrupt(iteration, &summary); };
  if (interrupted(0)) return summary;

  SolverWorkspace local;
  local.set_keep_linearizations(false);  // (nobody can read them)
  SolverWorkspace& ws = workspace != nullptr ? *workspace : local;
  internal::NormalEquations& system = *ws.system_;
  system.set_relinearize_threshold(options.relinearize_threshold);
  system.set_keep_linearizations(ws.keep_linearizations_);
  system.Reset(*graph, FreeVariableOrder(*graph));
  const std::vector<VariableId>& order = system.order();
  summary.free_dimension = system.dimension();
  summary.factors = static_cast<int>(system.factor_ids().size());
  std::string failed_stream;
  if (!system.Linearize(*graph, &failed_stream)) {
    if (interrupted(0)) return summary;
    summary.message = "a factor from stream '" + failed_stream + "' could not be evaluated at the initial values";
    return summary;
  }
  summary.initial_cost = summary.final_cost = system.cost();
  summary.cost_history.push_back(system.cost());
  if (order.empty()) {
    summary.termination = Termination::kNoFreeVariables;
    summary.seconds = elapsed();
    return summary;
  }

  // The free variables in the system's order, looked up once (a whole recording's graph holds hundreds of thousands).
  std::vector<Variable*>& free_variables = ws.free_variables_;
  free_variables.clear();
  for (VariableId id : order) free_variables.push_back(&graph->mutable_variable(id));

  const bool lm = options.method == SolverOptions::Method::kLevenbergMarquardt;
  double lambda = lm ? options.initial_lambda : 0.0;
  double nu = 2.0;
  DampingScope damping(options.damping);
  summary.termination = Termination::kMaxIterations;
  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    if (interrupted(iteration)) break;
    if (elapsed() > options.time_budget_s) {
      summary.termination = Termination::kTimeBudget;
      break;
    }
    // Solve the damped system; raise the damping if the matrix is not positive definite.
    Eigen::VectorXd dx;
    if (!SolveWithDamping(&system, &lambda, &damping, &dx)) {
      summary.termination = Termination::kFailure;
      summary.message = "normal equations are not positive definite even with damping";
      break;
    }
    ++summary.iterations;
    if (interrupted(iteration)) break;

    // Try the step, keeping a copy of the free variables' values.
    SaveValues(free_variables, &ws.saved_);
    system.Update(dx, free_variables);
    // Gauss-Newton takes every step it can evaluate: its trial point is linearized at once (the next iteration, or
    // the next solve of a workspace, starts there), Levenberg-Marquardt only evaluates the cost of a trial that may
    // be rejected.
    double new_cost = 0.0;
    const bool evaluated = lm ? system.CostWithLastWhitening(*graph, &new_cost) : system.LinearizeForCost(&new_cost);
    const double old_cost = system.cost();
    double predicted = system.ModelDecrease(dx);
    double actual = old_cost - new_cost;
    bool accept = evaluated && (lm ? (predicted > 0.0 && actual / predicted > 1e-3) : true);

    if (!accept) RestoreValues(ws.saved_, free_variables);
    // A rejected step is shortened along its direction (ShortenedStep) when that lowers the cost; the damping still
    // rises as after a rejection, since the model overestimated the decrease (kept or lowered instead, a solve with
    // gross outliers still in can walk weak parameters far off in the steps the model misjudges).
    bool shortened = false;
    if (lm && evaluated && !accept) {
      double short_cost = 0.0;
      if (auto short_dx = ShortenedStep(&system, *graph, dx, old_cost, new_cost, ws.saved_, free_variables,
                                        &short_cost)) {
        dx = std::move(*short_dx);
        new_cost = short_cost;
        predicted = system.ModelDecrease(dx);
        actual = old_cost - new_cost;
        accept = shortened = true;
      }
    }

    if (!accept) {
      if (interrupted(iteration)) break;
      if (!lm) {
        summary.termination = Termination::kFailure;
        summary.message = "Gauss-Newton step could not be evaluated";
        break;
      }
      // Both the model's and the actual change of the cost within the function tolerance: the point is a minimum to
      // that tolerance and the rejection is round-off (a fit that starts at, or has reached, its minimum, where the
      // damping would otherwise climb to its limit on changes of 1e-14 of the cost and report a failure).
      const double tolerance = options.function_tolerance * old_cost;
      if (evaluated && predicted <= tolerance && std::abs(actual) <= tolerance) {
        summary.termination = Termination::kFunctionTolerance;
        break;
      }
      lambda *= nu;
      nu *= 2.0;
      damping.AfterStep(/*full_step_accepted=*/false);
      if (lambda > 1e16) {
        summary.termination = Termination::kFailure;
        summary.message = "Levenberg-Marquardt damping exceeded 1e16 without a successful step";
        break;
      }
      continue;
    }
    if (lm) AdaptDampingAfterStep(shortened, actual, predicted, &lambda, &nu);
    damping.AfterStep(/*full_step_accepted=*/!shortened);

    // Stop here when converged or out of iterations or time; otherwise relinearize at the new point (which also
    // re-evaluates every error covariance, eq. 1).
    summary.cost_history.push_back(new_cost);
    summary.final_cost = new_cost;
    if (const auto met = ToleranceMet(options, old_cost, actual, predicted, dx.norm(), free_variables)) {
      summary.termination = *met;
      break;
    }
    if (iteration + 1 == options.max_iterations) break;
    if (elapsed() > options.time_budget_s) {
      summary.termination = Termination::kTimeBudget;
      break;
    }
    if (!system.Linearize(*graph, &failed_stream)) {
      if (interrupted(iteration + 1)) break;
      summary.termination = Termination::kFailure;
      summary.message = "a factor from stream '" + failed_stream + "' could not be evaluated";
      break;
    }
  }
  summary.final_lambda = lambda;
  if (covariance != nullptr && summary.usable())
    covariance->computed = system.Covariance(covariance->variables, &covariance->covariance, covariance->leading_dims);
  summary.seconds = elapsed();
  return summary;
}

}  // namespace roamlab::estimator
