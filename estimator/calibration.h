// Offline self-calibration (seed 000, Sections III-B and V): the whole recording in one graph, the chosen parameters
// free, optionally in stages (each stage frees its list and holds the other parameters at their current values, as
// in the seed's two-set procedure), followed by chi-square gating of gross outliers and the observability analysis of
// every parameter that was free in some stage, on the joint Hessian at the final estimate.
//
// Standard deviations. Two are computed: the white one (the inverse of the marginal information, right when the
// residuals are the configured white noise) and the HAC one (ComputeHacCovariance, covariance.h: a Newey-West sandwich
// over each stream's residuals in time order, right when they are autocorrelated or their spread is not the
// configured one). `std` is the chosen one (CalibrationOptions::std_method): by default the HAC one for imported
// (real) recordings, whose residuals are autocorrelated (vibration, slow biases, multipath) so that the white one
// understates the spread many times, and the white one for simulated recordings, whose noise is the configured white
// noise unless the scenario colours it. The HAC `std` is never below the white one: the HAC sees only the residuals,
// and residuals smaller than the configured noise are often errors the poses absorbed (an IMU-driven track follows the
// GPS fixes' slow errors), not a sensor better than stated. Both are kept as computed.
#pragma once

#include <functional>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "estimator/config.h"
#include "estimator/covariance.h"
#include "estimator/problem.h"
#include "estimator/solver.h"
#include "recording/recording.h"

