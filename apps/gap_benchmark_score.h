// Scoring of `roamlab gap-benchmark` (issue 6, "The proof"): pure functions on the cases' outcomes, no simulation.
//
//   - ReplayFirstRound: the diagnosis's first-round decision (gap/diagnose.h, step 3) under other thresholds, from the
//     candidates' statistics of a run with looser ones (held-out evaluated for every candidate passing them);
//   - ChooseThresholds: the thresholds (alpha, Delta BIC, held-out drop) fixed on the calibration cases only: the
//     grid point that identifies the most calibration cases correctly with false discoveries on the effect-free
//     cases (none and decoys) at or under the target;
//   - CalibrationSigmas / NoiseRatio: the noise of an effect's parameter is the median standard deviation the
//     diagnosis reports for that candidate's parameter over the calibration cases of the platform (every case fits
//     every candidate); an effect's magnitude relative to the noise is |theta - neutral| / that sigma;
//   - Summarize: the figures and targets.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace roamlab::apps::gapbench {

// A first-round candidate's statistics (gap::EffectEstimate).
struct CandidateStats {
  std::string name;
  double lr_pvalue = 1.0;
  double delta_bic = 0.0;
  bool evaluated_heldout = false;
  double heldout_improvement = 0.0;
  std::map<std::string, double> std;      // reported standard deviations (NaN when unknown)
};

struct Thresholds {
  double alpha = 1e-3;
  double max_delta_bic = 0.0;
  double min_heldout_improvement = 0.0;
};

// One benchmark case: what was hidden, what the diagnosis said, and the figures scored from truth.yaml.
struct CaseResult {
  std::string id;
  std::string platform;                    // atv | diffdrive | mecanum
  std::string kind;                        // none | effect | decoy
  std::string truth_name;                  // empty for none
  std::string truth_parameter;             // the parameter drawn away from neutral (effect, decoy)
  double truth_value = 0.0;
  double noise_ratio = -1.0;               // |truth - neutral| / sigma; < 0 when not defined
  std::string verdict;                     // named | unknown | none
  std::vector<std::string> named;          // accepted effects, in order
  std::vector<std::string> ranked;         // accepted effects, then the other first-round candidates by Delta BIC
  double estimate = 0.0;                   // the diagnosis's value of truth_parameter, when the truth was named
  bool has_estimate = false;
  double rms_before = 0.0, rms_after = 0.0;   // held-out whitened RMS of the affected stream
  double rms_1s_before = 0.0, rms_1s_after = 0.0;   // its systematic part (gap::StreamFit::rms_1s)
  bool has_rms = false;
  std::vector<CandidateStats> candidates;  // first round
  double seconds = 0.0;
};

// Neutral value of an effect parameter (what the nominal model assumes).
double NeutralValue(const std::string& parameter);

// The first candidate the first round keeps under `t` (empty: none kept). Candidates in order of Delta BIC; one that
// passes p and BIC but was not evaluated on the held-out part counts as failing it.
std::string ReplayFirstRound(std::vector<CandidateStats> candidates, const Thresholds& t);

// Whether a case is scored correct under a first-round decision: none and decoy cases name nothing, effect cases
// name their effect first.
bool ReplayCorrect(const CaseResult& c, const std::string& kept);

// The grid searched by ChooseThresholds (each point at least as strict as `Loosest()`).
std::vector<Thresholds> ThresholdGrid();
Thresholds Loosest();

// Thresholds from calibration cases: the grid point with the most correct replays among those whose false-discovery
// rate on the effect-free cases (none and decoy: anything named) is <= max_false_rate (all points when none is);
// ties go to the strictest. `table` (optional) receives every grid point's counts.
Thresholds ChooseThresholds(const std::vector<CaseResult>& calibration, double max_false_rate,
                            nlohmann::json* table = nullptr);

// platform -> "effect/parameter" -> median reported std over the calibration cases (NaN and non-positive skipped).
std::map<std::string, std::map<std::string, double>> CalibrationSigmas(const std::vector<CaseResult>& calibration);

// |value - neutral| / sigma of platform's effect parameter; -1 when there is no sigma.
double NoiseRatio(const std::map<std::string, std::map<std::string, double>>& sigmas, const std::string& platform,
                  const std::string& effect, const std::string& parameter, double value);

// The figures over the scored cases, with the targets and whether each is met.
nlohmann::json Summarize(const std::vector<CaseResult>& cases, double min_noise_ratio = 3.0);

// One case as a row of score.json's table.
nlohmann::json CaseRow(const CaseResult& c);

}  // namespace roamlab::apps::gapbench
