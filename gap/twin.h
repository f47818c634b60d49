// The diagnosis of a recording against its MuJoCo twin: the nominal scenario run so that it follows the recording
// (a TwinRunner: the replay of the recorded drive, or for a recording of the scenario's own drive the plain
// simulation without noise), compared stream by stream with the real recording, and the simulator's own effects
// (sim/scenario.h) fitted by running the twin again with them.
//
//   1. compare: per stream and component the residual real - twin matched by stamp and whitened by the recording's
//      stated noise (gap/internal/twin_residuals.h); RMS per stream and component; for an absolute stream (gps,
//      position, pose) the drift over fixed windows (TwinDrift). A replayed run's fit and held-out comparison compare
//      its absolute streams over windows (a pose stream as its drift is measured) and leave out the encoders that
//      drive the replay (TwinDiagnoseOptions::increment_window_s, ReplayedResidualOptions);
//   2. locate: Locate (gap/locate.h) on the nominal twin's whitened residuals of the whole run, against the stated
//      noise (level 1), with the conditions computed from the real recording's own streams: the poses of a pose
//      stream (motion capture) when there is one, else the wheel encoders' dead reckoning with the nominal geometry
//      (eval/velocity.h), else none;
//   3. fit: each candidate effect the scenario supports (TwinCandidateNames; TwinDiagnoseOptions::candidates) is
//      fitted on the training part (the first train_fraction of the recording) with the effects kept so far applied:
//      Levenberg-Marquardt over its parameters on cost = the sum of squared whitened residuals, the Jacobian by finite
//      differences of perturbed twin runs executed in parallel (central when 2k runs fit in the threads or for
//      diff_drive_geometry, the radius scale, ratio and track as one candidate; else forward), over the parameters the
//      data informs (a parameter whose conditional white std at the neutral values exceeds 5 % of its range is held at
//      its neutral value and listed in TwinEffect::not_informed; internal/twin_fit.h FitCandidate). Time shifts
//      (gps_latency latency_s, imu_time_offset offset_s, pose_time_offset offset_s: the motion capture's pose stamped
//      t is O's pose at t - offset_s, so negative is wheel encoders that read behind it; drive_time_offset offset_s, a
//      replay's drive inputs stamped t were the robot's at t - offset_s, with an IMU and replayed runs only) are whole
//      physics steps in the simulator: a 1-D search on the step grid, coarse to fine, then a parabola through the best
//      step and its neighbours for the value.
//      The parameters' covariance comes from the residuals' Jacobian at the fit (TwinFitRows, TwinCovariance): the
//      white-noise curvature (J^T J)^-1, which assumes independent residuals and understates the spread of
//      autocorrelated ones (real recordings, coloured sensor noise), and the HAC (Newey-West) sandwich around it,
//      which does not (each series' sum widened by its fixed-b factor, FixedBFactor); TwinDiagnoseOptions::std_method
//      chooses the one reported as the std (auto: HAC on an imported recording, white on a simulated one, as the
//      estimator's calibration chooses; estimator/calibration.h UsesHac);
//   4. name: each candidate is scored by its chi-square drop LR on the training part (~ chi2(k) under "no effect"),
//      p = 1 - F_chi2(k)(LR) and Delta BIC = -LR + k ln n (gap/internal/decide.h, Score); in order of Delta BIC the
//      first with p < alpha, Delta BIC < max_delta_bic and a held-out chi-square drop (the twin run over the whole
//      recording, compared on the rest) above min_heldout_improvement is kept (a candidate whose twin fails is dropped
//      with the reason); then the candidates that passed p in the first round (after a kept time shift: every
//      candidate, and later the ones that passed p in that round), other than those that set a simulator effect kept
//      already, are tried again on top of the kept ones, each fitted only when a score test passes alpha
//      (internal/twin_fit.h PredictedDrop: the Gauss-Newton step's predicted drop from its neutral values, one
//      Jacobian), up to max_effects; every round's candidates and decisions are kept (TwinDiagnosis::rounds).
//      Forward selection with refit: a candidate other than a time shift, once fitted on top of the kept effects, is
//      fitted again together with the kept ones that are not time shifts (internal/twin_fit.h FitJointly, from the kept
//      values and its own), and its LR is the drop of that nested model, "kept + candidate, all free" against "kept"
//      (TwinEffect::refitted); when it is kept, the kept effects take their refitted values and the patch with them.
//      Without it an effect whose signature overlaps a kept one's (a drive clock's rate and the wheels' scale on
//      straight runs) would be judged against a kept effect that has already absorbed part of it;
//   5. joint refit: the kept effects' parameters (time shifts held at their values) are fitted again together,
//      Levenberg-Marquardt from the kept values (internal/twin_fit.h FitJointly), and their joint values with the
//      marginal std (white and HAC, from the joint covariance) and the std conditional on the others are reported
//      beside the rounds' (TwinJointFit). After a round's refit it starts at the joint optimum unless a time shift was
//      kept later; it names nothing and leaves the patch and the held-out figures as the rounds kept them;
//   6. show: on the held-out part, the nominal twin's and the patched twin's residual RMS per stream and drift.
// Verdict: "named" (some effect kept), "unknown" (no effect kept, and some component inconsistent with the stated
// noise), "none". `unexplained` lists the components still inconsistent on the held-out part with the patch.
// The runner must be thread-safe (a Simulator of its own per call); it may stop the twin at the patched scenario's
// duration_s after the recording's first stamp (the fit's runs cover the training part only). The diagnosis never reads
// truth.yaml.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "common/status.h"
#include "estimator/calibration.h"
#include "gap/diagnose.h"
#include "gap/locate.h"
#include "gap/resimulate.h"
#include "recording/recording.h"
#include "sim/scenario.h"

