// Online fixed-lag tracking (seed 000, Section III-B): measurements are replayed in time order; each master sample adds
// a pose, the window is re-optimized by Gauss-Newton until the improvement drops under a threshold, an iteration cap
// or a time budget, gross outliers are gated, and poses beyond the window length are marginalized into a linear prior
// on their Markov blanket (marginalization.h). Calibration parameters are fixed at their calibrated values;
// time-varying ones declared free (for example a random-walk gyro bias) are tracked with the poses; an instance shared
// by several poses (process.interval_s) leaves the window with the last of them.
//
// Output: each pose's estimate and position covariance at the moment it leaves the window (a fixed-lag smoother with a
// lag of `window` master samples); poses still in the window at the end are reported from the final window.
// The first `initialization_s` seconds are buffered and solved in one batch (after aligning the dead-reckoned track to
// the absolute fixes) to obtain a starting estimate.
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "estimator/config.h"
#include "estimator/problem.h"
#include "recording/recording.h"
#include "recording/trajectory.h"

namespace roamlab::estimator {

struct TrackingResult {
  Trajectory trajectory;
  std::vector<Eigen::Matrix3d> position_covariance;  // world frame [m^2], one per pose
  int updates = 0;
  double mean_update_s = 0.0;
  double max_update_s = 0.0;
  double p99_update_s = 0.0;     // 99th percentile of the update times
  double mean_iterations = 0.0;  // Gauss-Newton iterations per update
  // Factor linearizations of the updates: evaluated with Jacobians, and carried to first order under
  // tracking.relinearize_threshold.
  long factor_evaluations = 0;
  long factor_carries = 0;
  double total_seconds = 0.0;
  std::map<std::string, StreamCounts> counts;
};

// What an offline calibration knows about its parameters: their joint marginal information (CalibrationResult::
// information), tangent coordinates stacked in the order of `names`.
struct CalibrationPrior {
  std::vector<std::string> names;
  Eigen::MatrixXd information;
};

struct TrackingOptions {
  std::function<void(double fraction_done)> progress;  // optional
  // When set and the configuration asks for it (tracking.calibration_prior), the parameters it names start at the
  // values of `calibration` and stay free under this prior: the window then carries the calibration's uncertainty
  // into the poses' covariance, and marginalization keeps what each update learns about the parameters.
  std::optional<CalibrationPrior> calibration_prior;
  // Optional: receives each pose and its world-frame position covariance [m^2] as it leaves the window. When set,
  // TrackingResult::trajectory and position_covariance stay empty (a long online run then keeps bounded memory).
  std::function<void(const StampedPose& pose, const Eigen::Matrix3d& position_covariance)> on_pose;
};

// `calibration` overrides parameter values (ambient, by name) and fixes them.
Result<TrackingResult> Track(const EstimatorConfig& config, const recording::Recording& recording,
                             const std::map<std::string, Eigen::VectorXd>& calibration,
                             const TrackingOptions& options = {});

}  // namespace roamlab::estimator
