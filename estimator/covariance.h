// Marginal covariances and observability (seed 000, Section III-D).
//
// The marginal information of a set of variables is the Schur complement of the Gauss-Newton Hessian onto them
// (every other free variable marginalized out), at the graph's current estimate. Its inverse is their marginal
// covariance, in tangent coordinates (geometry.h): [dp (m), dtheta (rad)] for poses, dtheta for quaternions.
//
// Observability of calibration parameters. A component's variance inflation factor is its marginal variance times its
// conditional information (the diagonal of the Hessian: what the data would say about it if every other variable,
// poses included, were known). The marginal information is also normalized to unit diagonal and eigen-decomposed.
//  - unobservable: the component loads on a (numerically) null direction, or its variance is inflated more than
//    `unobservable_inflation` times (its standard deviation 100 times what the data alone would give: what is left
//    comes from noise and linearization, as for a GPS lever arm's height on a flat drive). The estimate means
//    nothing and no standard deviation is reported;
//  - weak: inflated more than `weak_inflation` times by its dependence on other variables;
//  - observable otherwise.
// Correlations come from a slightly regularized inverse so that dependent pairs (for example the magnetometer's A
// against the IMU misalignment, eq. 10) show |rho| near 1 even when exactly dependent.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "estimator/graph.h"

