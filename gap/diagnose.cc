#include "gap/diagnose.h"

#include <algorithm>
#include <chrono>
#include <set>

#include "common/interrupt.h"
#include "gap/internal/candidate_fit.h"
#include "gap/internal/decide.h"
#include "gap/internal/effect_library.h"
#include "gap/internal/fit.h"

namespace roamlab::gap {
namespace {

using estimator::EstimatorConfig;
using internal::CandidateFit;
using internal::State;
using recording::Recording;

// The recording cut into the whole run, the training part and the held-out part (internal::Slice: cut for shifts
// within the time-shift range).
struct Parts {
  Recording whole, train, test;
  double split_s = 0.0;  // the held-out part starts here (recording time)
};

// The master stream's span and the split into training and held-out parts. Errors: no master stream, or too short.
Result<Parts> SplitRecording(const EstimatorConfig& nominal, const Recording& recording,
                             const DiagnoseOptions& options) {
  const auto master = nominal.streams.find(nominal.master);
  if (master == nominal.streams.end() || master->second.sources.empty())
    return Status::Error(nominal.source_file + ": master stream '" + nominal.master + "' is not configured");
  const recording::Stream* master_stream = recording.Find(master->second.sources.begin()->second);
  if (!master_stream || master_stream->t.size() < 10)
    return Status::Error("the recording has no (or too short a) '" + master->second.sources.begin()->second +
                         "' stream for the master '" + nominal.master + "'");
  const double t0 = master_stream->t.front().seconds();
  const double t1 = master_stream->t.back().seconds();
  Parts parts;
  parts.split_s = t0 + options.train_fraction * (t1 - t0);
  std::set<std::string> master_sources, position;
  for (const auto& [role, source] : master->second.sources) master_sources.insert(source);
  for (const auto& [name, sc] : nominal.streams)
    if (sc.model == "gps") position.insert(sc.sources.begin()->second);
  const double margin = options.max_shift_s;
  parts.whole = internal::Slice(recording, t0, t1, master_sources, position, margin);
  parts.train = internal::Slice(recording, t0, parts.split_s, master_sources, position, margin);
  parts.test = internal::Slice(recording, parts.split_s, t1, master_sources, position, margin);
  return parts;
}

// Step 1: the nominal self-calibration of the whole run, its residuals, per-stream fits, parameters and the motion
// conditions along its trajectory.
Status Replay(const EstimatorConfig& nominal, const Recording& whole, const Recording& recording,
              const internal::TrainingFits& fits, Diagnosis* out) {
  fits.Say("replay: nominal self-calibration of the whole recording");
  internal::FitSpec whole_spec;
  whole_spec.keep_residuals = true;
  auto whole_fit = internal::Fit(nominal, whole, whole_spec);
  ++out->fits;
  if (!whole_fit.ok()) return Status::Error("nominal calibration: " + whole_fit.status().message());
  fits.Say("replay: chi2 " + std::to_string(whole_fit.value().chi2) + " over " +
           std::to_string(whole_fit.value().measurements) + " measurements");
  out->residuals = whole_fit.value().residuals;
  out->whole_run = StreamFits(out->residuals);
  out->nominal_parameters = whole_fit.value().values;
  out->conditions = ComputeConditions(whole_fit.value().trajectory, recording);
  return Status::Ok();
}

// The nominal model's training fit and its held-out evaluation: the state the rounds start from.
Result<State> NominalState(const internal::TrainingFits& fits, internal::HeldoutEvaluator* heldout, Diagnosis* out) {
  auto train_fit = fits.Run({});
  if (!train_fit.ok()) return Status::Error("nominal calibration (training part): " + train_fit.status().message());
  State state;
  state.train_values = train_fit.value().values;
  out->training_parameters_before = state.train_values;
  state.train_trajectory = train_fit.value().trajectory;
  state.train_chi2 = train_fit.value().chi2;
  state.train_measurements = train_fit.value().measurements;
  auto h = heldout->Evaluate(state);
  if (!h.ok()) return Status::Error("held-out evaluation: " + h.status().message());
  state.heldout_chi2 = h.value().chi2;
  state.heldout = h.value().streams;
  state.heldout_components = h.value().components;
  out->before = state.heldout;
  out->heldout_components_before = state.heldout_components;
  return state;
}

// Fits and scores every candidate not yet accepted or dropped on top of `state`. A candidate whose fit fails (e.g. a
// gyroscope scale driven to 0 on an axis a short planar drive does not excite) explains nothing: it goes into
// `failed` and `dropped` (not tried again), and the diagnosis goes on.
std::vector<CandidateFit> FitRound(const internal::TrainingFits& fits, const std::vector<internal::Candidate>& library,
                                   const State& state, int round, const DiagnoseOptions& options,
                                   const std::set<std::string>& accepted, std::set<std::string>* dropped,
                                   std::vector<EffectEstimate>* failed) {
  std::vector<CandidateFit> out;
  for (const internal::Candidate& c : library) {
    if (InterruptRequested()) break;  // Diagnose() reports it
    if (accepted.count(c.name) || dropped->count(c.name)) continue;
    fits.Say("candidate " + c.name + (round > 0 ? " (on top of the accepted effects)" : ""));
    auto cf = internal::FitCandidate(fits, c, state);
    if (!cf.ok()) {
      EffectEstimate e;
      e.name = c.name;
      e.dof = c.shifted.empty() ? c.free_dof : 1;
      e.delta_bic = std::numeric_limits<double>::infinity();
      e.decision = "rejected: the fit failed (" + cf.status().message() + ")";
      fits.Say("candidate " + c.name + ": " + e.decision);
      failed->push_back(e);
      dropped->insert(c.name);
      continue;
    }
    internal::Score(options.baseline, state.train_measurements, &cf.value().estimate);
    out.push_back(std::move(cf).value());
  }
  return out;
}

// A round's candidates into the diagnosis: the held-out figures said, the undecided marked, the first round's
// candidates (then the failed ones) listed.
void RecordRound(const internal::TrainingFits& fits, int round, std::vector<CandidateFit>* candidates,
                 const std::vector<EffectEstimate>& failed, Diagnosis* out) {
  for (CandidateFit& f : *candidates) {
    if (f.estimate.evaluated_heldout)
      fits.Say("candidate " + f.estimate.name + ": held-out chi2 " +
               std::to_string(100.0 * f.estimate.heldout_improvement) + " % lower, share of the held-out mismatch " +
               std::to_string(f.estimate.explained_share) + ": " +
               (f.estimate.decision.empty() ? "evaluated" : f.estimate.decision));
    if (f.estimate.decision.empty()) f.estimate.decision = "not the best candidate";
    if (round == 0) out->candidates.push_back(f.estimate);
  }
  if (round == 0) out->candidates.insert(out->candidates.end(), failed.begin(), failed.end());
}

// Step 3: the candidates scored on top of the accepted ones, the best kept if it passes, repeated up to max_effects
// rounds (one round without keeping when max_effects is 0). Returns the state with the accepted effects.
State NameEffects(const internal::TrainingFits& fits, const std::vector<internal::Candidate>& library,
                  const DiagnoseOptions& options, internal::HeldoutEvaluator* heldout, State state, Diagnosis* out) {
  // The located mismatch: the components found inconsistent over the whole run, measured on the held-out part
  // against the nominal model's held-out level (the baseline's).
  const std::map<std::string, double> heldout_levels =
      options.baseline ? options.baseline->heldout_component_levels : std::map<std::string, double>{};
  std::vector<std::string> located_keys;
  for (const LocatedComponent& lc : out->located)
    if (lc.inconsistent) located_keys.push_back(ComponentKey(lc.stream, lc.component));
  const double nominal_heldout_chi2 = state.heldout_chi2;

  std::set<std::string> accepted, dropped;
  for (int round = 0; round < std::max(1, options.max_effects); ++round) {
    std::vector<EffectEstimate> failed;
    std::vector<CandidateFit> candidates = FitRound(fits, library, state, round, options, accepted, &dropped, &failed);
    if (candidates.empty()) {
      if (round == 0) out->candidates = failed;
      break;
    }
    std::sort(candidates.begin(), candidates.end(),
              [](const CandidateFit& a, const CandidateFit& b) { return a.estimate.delta_bic < b.estimate.delta_bic; });
    const internal::RoundRules rules{options, state, located_keys, heldout_levels, nominal_heldout_chi2};
    CandidateFit* kept = internal::DecideRound(rules, round, heldout, &candidates, &dropped);
    RecordRound(fits, round, &candidates, failed, out);
    if (!kept) break;
    accepted.insert(kept->estimate.name);
    out->effects.push_back(kept->estimate);
    fits.Say("accepted " + kept->estimate.name);
    state = kept->next;
  }
  return state;
}

}  // namespace

Result<Diagnosis> Diagnose(const EstimatorConfig& nominal_in, const Recording& recording,
                           const DiagnoseOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  EstimatorConfig nominal = nominal_in;
  nominal.gate_probability.reset();  // the same measurements in every fit
  Diagnosis out;
  auto parts = SplitRecording(nominal, recording, options);
  if (!parts.ok()) return parts.status();
  out.train_end_s = parts.value().split_s;
  const internal::TrainingFits fits{
      nominal,          parts.value().train, internal::MasterPeriod(nominal, recording), options.max_shift_s, &out.fits,
      options.progress, options.std_method};
  out.std_method = estimator::UsesHac(options.std_method, recording) ? "hac" : "white";
  std::vector<internal::Candidate> library = internal::Library(nominal);

  // 1. Replay: the nominal self-calibration of the whole recording, with its residuals.
  if (Status s = Replay(nominal, parts.value().whole, recording, fits, &out); !s.ok()) return s;
  internal::GuessGpsLatency(nominal, out.residuals, out.conditions, &library);

  // 2. Locate: per stream and component, against the baseline's levels when there is one.
  const std::map<std::string, double> levels =
      options.baseline ? options.baseline->component_levels : std::map<std::string, double>{};
  out.located = Locate(out.residuals, out.conditions, levels);

  // 3. Name: the nominal model's training and held-out fits, then the candidates scored and kept round by round.
  internal::HeldoutEvaluator heldout(nominal, parts.value().test, &out.fits);
  auto nominal_state = NominalState(fits, &heldout, &out);
  if (!nominal_state.ok()) return nominal_state.status();
  const State state = NameEffects(fits, library, options, &heldout, nominal_state.value(), &out);
  if (InterruptRequested()) return InterruptedError();

  // 4. Model: the accepted effects' training fit, as parameters and stream time shifts.
  out.training_parameters_after = state.train_values;
  for (const std::string& name : state.extra_free) out.effect_parameters[name] = state.train_values.at(name);
  out.stream_shifts_s = state.shift_s;

  // 5. Show: the held-out part with the accepted effects, against the nominal fit's (out.before).
  out.after = state.heldout;
  out.heldout_components_after = state.heldout_components;

  // The verdict.
  const std::map<std::string, double> heldout_levels =
      options.baseline ? options.baseline->heldout_component_levels : std::map<std::string, double>{};
  internal::Verdict(heldout_levels, &out);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace roamlab::gap
