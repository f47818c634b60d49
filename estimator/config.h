// The estimator configuration (EST.yaml): which recording streams feed which error model, their noise, the
// calibration parameters (initial value, fixed or free, constant or time-varying), the master stream that creates
// pose nodes, the solver, outlier gating, the online window and the offline calibration stages.
//
//   master: odometer                       # a stream whose model is ackermann, ackermann_seed, differential_drive,
//                                          # omni3_drive, mecanum_drive, omni4_drive, tricycle_drive or odometer;
//                                          # or a gyroscope stream (IMU master, below)
//   poses: {rate_hz: 20, position_sigma_m: 1.0}   # IMU master only (PosesConfig)
//   solver: {method: levenberg_marquardt, max_iterations: 50, function_tolerance: 1.0e-8, step_tolerance: 1.0e-10}
//   gating: {probability: 0.99999}         # chi-square gate on whitened errors; omit to disable
//   tracking: {window: 40, max_iterations: 10, improvement_threshold: 1.0e-3, time_budget_s: 0.05,
//              initialization_s: 2.0, relinearize_threshold: 0.0}
//   parameters:                            # any parameter not listed here keeps its model default and is fixed
//     gps.lever_arm: {value: [0, 0, 0], free: true}     # optional prior_sigma: [.inf, .inf, 0.5] (ParameterConfig)
//     odometer.k_theta: {value: 1.0, free: true, target_std: 0.00167}   # `roamlab design`'s target (ParameterConfig)
//     imu.gyro_bias: {value: [0, 0, 0], free: true, process: {type: random_walk, sigma: 1.0e-4}}
//     odometer.disturbance: {value: [0, 0, 0], free: true,   # per component: a list of three (Gauss-Markov:
//                            process: {type: gauss_markov, sigma: [0.01, 0.002, 0.03], tau_s: [0.5, 1.2, 1.8]}}
//                                          # a stationary prior N(0, sigma^2) on the first instance)
//                            # optional in process: interval_s: 0.1, one instance per 0.1 s shared by its poses
//                            # instead of one per pose (positive; for processes much slower than the master rate)
//   streams:
//     odometer:
//       model: ackermann
//       source: {speed: rear_wheel, steering: steering}
//       noise: {speed_mps: 0.033, steering_rad: 0.014, lateral_mps: 0.05, vertical_mps: 0.05,
//               roll_rate_radps: 0.3, pitch_rate_radps: 0.3}
//       parameters: {kv_over_L: odometer.kv_over_L}    # slot -> parameter name; default "<stream>.<slot>"
//       options: {wheelbase_m: 1.25}
//       loss: {type: huber, scale: 3.0}
//       gate: false                        # the gate leaves this stream's rows alone (default true)
//     gps: {model: gps, source: gps, noise: {sigma_m: 0.33}}
//     scan_matching:                       # a velocity measured over an interval (scan matcher, visual odometry)
//       model: relative_motion             # eqs. 5-8 between the poses nearest the interval's ends (problem.h)
//       source: scan_matching
//       noise: {linear_mps: 0.03, angular_radps: 0.05}     # of the interval's mean velocity
//       options: {interval_s: 0.1, row_covariance_scale: 2.0}
//   stages:                                # offline calibration: parameters freed in each stage, in order
//     - [gps.lever_arm, imu.misalignment]
//     - [magnetometer.A, magnetometer.b, odometer.kv_over_L, odometer.k_theta, odometer.k_gamma]
//
// Models, their noise keys, parameter slots (default value) and options are listed in the error-model registry
// (model_registry.h; the built-in models in model_registry.cc), which a program extends with its own models.
// `odometer` joins the two master poses around its sample's stamp (one master interval: for sources at the master's
// rate or faster). `relative_motion` reads the same velocity streams, whose rows hold the mean velocity over
// [t - T/2, t + T/2] stamped at the middle (scan_matching, visual_odometry), and joins the master poses nearest the
// two ends, so that a 10 Hz scan matcher constrains the whole 0.1 s displacement instead of one 10 ms interval;
// options.interval_s gives T (default: 1 / the stream's rate_hz). Both accept options.row_covariance_scale: k > 0
// adds k times the row's own covariance (the stream's 21 covariance columns) to the configured noise, per sample.
// Unknown keys, unknown models, missing noise keys and malformed values are errors naming the file and key.
#pragma once

#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "estimator/loss.h"
#include "estimator/manifold.h"
#include "estimator/solver.h"