namespace roamlab::estimator {

struct ParameterEstimate {
  std::string name;
  Manifold manifold = Manifold::Euclidean(0);
  Eigen::VectorXd estimate;   // ambient: quaternions [w, x, y, z], matrices row-major
  Eigen::VectorXd std;        // tangent; NaN where unobservable; white, or (hac) the larger of std_white and std_hac
  Eigen::VectorXd std_white;  // from the marginal information (white residuals)
  Eigen::VectorXd std_hac;    // HAC (Newey-West); NaN where unobservable
  std::vector<Observability> components;                     // per tangent component
  Observability observability = Observability::kObservable;  // the worst component
};

struct Correlation {
  std::string a, b;
  double rho = 0.0;  // the largest |correlation| between any components of a and b, with its sign
};

struct StageSummary {
  std::vector<std::string> free_parameters;
  SolverSummary solver;
  int rejected = 0;    // measurements gated out after this stage
  int readmitted = 0;  // rejected measurements this stage re-admitted on their innovation (ReadmitOnInnovation)
};

// The whitened error of one measurement at the final estimate (L^-1 e, eq. 1's covariance, before any robust loss):
// what the reality-gap diagnosis (gap/) takes apart by stream, component and time.
struct MeasurementResidual {
  std::string stream;        // the configured stream that produced the factor
  Time t;                    // the factor's time stamp
  Eigen::VectorXd whitened;  // residual_dim entries, each ~ N(0, 1) when the model and its noise are right
  bool active = true;        // false: gated out as an outlier
};

// The smoothed trajectory's uncertainty at one pose: its world-frame position covariance [m^2] with the calibrated
// parameters free, white (the marginal covariance) and HAC (the Newey-West sandwich of ComputeHacCovariance, which
// widens it when the residuals are autocorrelated: a wheel-aided track pulled for tens of seconds by slow GPS errors).
// `covariance` is the chosen one, as ParameterEstimate::std: white, or (hac) the HAC one unless its trace is below the
// white one's.
struct PoseCovariance {
  std::size_t pose = 0;  // index in CalibrationResult::trajectory
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d white = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d hac = Eigen::Matrix3d::Zero();
};

struct CalibrationResult {
  std::vector<ParameterEstimate> parameters;
  std::vector<Correlation> correlations;  // pairs of parameters with |rho| >= correlation_threshold
  // Joint marginal information of `parameters` (tangent coordinates, stacked in their order) at the final estimate:
  // what the recording says about them once the poses are eliminated. Zero along unobservable directions.
  Eigen::MatrixXd information;
  std::vector<StageSummary> stages;
  std::map<std::string, StreamCounts> counts;
  Trajectory trajectory;                         // the smoothed trajectory of the final estimate
  std::vector<PoseCovariance> pose_covariances;  // with CalibrationOptions::pose_covariance_every, in pose order
  std::vector<MeasurementResidual> residuals;    // with CalibrationOptions::keep_residuals, in factor id order
  std::string std_method;                        // "white" or "hac": which one ParameterEstimate::std is
  std::map<std::string, int> hac_lags;           // the HAC's truncation lag per stream (factor rows)
  double seconds = 0.0;
  // Totals over the stages.
  int iterations = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  std::string termination;
};

struct CalibrationOptions {
  double correlation_threshold = 0.9;
  ObservabilityOptions observability;
  std::function<void(const std::string&)> progress;  // optional: one line per step
  bool keep_residuals = false;                       // fill CalibrationResult::residuals
  // Initial poses (warm start, e.g. from an earlier calibration of the same recording): each pose node takes the
  // pose of the nearest stamp, and neither the alignment to the absolute fixes nor the IMU misalignment from the
  // motion replaces the configured values. Null: dead reckoning, then both alignments.
  const Trajectory* initial_trajectory = nullptr;
  bool analyze_observability = true;  // false: no marginal covariance (parameters get NaN std)
  // > 0: the position covariance of every pose_covariance_every-th pose of the smoothed trajectory, from the first
  // (CalibrationResult::pose_covariances; two sparse solves per chunk of poses, so thin a long recording out).
  int pose_covariance_every = 0;
  // Which standard deviation is `std`: kAuto is kHac for imported recordings, kWhite for simulated ones.
  enum class StdMethod { kAuto, kWhite, kHac };
  StdMethod std_method = StdMethod::kAuto;
};

Result<CalibrationResult> Calibrate(const EstimatorConfig& config, const recording::Recording& recording,
                                    const CalibrationOptions& options = {});

// Whether `method` resolves to the HAC standard deviation for `recording` (kAuto: when it is imported).
bool UsesHac(CalibrationOptions::StdMethod method, const recording::Recording& recording);

// One line for each stream whose measurements the gate rejected in more than `share` of those attached: the estimate
// then rests on the other streams, and a calibration that rejects most of a stream has often failed (a slipping
// drive's wheel stream under the Gaussian gate; `gate: false` in its configuration leaves it to its loss). Empty when
// none.
std::vector<std::string> HeavilyGatedStreams(const CalibrationResult& result, double share = 0.5);

// Options of one gating pass (GateOutliers) beyond testing each factor alone.
struct GateOptions {
  // > 0: a burst in a stream (at least 3 of its rows failing, at most 10 rows apart, one of them active until now) also
  // rejects the stream's active rows within burst_margin times the burst's length on either side, which the next pass
  // re-admits if they fit. Such a burst (an ATV's wheels skidding for a second) pulls the estimate towards itself, so
  // that its edges pass until the rows next to them are gone (masking): tested alone, each round re-solved without
  // the failing rows shows the next few beyond them. Rejecting good rows for one round costs no such cascade: the
  // rest of the measurements agree with them.
  double burst_margin = 0.0;
  // Reject no factor when no more would be newly rejected than the test's own false alarms among the tested ones are
  // expected to be, (1 - probability) of them, and none of them is a gross outlier (beyond the quantile that all N
  // tested factors pass with the test's probability, 1 - (1 - probability) / N each): such a set is as stable as the
  // test can tell. The factors that fit again are re-admitted all the same (unless they too, with the failing ones,
  // are no more than the false alarms: then nothing switches).
  bool ignore_chance_changes = false;
  // Reject a failing factor only where it fails worst (its squared error over the quantile) among the failing factors
  // that share a pose with it; the others stay active for the next pass, after a re-solve without it. A gross outlier
  // bends the solve's estimate of its poses until the good measurements of the same poses fail too (a steering outlier
  // against the gyroscope, of comparable weight on the yaw rate): rejected together, they would leave those poses
  // with nothing to hold them. Not with burst_margin.
  bool worst_per_pose = false;
  // In a pass that bridges wheel readings, reject nothing else: every other failing measurement waits for the
  // re-solve without the bridged readings. The estimate such readings bent fails the good measurements of many poses
  // (the IMU's rows and their bursts' margins); rejected with the readings, they leave poses that nothing holds, which
  // the re-solve moves so far that they never fit again.
  bool defer_when_bridging = false;
  // Test only the measurement factors with ids below this one (with `first`: a range of them).
  FactorId end = std::numeric_limits<FactorId>::max();
};

// What one gating pass switched.
struct GateSwitches {
  int rejected = 0;    // active factors switched off
  int readmitted = 0;  // inactive factors switched on again
  int ignored = 0;     // newly failing factors left active as chance would explain them
  int bridged = 0;     // readings of cumulative wheel streams left out (ProblemBuilder::BridgeCumulativeRun)
  int switched() const { return rejected + readmitted + bridged; }
};

// Re-tests the gated measurement factors (ProblemBuilder::StreamGated) with `first` <= id < options.end (factor ids
// grow as factors are added, so `first` selects the newest ones): active exactly when the whitened squared error is
// within the chi-square quantile `probability` of its dimension, but for what `options` add. A run of failing intervals
// of a cumulative wheel master stream is first bridged where a bridge over its readings passes
// (ProblemBuilder::BridgeCumulativeRun; the readings left out count as rejected), the poses of the left-out readings
// are set between the bridge's ends, their rejected measurements that fit there re-admitted, and the other failing
// measurements of the bridged poses left as they are until the next pass. Keeps the per-stream rejected counts up to
// date. `last_solve` (optional): the workspace of the solve that left the graph at its current values; a factor it
// linearized at exactly these values is tested on that linearization's error instead of being evaluated again.
GateSwitches GateOutliers(double probability, ProblemBuilder* builder, FactorId first = 0,
                          const SolverWorkspace* last_solve = nullptr, const GateOptions& options = {});

// Re-tests every measurement factor the gate has rejected on its innovation at the current estimate: its whitened
// error r against I + J P J^T, J its whitened Jacobians and P the joint marginal covariance of its free variables from
// one factorization of the active problem (the innovation test of the rows held out after a gap). Tested at an
// estimate solved without it, a good row of a pose whose other rows were rejected with it (or that an outlier bent)
// can fail the gate's own test by far, as nothing holds that pose where the row would put it; its innovation counts
// the pose's uncertainty. Where the active problem is singular (a pose that nothing holds at all), every free pose
// takes a weak prior (100 m, 10 rad) for this covariance alone. A factor whose r^T (I + J P J^T)^-1 r is within the
// chi-square quantile `probability` of its dimension is re-admitted. Left as they are: the bridges over cumulative
// wheel readings and the spans they replace, and the factors in `excluded` (the rows held out after a gap, which have
// their own admission). Keeps the per-stream rejected counts up to date; returns how many factors it re-admitted.
int ReadmitOnInnovation(double probability, ProblemBuilder* builder, const std::set<FactorId>& excluded = {});

}  // namespace roamlab::estimator
