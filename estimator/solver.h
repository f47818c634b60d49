// Gauss-Newton and Levenberg-Marquardt on the estimation graph (seed 000, Section III-C): the sparse normal equations
// of the whitened errors are solved by Cholesky (a band of poses with a border of constant parameters, a sliding
// window's or a whole recording's, by its own block factorization in the band's envelope, internal/normal_equations.h;
// anything else, such as poses tied far apart in time, by CHOLMOD supernodal), the free variables are updated
// through box-plus only, and the error covariances (eq. 1) are re-evaluated at every linearization.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include "common/status.h"

#include "estimator/graph.h"

namespace roamlab::estimator {

struct SolverOptions {
  enum class Method { kGaussNewton, kLevenbergMarquardt };
  Method method = Method::kLevenbergMarquardt;
  int max_iterations = 50;
  // Stop when an accepted step lowers the cost by less than this fraction.
  double function_tolerance = 1e-8;
  // Stop when an accepted step's actual decrease matches the decrease predicted by the quadratic model (the one the
  // step minimized) to within this fraction of the cost: the model is then accurate at the new point, and a
  // re-linearized step could gain only about that mismatch. 0 turns it off.
  double model_tolerance = 0.0;
  // Stop when |dx| < step_tolerance * (|x| + step_tolerance), x and dx in tangent coordinates.
  double step_tolerance = 1e-10;
  // Stop before starting an iteration once this much wall time has passed [s].
  double time_budget_s = std::numeric_limits<double>::infinity();
  // Initial Levenberg-Marquardt damping, relative to diag(H).
  double initial_lambda = 1e-4;
  // Which variables Levenberg-Marquardt's damping reaches: every one, or after a step its model predicted only the
  // constant parameters, the poses and other time-stamped states undamped (solver.cc, DampingScope: for a stretch
  // dead-reckoned between absolute fixes, whose long modes the damping of every pose holds back). Not the default:
  // where weak directions leave several minima (an IMU-master calibration with unobservable misalignment components)
  // the longer steps can lead to another one.
  enum class Damping { kAll, kParameters };
  Damping damping = Damping::kAll;
  // Gauss-Newton only: relinearization threshold (iSAM2's; internal::NormalEquations::set_relinearize_threshold). A
  // factor (trivial loss) whose free variables all moved by at most this much in every tangent component since its
  // Jacobians were computed keeps them, and its error is carried to the new values to first order; its part of the
  // cost is then that of the linearized error. 0: every factor is evaluated again at every new point.
  double relinearize_threshold = 0.0;

  // Empty when valid, otherwise what is wrong.
  std::string Validate() const;
};

enum class Termination {
  kFunctionTolerance,
  kModelTolerance,
  kStepTolerance,
  kMaxIterations,
  kTimeBudget,
  kNoFreeVariables,
  kFailure,  // a factor could not be evaluated, or the system could not be solved
};
const char* TerminationName(Termination termination);

struct SolverSummary {
  Termination termination = Termination::kFailure;
  int iterations = 0;         // linearizations that produced a step
  double initial_cost = 0.0;  // 1/2 sum of robustified squared whitened errors
  double final_cost = 0.0;
  // The initial cost, then after each accepted step the cost at the new point, evaluated with the error covariances
  // of the linearization that step came from (they are re-evaluated at the next linearization).
  std::vector<double> cost_history;
  double seconds = 0.0;
  // Levenberg-Marquardt's damping (relative to diag(H)) for the step after the last: a re-solve of the same problem
  // changed a little (a few measurements gated) can start from it instead of SolverOptions::initial_lambda.
  double final_lambda = 0.0;
  int free_dimension = 0;
  int factors = 0;
  std::string message;  // details on failure

  bool usable() const { return termination != Termination::kFailure; }
};

// Marginal covariance of some free variables, computed by Solve from its last linearization (the point its last step
// started from), with the factorization it already has: much cheaper than ComputeMarginalInformation afterwards.
// leading_dims > 0 asks for each variable's first leading_dims tangent components only (a pose's position: 3), at
// that share of the cost.
struct CovarianceRequest {
  std::vector<VariableId> variables;
  int leading_dims = 0;
  Eigen::MatrixXd covariance;  // tangent blocks of `variables` (or their leading parts), in order
  bool computed = false;
};

struct MarginalInformation;  // covariance.h
namespace internal {
class NormalEquations;
struct WhitenedFactor;
}  // namespace internal

// State kept between solves of graphs whose structure repeats (fixed-lag tracking: the window slides by one pose and
// keeps its band): the buffers of the normal equations, CHOLMOD's symbolic analysis, reused while the Hessian's
// sparsity pattern is unchanged, and the factors' last linearizations, reused while their variables keep their
// values. Results are the same as without it.
class SolverWorkspace {
 public:
  SolverWorkspace();
  ~SolverWorkspace();
  // How many solves had to analyse a new sparsity pattern.
  int analyses() const;
  // Factor evaluations with Jacobians, and linearizations carried to first order (relinearize_threshold), so far.
  long evaluations() const;
  long carries() const;
  // The last solve's linearization of factor `id` (still in the graph) when it was computed at the graph's current
  // values with the Jacobians of exactly the variables in want_mask (bit i: variable i), otherwise null. A
  // Gauss-Newton solve ends with every factor linearized at its final point (under relinearize_threshold, possibly
  // carried there to first order from an earlier point, with that point's Jacobians).
  const internal::WhitenedFactor* Linearization(FactorId id, std::uint64_t want_mask) const;
  // Its Jacobians' products J_i^T J_j when the solve kept them (internal::NormalEquations::KeptProductsAt), else null.
  const std::vector<double>* Products(FactorId id, std::uint64_t want_mask) const;
  // Whether the solves keep each factor's last linearization for Linearization and Products (default true). A caller
  // that does not read them (a whole recording's calibration) sets false: a solve without a relinearization threshold
  // then uses each factor's Jacobians as they are computed and keeps only its whitening, instead of writing
  // about 1 KB per factor and iteration to memory that nothing reads again (a long drive has close to a million
  // factors).
  // Results are the same.
  void set_keep_linearizations(bool keep) { keep_linearizations_ = keep; }

 private:
  friend SolverSummary Solve(const SolverOptions&, Graph*, CovarianceRequest*, SolverWorkspace*);
  friend Result<MarginalInformation> ComputeMarginalInformation(const Graph&, const std::vector<VariableId>&,
                                                                SolverWorkspace*);
  bool keep_linearizations_ = true;
  std::unique_ptr<internal::NormalEquations> system_;
  std::vector<double> saved_;
  std::vector<Variable*> free_variables_;
};

// Optimizes the free variables of `graph` in place. Variables are ordered in time, the stamped ones first (poses and
// time-varying parameters' instances; each instance after the last pose it serves, just before the pose that starts
// the next instance of the same parameter, the newest after every pose: a band), then the others in id order;
// in that order a band's envelope is factored as it is, otherwise CHOLMOD picks its own fill-reducing permutation
// on top. When `covariance` is given, fills it (computed = false if the Hessian is not positive definite).
// `workspace` (optional) carries buffers and the symbolic factorization over to the next solve.
SolverSummary Solve(const SolverOptions& options, Graph* graph, CovarianceRequest* covariance = nullptr,
                    SolverWorkspace* workspace = nullptr);

// The free variables of `graph` in the solver's order.
std::vector<VariableId> FreeVariableOrder(const Graph& graph);

}  // namespace roamlab::estimator