namespace roamlab::estimator {

struct MarginalInformation {
  std::vector<VariableId> variables;
  std::vector<int> offsets;     // of each variable in the matrix
  Eigen::MatrixXd information;  // Schur complement, tangent coordinates
  Eigen::VectorXd conditional;  // diagonal of the Hessian for the same components (every other variable known)
};

class SolverWorkspace;

// Requires the listed variables to be free. Fails with a message if the rest of the problem is singular even after a
// tiny regularization. `workspace` (optional): the buffers of the solves that reached the estimate are used again
// instead of new ones (a long recording's run to gigabytes, each page of which would be cleared by the kernel on
// first touch); the result is the same.
Result<MarginalInformation> ComputeMarginalInformation(const Graph& graph, const std::vector<VariableId>& variables,
                                                       SolverWorkspace* workspace = nullptr);

enum class Observability { kObservable, kWeak, kUnobservable };
const char* ObservabilityName(Observability observability);

struct ObservabilityOptions {
  double null_eigenvalue = 1e-9;  // normalized eigenvalues below this are null directions
  double null_loading = 1e-2;     // a component whose squared loading on null directions exceeds this is unobservable
  double weak_inflation = 100.0;  // variance inflation factor above which a component is weak
  double unobservable_inflation = 1.0e4;  // ... and above which it is unobservable
};

struct ObservabilityAnalysis {
  Eigen::MatrixXd covariance;                // pseudo-inverse of the information on its observable subspace
  Eigen::VectorXd std;                       // per component; NaN when unobservable
  Eigen::VectorXd inflation;                 // variance inflation factor per component (inf on a null direction)
  std::vector<Observability> observability;  // per component
  Eigen::MatrixXd correlation;               // from the regularized inverse
};

// `conditional`: the Hessian's diagonal for the same components (MarginalInformation::conditional); pass
// information.diagonal() when the information involves no other variables.
ObservabilityAnalysis AnalyzeObservability(const Eigen::MatrixXd& information, const Eigen::VectorXd& conditional,
                                           const ObservabilityOptions& options = {});

// Heteroscedasticity-and-autocorrelation-consistent (HAC, Newey-West) covariance of the given variables: what their
// spread is when the residuals are not the white noise the information matrix assumes (vibration, slow biases,
// multipath make real residuals autocorrelated, and the white covariance then understates the spread many times).
// With H = J^T W J at the estimate and g_t = J_t^T W r_t the score of factor t (whitened, loss-weighted), the sandwich
//   Cov = H^-1 M H^-1,  M = sum_s sum_{|l| <= L_s} (1 - |l| / (L_s + 1)) sum_t g_t g_{t+l}^T
// sums the lags within each stream s, its active factors in time order (streams independent of each other). Only
// the variables' block is formed: X = H^-1 E (E selects the variables; their block of X is `white_covariance`, the
// white marginal covariance, pseudo-inverse on the observable subspace, so that unobservable directions stay zero),
// the influence u_t = X^T g_t, and Cov = the Bartlett-weighted sum of u_t u_{t+l}^T. L_s is AnalyzeAutocorrelation's
// lag of the stream's active factors' residuals: the Bartlett weights fade the lags near L, and at 3 times the last
// correlated lag they keep most of a first-order Gauss-Markov residual's long-run variance (about 1 - 1 / (L / tau)).
// With white residuals L_s is 0 to 2 and Cov is the white covariance rescaled by the residuals' actual spread.
// The autocorrelation rho(l) of one stream's whitened residual vectors in time order (demeaned, summed over
// components), read over windows of lags [2^j, 2^(j+1)) up to n / 4: the HAC truncation lag L is 3 times the last lag
// of the last window whose mean autocorrelation reaches 2 / sqrt(n) (0 when none does, for fewer than 4 rows or rows
// of mixed dimensions). The last correlated window, not the first lag below the threshold: a residual is often a mix
// of a white part whose differencing makes rho(1) negative (encoder ticks) and a slow part of a small share whose
// correlation lasts (a drifting gyroscope), and the slow part is what dominates a parameter's spread. The integrated
// autocorrelation time 1 + 2 sum_{l=1..L} (1 - l / (L + 1)) rho(l), at least 1, is the factor by which the variance of
// a mean over the stream exceeds the white one, used to inflate variances that assume white residuals (the
// diagnosis's time shifts, gap/diagnose.h).
struct ResidualAutocorrelation {
  int lag = 0;
  double integrated_time = 1.0;
};
ResidualAutocorrelation AnalyzeAutocorrelation(const std::vector<Eigen::VectorXd>& residuals);

// The middle of the sandwich over one stream's rows in time order, column t of `a` (k x n) the score or influence of
// row t: sum_{|l| <= L} (1 - |l| / (L + 1)) sum_t a_t a_{t+l}^T, symmetric, in O(n k^2).
Eigen::MatrixXd BartlettSum(const Eigen::MatrixXd& a, int lag);

// BartlettSum after first-order prewhitening (Andrews and Monahan 1992, with a diagonal AR(1)): each component i of
// the a_t is fitted an AR(1) coefficient rho_i = sum_t a_i,t a_i,t-1 / sum_t a_i,t-1^2, bounded to [-0.97, 0.97],
// D = diag(rho_i); the Bartlett sum is taken of the prewhitened a*_t = a_t - D a_{t-1} (t = 1..n-1) and recoloured:
//   M = n / (n - 1) (I - D)^-1 BartlettSum(a*, L) (I - D)^-1.
// Since sum_t a*_t = (I - D) sum_t a_t up to one end term, M estimates the same long-run sum for any D; what D
// changes is the bias. A Bartlett sum over a strongly autocorrelated series is low for two reasons the prewhitened
// series mostly escapes: the weights' truncation at L (for a first-order Gauss-Markov series of coefficient phi they
// keep 1 + 2 sum_{l=1..L} (1 - l / (L + 1)) phi^l of its long-run (1 + phi) / (1 - phi): 78 % at phi = 0.82, L = 21),
// and the zero sum of scores taken at the fit, which takes more off the longer the series' memory. With white a_t,
// rho_i is near 0 and M is BartlettSum(a, L). The bound keeps the recolouring (at most (1 - 0.97)^-2 = 1111) from
// dividing by an estimate of 1 - rho that is mostly noise. Fewer than 3 columns: BartlettSum(a, L). The twin's fit
// (gap/twin.h) sums its residuals' scores with it; ComputeHacCovariance keeps the plain BartlettSum, its coverage
// being measured with that (docs/results.md).
Eigen::MatrixXd PrewhitenedBartlettSum(const Eigen::MatrixXd& a, int lag);

struct HacCovariance {
  Eigen::MatrixXd covariance;       // tangent coordinates, the variables stacked in order
  std::map<std::string, int> lags;  // per stream: L_s (factor rows)
};

// `white_covariance`: the variables' white marginal covariance (ObservabilityAnalysis::covariance of their
// MarginalInformation). Fails as ComputeMarginalInformation does.
Result<HacCovariance> ComputeHacCovariance(const Graph& graph, const std::vector<VariableId>& variables,
                                           const Eigen::MatrixXd& white_covariance);

}  // namespace roamlab::estimator