namespace roamlab::estimator {

struct ProcessConfig {
  enum class Type { kConstant, kRandomWalk, kGaussMarkov };
  Type type = Type::kConstant;
  // Per component of the (3-vector) parameter; EST.yaml gives one number for all three or a list of three.
  Eigen::Vector3d sigma = Eigen::Vector3d::Zero();  // random walk: units/sqrt(s); Gauss-Markov: stationary std in
                                                    // the parameter's units
  Eigen::Vector3d tau_s = Eigen::Vector3d::Zero();  // Gauss-Markov correlation time [s]
  // Spacing of the instances [s]; 0: one per pose. With a spacing, the poses within interval_s of an instance's first
  // pose share it (problem.h), and the process joins consecutive instances over their actual time difference.
  double interval_s = 0.0;
};

struct ParameterConfig {
  std::optional<Eigen::VectorXd> value;  // ambient; default from the model slot
  bool free = false;
  ProcessConfig process;
  // A Gaussian prior about the initial value on a constant parameter, one std per tangent component (.inf: none on
  // that component): for a component the measurements leave unobservable, e.g. the GPS antenna's height above an IMU
  // master's poses on a planar drive.
  std::optional<Eigen::VectorXd> prior_sigma;
  // The std `roamlab design` aims at for every tangent component of this free parameter, in its units (the command
  // line's --target overrides it).
  std::optional<double> target_std;
};

struct StreamConfig {
  std::string model;
  std::map<std::string, std::string> sources;  // role -> recording stream ("" role for single-source models)
  std::map<std::string, double> noise;
  std::map<std::string, std::string> parameters;  // slot -> parameter name
  std::map<std::string, std::vector<double>> options;
  std::map<std::string, std::string> inputs;  // role -> recording stream read as an extra input (optional)
  Loss loss;
  // `gate: false`: the outlier gate neither tests nor holds out this stream's rows; its loss alone handles its
  // outliers (a slipping wheel's rows under Cauchy's loss, whose heavy tail a Gaussian gate would reject wholesale).
  bool gated = true;
};

struct TrackingConfig {
  int window = 40;          // poses kept in the fixed-lag window
  int max_iterations = 10;  // per update
  // Stop iterating when the cost drops by less than this fraction, or when the drop matches the Gauss-Newton
  // model's prediction to within this fraction (SolverOptions::model_tolerance).
  double improvement_threshold = 1e-3;
  double time_budget_s = 0.05;  // per update
  // Relinearization threshold of the updates (SolverOptions::relinearize_threshold, iSAM2's): a factor whose
  // variables all moved by at most this much in every tangent component [m, rad, parameter units] since it was last
  // linearized keeps its Jacobians, its error carried to first order. 0: every factor is relinearized at every step.
  double relinearize_threshold = 0.0;
  double initialization_s = 2.0;  // data buffered before the first window is solved
  // With a calibration that carries its information matrix (TrackingOptions::calibration_prior), the calibrated
  // constant parameters stay free in the window under that Gaussian prior instead of being fixed at their values.
  bool calibration_prior = false;
  // Offline calibration configuration (absolute path; written relative to this file) that `roamlab montecarlo`
  // runs once, on the scenario simulated with its own seed, when it is given no calibration. "" = none.
  std::string calibrate;
};

// Pose nodes of an IMU master (a gyroscope stream as master; problem.h): the IMU drives the graph instead of an
// odometric model. The poses sit on a regular grid from the IMU's first sample, rate_hz apart (0: at every IMU
// sample); consecutive poses are joined by the gyroscope samples between them and every three by the accelerometer.
// Without an absolute sensor (gps, absolute_pose) every pose's position gets a weak prior N(0, position_sigma_m^2)
// about the start: the device stays near where it started (handheld), which holds the position and velocity that
// the accelerometer alone leaves free.
struct PosesConfig {
  double rate_hz = 0.0;
  double position_sigma_m = 1.0;
};

struct EstimatorConfig {
  std::string source_file;  // for messages
  std::string master;
  PosesConfig poses;  // IMU master only
  SolverOptions solver;
  std::optional<double> gate_probability;
  // Calibration with the gate on: each stage's solves take Huber's loss (gating.robust_start) until the gate has
  // settled, then least squares on the measurements it kept (calibration.h, Calibrate). On by default: least squares
  // with gross outliers in bends the first solve, and the gate's decisions taken there reject good rows with them.
  bool gate_robust_start = true;
  TrackingConfig tracking;
  std::map<std::string, ParameterConfig> parameters;
  std::map<std::string, StreamConfig> streams;  // by stream name (ordered: deterministic)
  std::vector<std::vector<std::string>> stages;
};

// What a model expects: its recording source roles, noise keys, parameter slots.
struct SlotSpec {
  std::string name;
  Manifold manifold;
  Eigen::VectorXd default_value;
};
struct ModelSpec {
  std::string name;
  std::vector<std::string> source_roles;  // {""} for one source
  std::vector<std::string> noise_keys;
  std::vector<SlotSpec> slots;
  std::vector<std::string> option_keys;
  bool odometric = false;                // can be the master stream
  std::vector<std::string> input_roles;  // optional extra inputs (StreamConfig::inputs)
};
// The spec of a registered model (model_registry.h); nullptr for an unknown name.
const ModelSpec* FindModelSpec(const std::string& model);

// The recording streams a configuration reads: its streams' sources and inputs.
std::set<std::string> StreamsRead(const EstimatorConfig& config);

Result<EstimatorConfig> LoadEstimatorConfig(const std::string& path);
Result<EstimatorConfig> ParseEstimatorConfig(const std::string& yaml_text, const std::string& source_name);

}  // namespace roamlab::estimator
