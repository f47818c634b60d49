// Scoring of the gap benchmark (gap/benchmark/benchmark.h): pure functions on the cases' outcomes, no simulation.
//
//   - ReplayFirstRound: the diagnosis's first-round decision (gap/diagnose.h, step 3) under other thresholds, from the
//     candidates' statistics of a run with looser ones (held-out evaluated for every candidate passing them);
//   - Identified / FalseDiscovery: the one rule that judges a case from the effects kept, used by both the
//     calibration's replay and the score;
//   - ChooseThresholds: the thresholds (alpha, Delta BIC, held-out drop, share of the held-out mismatch explained)
//     fixed on the calibration cases only (drawn stratified, CalibrationKind): the
//     grid point that identifies the most calibration cases correctly with false discoveries on the none cases and
//     on the decoys at or under the benchmark's targets;
//   - CalibrationSigmas / NoiseRatio: the noise of an effect's parameter is the median standard deviation the
//     diagnosis reports for that candidate's parameter over the calibration cases of the platform (every case fits
//     every candidate); an effect's magnitude relative to the noise is |theta - neutral| / that sigma;
//   - RearCorneringCompliance: a lateral_slip effect's size in the candidate's units, measured on a drive's truth;
//   - Summarize: the benchmark's figures and targets.
#pragma once

#include <limits>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/status.h"
#include "gap/diagnose.h"
#include "recording/trajectory.h"

