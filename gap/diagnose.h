// Reality-gap diagnosis: given a recording and the nominal model of the robot (an estimator configuration whose free
// parameters are the ordinary calibration), find where the recording departs from the model, name the physical effect
// from a library, fit it and show the held-out fit improve. Diagnose runs these steps (diagnose.cc):
//
//   1. replay: self-calibrate the nominal parameters on the whole recording (the estimator's models are the nominal
//      model) and keep the whitened residuals;
//   2. locate: per stream and component, chi-square per dof, intervals and correlated conditions (locate.h), against
//      the levels the nominal model reaches on a nominal simulation (Baseline) when one is given;
//   3. name: every candidate effect of the library (internal/effect_library.h) is fitted on the first
//      `train_fraction` of the recording with the full solver (all calibration parameters free, warm-started at the
//      nominal fit; internal/candidate_fit.h): a parameter slot freed in an error model (also the IMU's clock offset,
//      the time_offset_s the gyroscope and accelerometer share, started from a profile over it), or a time shift of
//      a stream found by a 1-D search on the master period's grid with a parabola through the best points (its
//      curvature gives the standard deviation; GPS latency, an absolute pose stream's offset, and an IMU offset
//      beyond the first-order model's range; internal/time_shift.h). Standard deviations (DiagnoseOptions::std_method,
//      HAC by default on imported recordings, whose residuals are autocorrelated so that the white chi-square
//      curvature understates a fitted parameter's spread many times): a freed slot's from the estimator's HAC
//      covariance (estimator/covariance.h); a time shift's is the parabola's times sqrt(tau), tau the integrated
//      autocorrelation time of the shifted streams' residuals at the chosen shift (AnalyzeAutocorrelation; the
//      largest over those streams). Statistic (internal/decide.h, Score): without a
//      baseline the chi-square drop LR = chi2_nominal - chi2_effect ~ chi2(k) (cost = chi2 / 2, estimator/solver.h);
//      with one, the nominal model is not exact on MuJoCo data and already moves each candidate's parameters on the
//      nominal simulation, so H0 is "the parameters take the baseline's values" and LR is its Wald form with both
//      fits' variances. p = 1 - F_chi2(k)(LR), Delta BIC = -LR + k ln n. In order of Delta BIC, the first candidate
//      with p < alpha, Delta BIC < max_delta_bic and a held-out chi-square drop above min_heldout_improvement
//      (defaults 1e-3, 0, 0; gap-benchmark calibrates them) (the last part of the recording, every parameter fixed
//      at the training values) and that explains at least min_explained_share of the mismatch there (ExplainedShare:
//      its held-out chi-square drop over that drop plus the chi-square left above the nominal level in the
//      components Locate found inconsistent; with effects kept, the drop is theirs and its together; default 0.25)
//      is kept; one that fails a held-out test is dropped. Then the others are scored again on top, up to
//      max_effects;
//   4. model: the accepted effects' parameters and standard deviations (training fit), as estimator settings too;
//   5. show: per-stream whitened RMS and chi2/dof on the held-out part before (nominal) and after (with the effects).
// Verdict (internal/decide.h): "named" (some effect kept and every inconsistent component explained), "unknown" (some
// component stays inconsistent: without a kept effect, or on the held-out part with the kept effects against the
// nominal model's held-out level; its conditions say what it depends on; the kept effects are still listed) or
// "none". The diagnosis reads the recording's streams only (never truth.yaml), and needs no simulator: the nominal
// configuration of a simulated robot, the baseline and the re-simulation live in roamlab::gap_sim
// (nominal_config.h, learn_baseline.h, resimulate.h).
#pragma once

#include <functional>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "estimator/calibration.h"
#include "estimator/config.h"
#include "gap/locate.h"
#include "recording/recording.h"

