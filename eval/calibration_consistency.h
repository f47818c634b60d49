// Consistency of a calibration's reported uncertainty over N independent realizations of one drive (Bar-Shalom et
// al. 2001, 5.4.2, applied to static parameters): does the std the calibration reports match the spread of its
// errors, and is the calibration as good as the drive allows?
//
// Per parameter block (a parameter's tangent components: the GPS lever arm's 3, the magnetometer's A's 9), run j
// gives the error e_j = estimate - truth in the tangent space (eval/parameters.h), the reported std s_j and the
// reported block covariance C_j. Per component i, over the N runs:
//   bias        = mean_j e_ji, its standard error spread / sqrt(N); `biased` when |bias| > kBiasStandardErrors of it
//   spread      = sample standard deviation of e_ji (N - 1 in the denominator)
//   mean_std    = mean_j s_ji; spread_over_std = spread / mean_std (1 when the std is right; above 1: over-confident)
//   coverage(k) = share of runs with |e_ji| <= k s_ji, k = 1, 2, 3 (68.27, 95.45, 99.73 % for a Gaussian error with
//                 the right std), with its 95 % Wilson score interval for a binomial share of N
//   efficiency  = mean_std / the Cramer-Rao std (the std the calibration reports on the noise-free drive at the
//                 truth): 1 when the calibration reaches the bound
// Per block: NEES_j = e_j^T C_j^-1 e_j; for a consistent estimator sum_j NEES_j ~ chi-square(N d), so the mean lies
// in AverageNeesBand(N, d, alpha) (common/chi_square.h) with probability 1 - alpha; above it the reported covariance
// is too small, below it too large.
#pragma once

#include <array>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "common/chi_square.h"

namespace roamlab::eval {

// A bias larger than this many standard errors of the mean is reported as a bias (0.27 % false alarms per component).
inline constexpr double kBiasStandardErrors = 3.0;

// One run's calibrated parameter block against its true value.
struct ParameterDraw {
  Eigen::VectorXd error;       // estimate - truth, tangent (d components)
  Eigen::VectorXd std;         // reported standard deviations (d); NaN where unknown
  Eigen::MatrixXd covariance;  // reported d x d covariance; NaN entries where unknown
};

// The share of runs whose error lies within k reported standard deviations.
struct Coverage {
  int sigmas = 1;            // k
  double nominal = 0.0;      // P(|x| <= k) for a standard normal x
  double fraction = 0.0;     // observed share (NaN without runs with a finite std)
  Interval confidence{0, 0};  // 95 % Wilson score interval of the share
  bool consistent() const { return nominal >= confidence.lo && nominal <= confidence.hi; }
};

struct ComponentConsistency {
  double bias = 0.0;                 // mean error
  double bias_standard_error = 0.0;  // spread / sqrt(N)
  bool biased = false;               // |bias| > kBiasStandardErrors * bias_standard_error
  double spread = 0.0;               // sample standard deviation of the errors (NaN for N < 2)
  double mean_std = 0.0;             // mean reported std (over the runs where it is finite)
  double spread_over_std = 0.0;
  std::array<Coverage, 3> coverage;  // k = 1, 2, 3
  double cramer_rao_std = 0.0;       // NaN when not given
  double efficiency = 0.0;           // mean_std / cramer_rao_std
  // Set by the caller when known: the error of the calibration without noise, what a bias shared by every run comes
  // from (physics the model misses); NaN when not given.
  double noise_free_error = std::numeric_limits<double>::quiet_NaN();
};

struct BlockConsistency {
  std::string name;
  int runs = 0;       // N
  int dimension = 0;  // d
  std::vector<ComponentConsistency> components;
  std::vector<double> nees;  // per run; NaN where the covariance is not positive definite
  int nees_runs = 0;         // runs with a finite NEES
  double mean_nees = 0.0;    // over those runs
  Interval band{0, 0};       // AverageNeesBand(nees_runs, d, alpha)
  double alpha = 0.05;
  bool nees_in_band() const { return mean_nees >= band.lo && mean_nees <= band.hi; }
};

// The 95 % Wilson score interval of a binomial share `successes` / `trials` (trials >= 1).
Interval WilsonInterval(int successes, int trials);

// The statistics above for one block. `cramer_rao_std`: d values, or empty (efficiency NaN). Preconditions (CHECK):
// at least one draw, every draw of one size d >= 1 (error, std, d x d covariance), 0 < alpha < 1.
BlockConsistency BlockStatistics(const std::string& name, const std::vector<ParameterDraw>& draws,
                                 const Eigen::VectorXd& cramer_rao_std = {}, double alpha = 0.05);

// [{"name", "runs", "dimension", "nees": {"mean", "band": [lo, hi], "alpha", "in_band", "runs", "per_run": [...]},
//   "components": [{"index", "bias", "bias_standard_error", "biased", "spread", "mean_std", "spread_over_std",
//                   "coverage": [{"sigmas", "nominal", "fraction", "confidence": [lo, hi], "consistent"}, x3],
//                   "cramer_rao_std", "efficiency", "noise_free_error"}]}]; NaN as null.
nlohmann::json ConsistencyJson(const std::vector<BlockConsistency>& blocks);

// The printed table: one row per component (bias +- standard error, spread, mean std, ratio, coverage at 1/2/3
// sigma, Cramer-Rao std, efficiency, noise-free error), then one row per block (mean NEES and its band).
std::string ConsistencyTable(const std::vector<BlockConsistency>& blocks);

}  // namespace roamlab::eval
