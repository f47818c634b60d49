// The Cramer-Rao bound of a drive's calibration and where its information comes from (docs/methods-information.md).
//
// An analysis of the design, not an estimate: it is given the true poses and parameter values (it may read the truth;
// the estimator never does) and linearizes every factor the configuration builds from the recording there, with the
// configured noise and no robust loss:
//
//   J = [J_x J_p]   the whitened Jacobians (rows: every factor's error, L^-1 e with L L^T the error covariance of
//                   eq. 1; columns: x = poses and time-varying parameter instances, p = the free constant parameters)
//   H = J^T J       the Fisher information of (x, p)
//   I = H_pp - H_px H_xx^-1 H_xp        the parameters' marginal information, poses marginalized (Schur complement)
//   CRB std_i = sqrt((I^+)_ii)           I^+ the pseudo-inverse on I's observable subspace
//
// Origin. With Y = H_xx^-1 H_xp (the best poses move by -Y per unit change of the parameters), the rows
//   R_f = J_p,f - J_x,f Y = (P J_p)_f     (factor f's sensitivity to the parameters once the poses follow them; P the
//                                         projector orthogonal to the columns of J_x)
// split I exactly in two ways, I = sum_f R_f^T R_f = sum_f J_p,f^T R_f. For component i with w_i = I^+ e_i (the
// direction of its estimate: p_i's estimate moves by w_i^T sum_f R_f^T n_f for whitened noise n), two shares, each
// summing to 1 over the factors and additive over any grouping of them:
//   variance share  |R_f w_i|^2 / (I^+)_ii                 the part of the CRB variance that factor f's noise causes:
//                                                          never negative; split by stream and by time window of the
//                                                          factor's stamp (by_stream, by_window, by_stream_window).
//                                                          A stream that only holds the poses gets a share through
//                                                          them (its noise moves the poses that the parameter's
//                                                          measurements are compared with).
//   measured share  (J_p,f w_i)^T (R_f w_i) / (I^+)_ii     the part of the information that factor f's own
//                                                          sensitivity brings, less what of it the poses absorb: only
//                                                          the streams that measure the parameter (or one correlated
//                                                          with it) get one (measured_by,
//                                                          measured_by_stream_window); a single term is negative
//                                                          where the rest of the drive moves the poses more than the
//                                                          row calls for, so that two streams measuring one parameter
//                                                          with poses between them can show +480 % and -380 %.
//
// Directions. N = C^-1/2 I C^-1/2 with C = diag(H_pp) (each component's information were every other variable known)
// is eigen-decomposed; an eigenvalue lambda is the information along its direction relative to what the components
// would have alone (1 / lambda: the variance inflation of that combination). Directions with lambda below
// 1 / unobservable_inflation are unobservable, below 1 / weak_inflation weak (ObservabilityOptions' thresholds), each
// named by its components whose squared loading is at least kDirectionLoading.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "estimator/config.h"
#include "estimator/covariance.h"
#include "recording/recording.h"
#include "recording/trajectory.h"

namespace roamlab::estimator {

// A component loads on a direction when its squared loading is at least this.
inline constexpr double kDirectionLoading = 0.1;

struct InformationOptions {
  double window_s = 1.0;  // time windows of the origin split [s], > 0
  ObservabilityOptions observability;
  // Empty when valid, otherwise what is wrong.
  std::string Validate() const;
};

// One tangent component of a free parameter.
struct InformationComponent {
  std::string parameter;  // e.g. "gps.lever_arm"
  std::string label;      // e.g. "gps.lever_arm[x]", "magnetometer.A[0,1]", "imu.misalignment[rz]"
  double crb_std = 0.0;   // NaN when unobservable
  Observability observability = Observability::kObservable;
  // Variance shares (the header comment), NaN when unobservable: by stream (summing to 1 over the streams), by window
  // and by stream and window (window k covers [t0 + k window_s, t0 + (k + 1) window_s), t0 the first pose's time;
  // factors stamped before t0, such as a parameter's prior, count in window 0).
  std::map<std::string, double> by_stream;
  std::vector<double> by_window;
  std::map<std::string, std::vector<double>> by_stream_window;
  // Measured shares (the header comment) by stream, summing to 1, and by stream and window; NaN when unobservable.
  std::map<std::string, double> measured_by;
  std::map<std::string, std::vector<double>> measured_by_stream_window;
};

struct InformationDirection {
  double eigenvalue = 0.0;  // of N (header comment)
  Observability observability = Observability::kObservable;
  Eigen::VectorXd direction;  // unit eigenvector, in the components' order (normalized coordinates)
  std::string name;           // its loadings, e.g. "0.71 magnetometer.A[2,2] - 0.70 magnetometer.b[z]"
};

struct InformationParameter {
  std::string name;
  Manifold manifold = Manifold::Euclidean(0);
  Eigen::VectorXd truth;  // ambient, the value linearized at
  bool has_truth = true;  // false: not in the given truth; linearized at the configured value
  int first_component = 0;  // index into InformationResult::components
};

struct InformationResult {
  std::vector<InformationParameter> parameters;  // the free constant parameters, in the builder's order
  std::vector<InformationComponent> components;  // their tangent components, stacked
  std::vector<std::string> streams;              // the streams factors came from ("prior" and "process" included)
  Time t0;                                       // start of window 0
  double window_s = 1.0;
  int windows = 0;
  Eigen::MatrixXd information;  // I, components x components
  Eigen::MatrixXd covariance;   // I^+ (observable subspace)
  Eigen::VectorXd conditional;  // diag(H_pp)
  std::vector<InformationDirection> directions;  // weak and unobservable ones, the weakest first
  int poses = 0;
  int factors = 0;
};

// The analysis of the header comment for `recording` (simulated without noise: the errors at the truth are then what
// the configuration's models leave out) under `config`. `truth`: true values by parameter name (ambient, as
// truth.yaml), for every parameter present; a parameter not in it keeps its configured value (has_truth false).
// Time-varying parameters' instances are marginalized with the poses. `true_trajectory`: the pose of O, interpolated
// at the poses' stamps (clamped at its ends). Errors: a configuration that does not fit the recording, a truth value
// of the wrong size, an empty trajectory, no free constant parameter, a factor that cannot be evaluated at the truth.
Result<InformationResult> AnalyzeInformation(const EstimatorConfig& config, const recording::Recording& recording,
                                             const std::map<std::string, std::vector<double>>& truth,
                                             const Trajectory& true_trajectory, const InformationOptions& options = {});

}  // namespace roamlab::estimator