namespace roamlab::gap {

struct EffectEstimate {
  std::string name;
  int dof = 0;                               // parameters added
  std::map<std::string, double> parameters;  // names as the simulator's effects (sim/scenario.h)
  std::map<std::string, double> std;
  std::map<std::string, double> baseline_parameters;  // the raw fit on the nominal simulation, subtracted
  double lr_raw = 0.0;                                // chi2 drop on the training part against the nominal model
  double baseline_lr = 0.0;                           // the same candidate's drop on the nominal simulation
  double lr = 0.0;  // the test statistic (Score, internal/decide.h), ~ chi2(dof) under H0
  double lr_pvalue = 1.0;
  double delta_bic = 0.0;            // < 0 favours the effect
  double heldout_improvement = 0.0;  // relative drop of the held-out chi2 (0.1 = 10 % lower)
  // The located mismatch on the held-out part (HeldoutExcess over the components Locate found inconsistent) before
  // the candidate (the nominal model with the effects kept so far) and with it, and the share of the mismatch the
  // effects kept so far and the candidate explain together (ExplainedShare of their held-out chi2 drop from the
  // nominal model and the excess left; NaN until evaluated).
  double heldout_excess_before = 0.0;
  double heldout_excess_after = 0.0;
  double explained_share = std::numeric_limits<double>::quiet_NaN();
  bool evaluated_heldout = false;
  bool accepted = false;
  std::string decision;  // why kept or not, one phrase
};

// What the nominal model gives on a nominal simulation of the same robot and drive.
struct Baseline {
  std::map<std::string, double> component_levels;          // ComponentKey -> chi2/dof, whole run
  std::map<std::string, double> heldout_component_levels;  // ComponentKey -> chi2/dof, held-out part (nominal fit)
  std::map<std::string, StreamFit> streams;                // whole run
  std::map<std::string, double> candidate_lr;              // candidate -> chi2 drop on the training part
  // candidate -> parameter -> (value, std) fitted on the nominal simulation
  std::map<std::string, std::map<std::string, std::pair<double, double>>> candidate_parameters;
};

struct Diagnosis {
  std::string verdict;                             // named | unknown | none
  std::vector<LocatedComponent> located;           // every component; inconsistent ones flagged
  std::vector<EffectEstimate> candidates;          // the first round's scores, best first
  std::vector<EffectEstimate> effects;             // accepted, in order
  std::vector<std::string> unexplained;            // for "unknown": "stream/component depends on condition"
  std::map<std::string, StreamFit> whole_run;      // the nominal fit of the whole recording
  std::map<std::string, StreamFit> before, after;  // held-out part: nominal, with the accepted effects
  std::map<std::string, ComponentLevel> heldout_components_before, heldout_components_after;  // per ComponentKey
  double train_end_s = 0.0;                                   // the held-out part starts here (recording time)
  std::vector<estimator::MeasurementResidual> residuals;      // whole-run nominal fit
  Conditions conditions;                                      // from the whole-run nominal trajectory
  std::map<std::string, Eigen::VectorXd> nominal_parameters;  // whole-run nominal calibration
  // The training part's calibration (every parameter: fitted, or at its configured value), nominal and with the
  // accepted effects: what the held-out part's `before` and `after` are fitted with.
  std::map<std::string, Eigen::VectorXd> training_parameters_before, training_parameters_after;
  // The accepted effects as estimator settings: parameters (name -> value) and stream time shifts [s]
  // (recording stream -> seconds to subtract from its stamps).
  std::map<std::string, Eigen::VectorXd> effect_parameters;
  std::map<std::string, double> stream_shifts_s;
  int fits = 0;  // calibrations run
  double seconds = 0.0;
  std::string std_method;  // "white" or "hac": how the effects' standard deviations were computed
};

inline constexpr double kDefaultMinExplainedShare = 0.25;

struct DiagnoseOptions {
  const Baseline* baseline = nullptr;  // null: levels 1 and no baseline drops
  double train_fraction = 2.0 / 3.0;
  double alpha = 1e-3;                   // likelihood-ratio test level
  double max_delta_bic = 0.0;            // kept only with Delta BIC below this
  double min_heldout_improvement = 0.0;  // kept only when the held-out chi2 drops by more than this fraction
  // Kept only when it explains at least this share of the mismatch on the held-out part (ExplainedShare). An effect
  // outside the library can pull a library parameter through the shared attitude or trajectory and pass the tests
  // above, but leaves its own stream about as inconsistent as before: the share it explains is small.
  double min_explained_share = kDefaultMinExplainedShare;
  // First round: also evaluate the held-out part for the candidates after the kept one that pass the p and BIC
  // tests (decisions unchanged; lets gap-benchmark replay the first round's decision under stricter thresholds).
  bool heldout_all_candidates = false;
  int max_effects = 3;       // 0: score the candidates only (learning a baseline)
  double max_shift_s = 0.5;  // time-shift search range and the margin cut from shifted streams
  // The effects' standard deviations: white, or HAC (freed slots: the estimator's HAC covariance; time shifts: the
  // parabola's inflated by the shifted streams' integrated autocorrelation time); kAuto: HAC on imported recordings.
  estimator::CalibrationOptions::StdMethod std_method = estimator::CalibrationOptions::StdMethod::kAuto;
  std::function<void(const std::string&)> progress;
};

// The candidate effects the library knows, whether or not a configuration supports them.
const std::vector<std::string>& CandidateNames();

// Runs the diagnosis. Errors: the configuration does not fit the recording, or a fit fails.
Result<Diagnosis> Diagnose(const estimator::EstimatorConfig& nominal, const recording::Recording& recording,
                           const DiagnoseOptions& options = {});

// The located mismatch a fit leaves on the held-out part: the chi-square above the nominal level, sum over `keys` of
// max(0, chi2 - expected * count), with `components` the fit's per-component statistics and `expected` the nominal
// model's held-out chi2/dof per component (missing keys: 1; keys absent from `components` add nothing). Every located
// component counts, also one back within Locate's ratio there: a decoy's accelerometer at a few times its tiny level
// can fall under the verdict's rule on a short held-out part and still hold most of the mismatch.
double HeldoutExcess(const std::map<std::string, ComponentLevel>& components, const std::vector<std::string>& keys,
                     const std::map<std::string, double>& expected);
// The share of the held-out mismatch a candidate explains: its held-out chi-square drop D over D plus the located
// excess R left with it (HeldoutExcess), D / (D + R): 1 when nothing located stays above its level, small when a
// large excess stays (a decoy's stream), 0 when D <= 0. The drop counts wherever it is (an effect's own components
// need not be among the located ones, e.g. an oval tire's wheel rows), the remainder only where Locate found the run
// inconsistent (the rest carries the noise's excess).
double ExplainedShare(double heldout_drop, double remaining_excess);

// The baseline from the diagnosis of a nominal simulation (run with max_effects = 0 and no baseline).
Baseline BaselineFrom(const Diagnosis& nominal_simulation);

}  // namespace roamlab::gap
