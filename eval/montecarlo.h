// Monte-Carlo consistency of an estimator (seed 000, Section V, Fig. 4): the position NEES (eq. 16) of each run's
// poses against the truth, and the average over runs on the time stamps they share.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "common/time.h"
#include "eval/nees.h"
#include "recording/trajectory.h"

namespace roamlab::eval {

// One run's NEES at the poses that have a ground-truth pose at the same time stamp.
struct RunNees {
  std::vector<Time> t;
  std::vector<double> nees;  // NaN where the covariance is not positive definite
  double ate_m = 0.0;        // root mean square position error over those poses [m]
  double mean_nees = 0.0;
};

// Pairs `estimate` (with its world-frame position covariances [m^2], one per pose) with the truth pose of the same
// time stamp; both in increasing time. The result's t is empty when no pose has such a truth pose.
RunNees MatchedNees(const Trajectory& estimate, const std::vector<Eigen::Matrix3d>& position_covariance,
                    const Trajectory& truth);

// Averages the runs' NEES (AggregateNees, dof 3) on the stamps every run has (they share the master stream's rate);
// a NaN NEES counts as +Inf (a diverged run). At least one run; an error when the runs share no time stamp.
Result<MonteCarloNees> AggregateRunNees(const std::vector<RunNees>& runs, double t0_s);

}  // namespace roamlab::eval