namespace roamlab::gap {

// The twin of `real` for a patched scenario (the nominal one with effects): the same streams at the same stamps.
using TwinRunner = std::function<Result<recording::Recording>(const sim::Scenario& patched)>;

// Runs `patched` without noise with sim::Simulate: the twin of a recording of the scenario's own drive.
TwinRunner PlainSimulationRunner();
// Replays `patched` with the drive inputs of `real` (sim/replay.h) up to patched.duration_s after the recording's first
// stamp (stamps may be absolute, e.g. Unix time): the twin of any recording with drive inputs. Keeps its own copy of
// the recording, and the replay's start (sim::ReplayStartOf) found at its first call. With a pose stream (motion
// capture) each run then replays its first sim::kStartAlignS from that start with its own scenario, and the start is
// moved by the planar rigid motion (yaw and translation) that best fits that replay's pose track onto the recorded one
// over that span, positions and headings weighted by their stated noise (as TwinDrift's alignment), before the run
// is replayed from the aligned start: a single pose's heading noise (5 mrad in motion capture), and a recording that
// starts in motion, which the twin takes a few steps to follow, would otherwise turn the whole run by some mrad and
// bias the geometry fitted to it.
TwinRunner ReplayRunner(const recording::Recording& real);

// How far `twin` is from following the drive of `real`: for each wheel stream in both (wheel_encoders, steering),
// over consecutive kDriveWindowS windows of their common stamps, the drive of each window (a cumulative wheel angle's
// change, i.e. its mean rate; the mean of any other reading: a wheel rate or speed, a steering angle), real against
// twin: the relative RMS difference ||d_real - d_twin - c|| / ||d_real||, c each column's mean difference (a constant
// offset of a reading, such as a steering offset, is not another drive), each squared sum less the real stream's
// stated noise variance of the windows' drives; the stream that differs most. Window means keep the readings' noise out
// of it (a 1 s mean of N samples carries 1/sqrt(N) of a sample's noise). The plain simulation is the twin only of a
// recording of the scenario's own drive: a hidden effect changes the wheels' motion by little (they are servoed to the
// same set-points), another drive by a good part of its size.
inline constexpr double kDriveWindowS = 1.0;
inline constexpr double kMaxDriveMismatch = 0.05;
struct DriveComparison {
  std::string stream;     // empty: no wheel stream in both shows a drive
  double relative = 0.0;  // its relative difference
};
DriveComparison CompareDrive(const recording::Recording& real, const recording::Recording& twin);
// Empty when `twin` follows the drive of `real` (CompareDrive's difference below kMaxDriveMismatch); otherwise why not
// (the stream and the relative difference, or that no wheel stream can tell).
std::string DriveMismatch(const recording::Recording& real, const recording::Recording& twin);

// An absolute stream's drift over fixed windows: the twin aligned to the real track over the first align_s of each
// window and the error at the window's last sample. The alignment is the planar rigid transform (yaw about the
// vertical and translation) that best fits those samples in least squares, positions and a pose stream's headings
// weighted by their stated noise (position_m or sigma_m, orientation_rad); a stream without stated heading noise
// whose real track moves less than 0.1 m there is aligned by translation at the window's first sample alone. A fit
// over align_s rather than one sample keeps the sample's noise out of the drift (a 5 mrad heading error at the start
// moves the end of a 1 m window by 5 mm). Position error, and for a pose stream the heading error
// (heading_measured).
struct TwinDrift {
  std::string stream;
  double window_s = 0.0;
  int windows = 0;
  double mean_position_m = 0.0, max_position_m = 0.0;
  bool heading_measured = false;
  double mean_heading_rad = 0.0, max_heading_rad = 0.0;
};

struct DriftOptions {
  double window_s = 10.0;
  double stride_s = 1.0;  // windows start every stride_s
  double align_s = 2.0;   // the span of the window's start the alignment fits
};

// How the twin's residuals compare a recording's streams (gap/internal/twin_residuals.h).
//   increment_window_s > 0: the absolute streams (pose, gps, position) compared over windows of this length instead of
//     sample by sample:
//     - a pose stream as TwinDrift measures the twin's drift: a window starting every increment_stride_s (the drift's
//       stride_s; the windows overlap), the twin aligned onto the recorded poses of its first align_s (the drift's
//       planar alignment, positions and headings weighted by their stated noise), the recorded position at its last
//       sample less the aligned twin's, along and across the lever from the aligned samples' recorded centroid,
//       whitened by the recorded samples' noise: sigma^2 (1 + 1/n) each way (the end sample and the centroid of n
//       samples) and l^2 / I more across (the lever l turned by the alignment's yaw, of information I). Each entry is
//       scaled by sqrt(increment_stride_s / increment_window_s), so that the overlapping windows of a span weigh in
//       the chi-square as the consecutive windows it holds would (their correlation is the HAC's, TwinCovariance);
//     - a gps fix or position stream by its increments over consecutive windows [t0, t0 + W] (each ending at the last
//       sample within W of its start, the next starting there; a window shorter than 0.9 W is not compared) in ENU,
//       per axis, whitened by the noise of the two recorded samples, sqrt(2) sigma.
//     What the twin's 10 s drift measures, without the start's error carried along the whole track. 0: sample by
//     sample, the absolute values.
//   left_out: streams not compared, by name, with the reason (the layout's left_out as "stream: reason").
struct TwinResidualOptions {
  double increment_window_s = 0.0;
  double increment_stride_s = 1.0;  // a pose stream's window starts (DriftOptions::stride_s)
  double align_s = 2.0;             // a pose stream's window alignment (DriftOptions::align_s)
  std::map<std::string, std::string> left_out;
};
// The residual options of a replayed run of `real` (ReplayRunner): windows of increment_window_s, and the
// wheel_encoders stream that drives the replay (sim::DriveInputsFrom) left out: the twin's encoders track the recorded
// angles through the wheels' velocity servos, a tick or two behind (both in whole ticks), a systematic residual of
// several sigma that the effects fitted would otherwise chase.
TwinResidualOptions ReplayedResidualOptions(const sim::Scenario& nominal, const recording::Recording& real,
                                            double increment_window_s);

// The twin against the real recording over [from_s, to_s].
struct TwinComparison {
  double increment_window_s = 0.0;  // the residuals' (TwinResidualOptions)
  double from_s = 0.0, to_s = 0.0;
  std::map<std::string, SimulatedStreamFit> streams;  // an imu as "gyroscope" and "accelerometer"
  std::map<std::string, TwinDrift> drift;             // absolute streams with a window inside the span
  std::vector<std::string> left_out;                  // "stream: reason"
  double chi2 = 0.0;                                  // sum of squared whitened residuals
  int residuals = 0;                                  // scalar residuals compared
};
TwinComparison CompareTwin(const recording::Recording& real, const recording::Recording& twin, double from_s,
                           double to_s, const DriftOptions& drift = {}, const TwinResidualOptions& residuals = {});

// The rows of a fit at its solution: the whitened residuals (finite entries only) and their derivatives by the
// parameters (one column each, in the fitted units), with each row's stamp and series (stream name), the rows of one
// series in time order.
struct TwinFitRows {
  Eigen::MatrixXd jacobian;
  Eigen::VectorXd residuals;
  std::vector<Time> t;
  std::vector<std::string> series;
  // Per row: its chi-square weight w, the square of the factor its whitened residual and Jacobian row were scaled by
  // (TwinDiagnoseOptions::train_weight); empty: every one 1.
  std::vector<double> weight;
};
// The parameters' covariances from the rows:
//   white: (J^T J)^-1, pseudo-inverse over the directions the rows see: independent unit-variance residuals; with
//          row weights other than 1, the weighted fit's (J^T J)^-1 J^T W J (J^T J)^-1 (a row scaled by sqrt(w) has
//          variance w);
//   hac:   the Newey-West sandwich B M B, B = (J^T J)^-1, with the estimator's weights and bandwidth
//   (estimator/covariance.h):
//          the rows of one series and stamp form one residual vector r_t and one score g_t = J_t^T r_t, and M sums
//          within each series the Bartlett-weighted products g_t g_{t+l}^T up to the series' lag L_s
//          (AnalyzeAutocorrelation of its residual vectors), the scores prewhitened by an AR(1) per parameter and
//          recoloured (PrewhitenedBartlettSum), each series' sum times FixedBFactor(b_s)^2, b_s = (L_s + 1) / n_s
//          of its n_s stamps; series independent of each other. With white residuals (L_s = 0) it is the white
//          covariance rescaled by the residuals' actual spread.
struct TwinCovariance {
  Eigen::MatrixXd white, hac;
  std::map<std::string, int> lags;  // per series: L_s (samples)
  // A time shift's: the batch-means variance of its spread along the run (internal/twin_fit.h BatchShiftStd), 1 x 1;
  // empty for other fits.
  Eigen::MatrixXd batch;
};
TwinCovariance ComputeTwinCovariance(const TwinFitRows& rows);
// A HAC std's widening at the bandwidth share b = (L + 1) / n of its series: Kiefer and Vogelsang's fixed-b critical
// value of the Bartlett kernel (two-sided 5 %), cv(b) = 1.96 + 2.9694 b + 0.4160 b^2 - 0.5324 b^3, over the normal's
// 1.96. With the lag a fixed share of the series the HAC long-run sum stays random and low (its mean 1 - b + b^2 / 3
// of the true one), and +-2 of the widened std covers as +-2 normal std would; 1 at b = 0.
double FixedBFactor(double b);

struct TwinEffect {
  EffectEstimate estimate;  // name (the candidate's label), dof, parameters, std, lr, p, Delta BIC, held-out drop
  // Per fitted parameter; estimate.std is the chosen one (std_method): with HAC the largest of the three.
  std::map<std::string, double> std_white, std_hac;
  std::map<std::string, double> std_batch;  // a time shift's batch-means std; empty for other fits
  // Parameters the data does not inform (internal/twin_fit.h FitCandidate: a conditional white std above 5 % of the
  // parameter's range), held at their neutral values in estimate.parameters and the effect, without a std and not
  // counted in estimate.dof.
  std::vector<std::string> not_informed;
  std::map<std::string, int> hac_lags;      // per series: the HAC lag (samples)
  std::vector<sim::EffectOptions> applied;  // as the simulator applies it (time shifts in whole physics steps): one
                                            // effect, or a composite candidate's parts
  double chi2_before = 0.0;                 // training part: with the effects kept before it
  double chi2_after = 0.0;                  // with it (refitted: with it and the kept effects refitted)
  // Its values and std come from a fit together with the other kept effects but time shifts (step 3): a later
  // round's candidate refitted with the kept ones, or a kept one refitted with a later round's; the std is marginal
  // over theirs.
  bool refitted = false;
  int iterations = 0;
  int runs = 0;  // twin runs spent on the fit
};

// The kept effects fitted together (step 5): per refitted effect its joint values and marginal std (estimate.name,
// parameters, std, dof; std_white, std_hac, not_informed and hac_lags as the rounds'); chi2_before is the training
// chi-square at the rounds' values, chi2_after at the joint ones; iterations and runs are the joint fit's.
struct TwinJointFit {
  std::vector<TwinEffect> effects;  // in the kept order
  // Per effect (effects' order) and parameter: its white std with the other effects held at their joint values (from
  // the joint information's block of the effect), the std a fit of the effect alone there would report; at most the
  // marginal std_white, equal to it where the effect does not correlate with the others.
  std::vector<std::map<std::string, double>> std_white_conditional;
  std::vector<std::string> held;  // kept effects not refitted (time shifts), at their kept values
  std::string failed;             // why the joint fit failed (a twin run's error), empty when it did not
  double chi2_before = 0.0, chi2_after = 0.0;
  int iterations = 0, runs = 0;
};

// A recording held out of the fit (another run of the same robot): the nominal twin and the patched twin (the patch
// fitted on the diagnosed recording) compared with it over its whole span.
struct TwinHeldOutRun {
  std::string recording;  // as named by the caller (its path)
  bool replayed = false;  // the runner replays its drive
  TwinComparison before, after;
};

// A recording the patch is fitted on, with its twin's runner: the diagnosed recording, and further runs of the same
// robot (DiagnoseTwin's training runs).
struct TwinTrainingRun {
  std::string recording;  // as named by the caller (its path); prefixes its series' names in a fit on several runs
  const recording::Recording* real = nullptr;
  TwinRunner runner;
  bool replayed = false;  // the runner replays its drive
};

// A further training run's figures: its training part's end and its held-out part (the last 1 - train_fraction; none
// when the run trains whole, DiagnoseTwin's runs) with the nominal twin and the patched one.
struct TwinTrainingFigures {
  std::string recording;
  bool replayed = false;
  double train_end_s = 0.0;
  TwinComparison heldout_before, heldout_after;
};

struct TwinDiagnosis {
  std::string verdict;  // named | unknown | none
  bool replayed = false;
  std::string std_method;  // "white" or "hac": which of each effect's std_white and std_hac is its std
  double train_end_s = 0.0;
  std::vector<LocatedComponent> located;  // the nominal twin, whole run
  std::vector<TwinEffect> candidates;     // the first round, best Delta BIC first
  // Every round's candidates (the first is `candidates`), best Delta BIC first, each with its decision.
  std::vector<std::vector<TwinEffect>> rounds;
  std::vector<TwinEffect> effects;       // kept, in order
  TwinJointFit joint;                    // empty unless more than one effect is kept and refitted
  std::vector<std::string> unexplained;  // "stream/component" inconsistent on the held-out part with the patch
  TwinComparison whole_run;              // the nominal twin
  TwinComparison heldout_before, heldout_after;
  std::vector<sim::EffectOptions> patch;           // the kept effects as the simulator takes them
  std::vector<TwinHeldOutRun> heldout_runs;        // ShowOnHeldOut's, filled by the caller
  std::vector<TwinTrainingFigures> training_runs;  // the training runs after the diagnosed one
  double increment_window_s = 0.0;                 // the replayed runs' residuals (TwinDiagnoseOptions)
  std::string train_weight = "windows";            // TwinDiagnoseOptions::train_weight: "windows" or "runs"
  std::vector<double> run_weights;                 // per training run (the diagnosed first): its chi-square weight
  int runs = 0;
  double seconds = 0.0;
};

struct TwinDiagnoseOptions {
  double train_fraction = 2.0 / 3.0;
  double alpha = 1e-3;
  double max_delta_bic = 0.0;
  double min_heldout_improvement = 0.0;
  int max_effects = 2;
  double max_shift_s = 0.5;  // time-shift search range
  int threads = 2;           // twin runs in parallel
  int max_iterations = 8;    // Levenberg-Marquardt
  bool replayed = false;     // the runner replays the recorded drive (written with the results)
  DriftOptions drift;
  // A replayed run's fit and held-out comparison (TwinTrainingRun::replayed): its absolute streams compared over
  // windows of this length (TwinResidualOptions), and its driving encoders left out (ReplayedResidualOptions); 0: the
  // absolute values, the driving encoders still left out. The other runs, and the located components, compare the
  // absolute values.
  double increment_window_s = 10.0;
  // How the training runs weigh in the fit (with several runs):
  //   kWindows: each residual as its series weighs it, so that a run weighs by its training part's length;
  //   kRuns: each run's whitened residuals scaled by sqrt(w_r), w_r = S / (R S_r), S_r the run's summed chi-square
  //     weight (its layout's entries, each its series' weight squared), S the runs' total, R their number: every run
  //     weighs S / R, the total S unchanged (internal::EqualRunScales). The held-out test weighs each run's held-out
  //     chi-square by the same w_r. With one run the two are the same.
  enum class TrainWeight { kWindows, kRuns };
  TrainWeight train_weight = TrainWeight::kWindows;
  // The std reported: white, hac (the larger of std_white and std_hac, as the estimator's calibration reports), or
  // auto (hac on an imported recording, white on a simulated one).
  estimator::CalibrationOptions::StdMethod std_method = estimator::CalibrationOptions::StdMethod::kAuto;
  // Empty: every one the scenario supports, diff_drive_geometry (the radius scale, right/left ratio and track fitted
  // together) only with several training runs.
  std::vector<std::string> candidates;
  std::function<void(const std::string&)> progress;
};

// The candidate effects of the twin: labels (an effect name, with the wheel for axle_misalignment: "axle_misalignment
// wheel 1") that `nominal` supports.
std::vector<std::string> TwinCandidateNames(const sim::Scenario& nominal);

// Errors: the nominal twin fails, or the recording has nothing to compare.
Result<TwinDiagnosis> DiagnoseTwin(const sim::Scenario& nominal, const recording::Recording& real,
                                   const TwinRunner& runner, const TwinDiagnoseOptions& options = {});
// The diagnosis with the patch fitted on several runs of the same robot, the diagnosed recording first: each run's
// twin with its own runner; each contributes its first train_fraction to the fit and its last part to the held-out
// test, except a further run whose last part is too short to hold one of its comparison's windows (a replayed run's
// increment_window_s, internal::kShortestWindowShare of it): that one trains whole. The fit's residuals and chi-square,
// the score test, LR and Delta BIC (n: the runs' training residuals) and the held-out chi-square drop are over the runs
// together; the HAC covariance treats each run's series as independent series. Locate, whole_run, heldout_before/after
// and unexplained are the diagnosed recording's; training_runs holds the others' held-out figures. With one run it is
// the diagnosis above. Errors: as above, naming the run.
Result<TwinDiagnosis> DiagnoseTwin(const sim::Scenario& nominal, const std::vector<TwinTrainingRun>& runs,
                                   const TwinDiagnoseOptions& options = {});

// The patch shown on a held-out recording: its twin with `runner` (the twin of `held`) for the nominal scenario (its
// effects removed) and for the nominal one with `patch`, both up to held's last stamp, run in parallel on `threads`,
// each compared with `held` over its span (`residuals`: ReplayedResidualOptions for a replayed twin, as the fit's).
// Errors: a twin fails, or `held` has no span of samples.
Result<TwinHeldOutRun> ShowOnHeldOut(const sim::Scenario& nominal, const std::vector<sim::EffectOptions>& patch,
                                     const recording::Recording& held, const TwinRunner& runner,
                                     const DriftOptions& drift = {}, int threads = 2,
                                     const TwinResidualOptions& residuals = {});

// Per stream: {"window_s", "windows", "mean_position_m", "max_position_m"[, "mean_heading_rad", "max_heading_rad"]}.
nlohmann::json TwinDriftJson(const std::map<std::string, TwinDrift>& drift);

// {"replayed", "verdict", "std_method", "train_end_s", "located", "candidates", "rounds" (every round's candidates,
// the first's as "candidates"), "effects" (each with "effect": the simulator's effects it sets), "joint" (null, or
// {"effects", "held", "failed", "chi2_before", "chi2_after", "iterations", "runs"}), "unexplained",
// "heldout": {"before", "after"}, "whole_run", "patch",
// "heldout_runs": [{"recording", "replayed", "before", "after"}], "increment_window_s", "train_weight", "run_weights",
// "runs", "seconds"}, and with
// further training runs "training_runs": [{"recording", "replayed", "train_end_s", "heldout": {"before", "after"}}]:
// gap.json's "simulation" section.
nlohmann::json TwinDiagnosisJson(const TwinDiagnosis& d);

}  // namespace roamlab::gap