namespace roamlab::gap::benchmark {

// A first-round candidate's statistics (EffectEstimate).
struct CandidateStats {
  std::string name;
  double lr_pvalue = 1.0;
  double delta_bic = 0.0;
  bool evaluated_heldout = false;
  double heldout_improvement = 0.0;
  std::map<std::string, double> std;  // reported standard deviations (NaN when unknown)
  // The share of the held-out mismatch it explains (ExplainedShare; NaN: not evaluated).
  double explained_share = std::numeric_limits<double>::quiet_NaN();
};

struct Thresholds {
  double alpha = 1e-3;
  double max_delta_bic = 0.0;
  double min_heldout_improvement = 0.0;
  double min_explained_share = kDefaultMinExplainedShare;
};

// One benchmark case: what was hidden, what the diagnosis said, and the figures scored from truth.yaml.
struct CaseResult {
  std::string id;
  std::string platform;         // atv | diffdrive | mecanum
  std::string kind;             // none | effect | decoy
  std::string truth_name;       // empty for none
  std::string truth_parameter;  // the parameter drawn away from neutral (effect, decoy)
  double truth_value = 0.0;
  double noise_ratio = -1.0;        // |truth - neutral| / sigma; < 0 when not defined
  std::string verdict;              // named | unknown | none
  std::vector<std::string> named;   // accepted effects, in order
  std::vector<std::string> ranked;  // accepted effects, then the other first-round candidates by Delta BIC
  double estimate = 0.0;            // the diagnosis's value of truth_parameter, when the truth was named
  bool has_estimate = false;
  double rms_before = 0.0, rms_after = 0.0;        // held-out whitened RMS of the affected stream
  double rms_1s_before = 0.0, rms_1s_after = 0.0;  // its systematic part (StreamFit::rms_1s)
  bool has_rms = false;
  // The re-simulation's (gap/resimulate.h): RMS of recorded minus simulated in the stream the effect shows in
  // (SimulatedStream), in units of its stated noise, on the held-out part, as believed and with the accepted effects.
  std::string sim_stream;
  double sim_rms_before = 0.0, sim_rms_after = 0.0;
  double sim_rms_1s_before = 0.0, sim_rms_1s_after = 0.0;  // of its 1 s means
  bool has_sim_rms = false;
  std::vector<CandidateStats> candidates;  // first round
  // The "real" recording's drive: the scenario's own schedule, or another one (OtherDrive); and whether the
  // re-simulation replayed it (gap/resimulate.h ChooseTwin, detected blind).
  bool other_drive = false;
  bool replayed = false;
  double seconds = 0.0;
};

// The benchmark's targets on the effect-free cases: false discoveries on none cases <= 10 %, decoys reported `unknown`
// (and nothing kept) >= 70 %, i.e. at most 30 % of the decoys with a library effect kept.
constexpr double kMaxNoneFalseRate = 0.10;
constexpr double kMinDecoysUnknown = 0.70;

// Neutral value of an effect parameter (what the nominal model assumes).
double NeutralValue(const std::string& parameter);

// The first candidate the first round keeps under `t` (empty: none kept). Candidates in order of Delta BIC; one that
// passes p and BIC but was not evaluated on the held-out part counts as failing it; one evaluated passes the share
// test when it explains at least t.min_explained_share of the held-out mismatch (a NaN share, not recorded, passes).
std::string ReplayFirstRound(std::vector<CandidateStats> candidates, const Thresholds& t);

// The one rule for a case, from the first effect the diagnosis kept (empty: none kept), shared by the calibration's
// replay and the score. The verdict is not part of it (the replay cannot know it):
//   - an effect case is identified when its effect is the first kept, also beside a verdict `unknown` (the user gets
//     the right effect and a warning that more structure remains);
//   - an effect-free case (none, decoy) is a false discovery when any library effect is kept, also beside a verdict
//     `unknown`: the user would still apply a scenario patch with a wrong effect.
bool Identified(const CaseResult& c, const std::string& first_kept);
bool FalseDiscovery(const CaseResult& c, const std::string& first_kept);
// The first effect a scored case kept (empty: none).
std::string FirstKept(const CaseResult& c);

// Whether a case is correct under a first-round decision: effect cases identified, the others no false discovery.
bool ReplayCorrect(const CaseResult& c, const std::string& kept);

// The kind of calibration case `index` (stratified: the threshold's false-discovery rates are judged on enough
// effect-free cases): none when index % 4 == 0, decoy when index % 4 == 1, else effect, so that any first n cases
// hold about a quarter none and a quarter decoys. The scored cases are drawn blind (kinds at random).
std::string CalibrationKind(int index);

// The grid searched by ChooseThresholds (each point at least as strict as `Loosest()`).
std::vector<Thresholds> ThresholdGrid();
Thresholds Loosest();

// Thresholds from calibration cases: the grid point with the most correct replays among those whose false-discovery
// rate is <= max_none_false_rate on the none cases and <= max_decoy_false_rate on the decoys (all points when none
// is); ties go to the point nearest diagnose's defaults (alpha 1e-3, Delta BIC 0, held-out drop 0, explained share
// kDefaultMinExplainedShare), then the strictest. `table` (optional) receives every grid
// point's counts.
Thresholds ChooseThresholds(const std::vector<CaseResult>& calibration, double max_none_false_rate,
                            double max_decoy_false_rate, nlohmann::json* table = nullptr);

// platform -> "effect/parameter" -> median reported std over the calibration cases (NaN and non-positive skipped).
std::map<std::string, std::map<std::string, double>> CalibrationSigmas(const std::vector<CaseResult>& calibration);

// |value - neutral| / sigma of platform's effect parameter; -1 when there is no sigma.
double NoiseRatio(const std::map<std::string, std::map<std::string, double>>& sigmas, const std::string& platform,
                  const std::string& effect, const std::string& parameter, double value);

// The rear axle's cornering compliance c_rear [s] of a drive, measured on its truth (how the diagnosis's lateral_slip
// candidate states a tire's sideways slip, as tools/atv_odometer_residuals.py measures it): O's sideways velocity
// regressed on the lateral acceleration a_y = v_x omega_z and on the roll rate (which moves O sideways over the ground
// contact), velocities between consecutive poses, after the first 2 s and above 0.5 m/s forward; c_rear = -(slope on
// a_y). NaN with fewer than 10 such pose pairs.
double RearCorneringCompliance(const Trajectory& truth);

// The benchmark's figures over the scored cases, with the targets and whether each is met; with cases of both drives,
// also "drive": the cases of each whose re-simulation was replayed, and the figures of each drive's cases alone
// ("by_drive": {"own", "other"}).
nlohmann::json Summarize(const std::vector<CaseResult>& cases, double min_noise_ratio = 3.0);

// One case as a row of score.json's table (and of its case.json).
nlohmann::json CaseRow(const CaseResult& c);
// The case a row describes, as CaseRow wrote it: every field read back exactly. An error when a key is missing or of
// another type.
Result<CaseResult> CaseFromRow(const nlohmann::json& row);

}  // namespace roamlab::gap::benchmark
