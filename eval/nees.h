// Consistency of a position estimator: the normalized estimation error squared (NEES) of the seed's eq. 16 and its
// Monte-Carlo average against the chi-square band (seed Section V, Fig. 4; Bar-Shalom et al. 2001, 5.4.2).
//
//   eps_j(t) = (O(t) - O_hat_j(t))^T Sigma_j(t)^-1 (O(t) - O_hat_j(t))        (eq. 16, run j, position of O in W)
//   eps_bar(t) = 1/N sum_j eps_j(t)
// For a consistent, approximately linear-Gaussian estimator N eps_bar(t) ~ chi-square(N d) with d = 3, so eps_bar(t)
// lies in AverageNeesBand(N, d) (common/chi_square.h: for N = 50, d = 3 and 95 % that is [2.359, 3.716]) with
// probability 0.95 at each t. Above the band the estimator is optimistic (covariance too small), below it conservative.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "common/chi_square.h"
#include "common/status.h"
#include "common/time.h"

namespace roamlab::eval {

// eq. 16 for one pose: error^T covariance^-1 error, error [m] and covariance [m^2] in the same frame. NaN when the
// covariance is not symmetric positive definite (Cholesky fails).
double PositionNees(const Eigen::Vector3d& error, const Eigen::Matrix3d& covariance);

// One row of an estimate's covariance.csv: the 3x3 world-frame covariance of the position of O [m^2].
struct StampedCovariance {
  Time t;
  Eigen::Matrix3d covariance_world = Eigen::Matrix3d::Zero();
};

// Reads covariance.csv as written by `roamlab track`: header "t,xx,xy,xz,yx,yy,yz,zx,zy,zz", one row per pose, time in
// seconds, matrix row-major. Errors name the file and line: wrong header or field count, a non-number, NaN/Inf,
// non-increasing time, a matrix that is not symmetric (relative 1e-6; it is symmetrized otherwise). Matrices that are
// not positive definite are kept: PositionNees gives NaN for them and callers count them.
Result<std::vector<StampedCovariance>> ReadPositionCovariances(const std::string& path);

// Monte-Carlo consistency over N runs sharing one time grid (the structure of nees.json).
struct MonteCarloNees {
  int runs = 0;                   // N
  int dof = 3;                    // d
  Interval band{0.0, 0.0};        // AverageNeesBand(runs, dof, alpha)
  double alpha = 0.05;            // 1 - confidence of the band
  double t0_s = 0.0;              // steps with t - t.front() < t0_s are left out of fraction_in_band [s]
  std::vector<Time> t;            // common grid
  std::vector<double> mean_nees;  // eps_bar(t), one per grid time
  double fraction_in_band = 0.0;  // of the steps from t0_s on whose mean lies in [band.lo, band.hi]; NaN if none
};

// Averages per-run NEES series on the grid t. Preconditions (CHECK): at least one run, every run has t.size() values,
// none NaN (+Inf is allowed: a diverged run), t strictly increasing, dof >= 1, 0 < alpha < 1, t0_s >= 0.
MonteCarloNees AggregateNees(const std::vector<Time>& t, const std::vector<std::vector<double>>& runs, int dof = 3,
                             double t0_s = 0.0, double alpha = 0.05);

// Fraction of the values with t - t.front() >= t0_s that lie in [band.lo, band.hi] (inclusive); NaN when none
// qualifies. Sizes equal (CHECK).
double FractionInBand(const std::vector<Time>& t, const std::vector<double>& values, Interval band, double t0_s);

// {"runs": N, "dof": d, "band": [lo, hi], "alpha": a, "t0_s": t0, "t": [s...], "mean_nees": [...],
//  "fraction_in_band": f}; t in seconds; non-finite numbers as null.
nlohmann::json NeesJson(const MonteCarloNees& nees);

}  // namespace roamlab::eval
