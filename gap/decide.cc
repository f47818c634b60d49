#include "gap/internal/decide.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "common/chi_square.h"

namespace roamlab::gap {
namespace internal {
namespace {

// Neutral value of an effect parameter (what the nominal model assumes).
double Neutral(const std::string& parameter) {
  return parameter.rfind("scale_", 0) == 0 || parameter.rfind("ratio_", 0) == 0 ? 1.0 : 0.0;
}

// Why a candidate fails the likelihood-ratio test or BIC on the training part ("" when it passes both).
std::string TrainingTestFailure(const EffectEstimate& e, const DiagnoseOptions& options) {
  if (e.lr_pvalue >= options.alpha) return "rejected: likelihood-ratio p above alpha";
  if (e.delta_bic >= options.max_delta_bic) return "rejected: BIC does not favour it";
  return "";
}

// Why a candidate's fitted shift cannot be judged ("" when every shift is within the range): the parts were cut for
// shifts within the search range (Slice), and beyond it shifted fixes leave the poses' span and the held-out
// comparison counts other measurements.
std::string ShiftRangeFailure(const CandidateFit& f, const DiagnoseOptions& options) {
  const auto beyond = std::find_if(f.next.shift_s.begin(), f.next.shift_s.end(),
                                   [&](const auto& shift) { return std::abs(shift.second) > options.max_shift_s; });
  if (beyond == f.next.shift_s.end()) return "";
  std::ostringstream decision;
  decision << "rejected: the fitted shift of " << beyond->first << " (" << beyond->second
           << " s) is beyond the time-shift range +-" << options.max_shift_s << " s (--max-shift)";
  return decision.str();
}

// The candidate's held-out figures: the chi-square drop against the state's, the located excess before and after,
// the share of the mismatch explained.
void RecordHeldout(const RoundRules& rules, const HeldOut& h, EffectEstimate* e) {
  const State& state = rules.state;
  e->evaluated_heldout = true;
  e->heldout_improvement = state.heldout_chi2 > 0.0 ? 1.0 - h.chi2 / state.heldout_chi2 : 0.0;
  e->heldout_excess_before = HeldoutExcess(state.heldout_components, rules.located_keys, rules.heldout_levels);
  e->heldout_excess_after = HeldoutExcess(h.components, rules.located_keys, rules.heldout_levels);
  e->explained_share = ExplainedShare(rules.nominal_heldout_chi2 - h.chi2, e->heldout_excess_after);
}

// Why an evaluated candidate fails the held-out tests ("" when it passes). A decoy's stream stays about as
// inconsistent as before: the effect explains too small a share of the mismatch (a candidate the same structure
// pulls in would not explain more in a later round either).
std::string HeldoutTestFailure(const EffectEstimate& e, const DiagnoseOptions& options) {
  if (e.heldout_improvement <= options.min_heldout_improvement) return "rejected: no improvement on the held-out part";
  if (e.explained_share < options.min_explained_share)
    return "rejected: explains too small a share of the held-out mismatch";
  return "";
}

}  // namespace

void Score(const Baseline* baseline, int measurements, EffectEstimate* e) {
  const double k = e->dof;
  e->lr = e->lr_raw;
  if (baseline && baseline->candidate_parameters.count(e->name)) {
    const auto base = baseline->candidate_parameters.find(e->name);
    if (baseline->candidate_lr.count(e->name)) e->baseline_lr = baseline->candidate_lr.at(e->name);
    double wald = 0.0;
    bool finite = true;
    for (auto& [name, value] : e->parameters) {
      // Parameters without a std are labels (wheel_deformation's wheel index), neither tested nor shifted.
      if (!base->second.count(name) || !e->std.count(name)) continue;
      const auto [theta0, sigma0] = base->second.at(name);
      e->baseline_parameters[name] = theta0;
      const double raw = value;
      const double raw_sigma = e->std.count(name) ? e->std.at(name) : NAN;
      // Reported: the departure from the baseline, both variances.
      value = raw - theta0 + Neutral(name);
      e->std[name] = std::hypot(raw_sigma, sigma0);
      // Tested: against theta_0 when the baseline shows structure (beyond 2 sigma_0 from neutral), else against
      // neutral with the fit's own variance (one noisy draw of nothing would only blur the test).
      const bool structure = std::abs(theta0 - Neutral(name)) > 2.0 * sigma0;
      const double null = structure ? theta0 : Neutral(name);
      const double sigma = structure ? std::hypot(raw_sigma, sigma0) : raw_sigma;
      finite = finite && std::isfinite(sigma) && sigma > 0.0;
      if (finite) wald += std::pow((raw - null) / sigma, 2);
    }
    e->lr = finite ? wald : 0.0;
  }
  e->lr_pvalue = e->lr > 0.0 ? 1.0 - ChiSquareCdf(e->lr, k) : 1.0;
  e->delta_bic = -e->lr + k * std::log(std::max(2, measurements));
}

Result<HeldOut> HeldoutEvaluator::Evaluate(const State& s) {
  FitSpec spec;
  spec.initial = trajectory_.empty() ? nullptr : &trajectory_;
  spec.mode = FitMode::kFixed;
  spec.values = s.train_values;
  spec.shift_s = s.shift_s;
  spec.keep_residuals = true;
  auto fit = Fit(nominal_, test_, spec);
  ++*fits_;
  if (!fit.ok()) return fit.status();
  if (trajectory_.empty()) trajectory_ = fit.value().trajectory;
  return HeldOut{fit.value().chi2, StreamFits(fit.value().residuals), ComponentStatistics(fit.value().residuals)};
}

CandidateFit* DecideRound(const RoundRules& rules, int round, HeldoutEvaluator* heldout,
                          std::vector<CandidateFit>* fits, std::set<std::string>* dropped) {
  const DiagnoseOptions& options = rules.options;
  CandidateFit* kept = nullptr;
  for (CandidateFit& f : *fits) {
    // After the kept one: evaluated for the record only, neither a decision nor a drop for the later rounds.
    const bool extra = kept && options.heldout_all_candidates && round == 0;
    if (options.max_effects <= round || (kept && !extra)) break;
    EffectEstimate& e = f.estimate;
    if (std::string why = TrainingTestFailure(e, options); !why.empty()) {
      e.decision = why;
      continue;
    }
    if (std::string why = ShiftRangeFailure(f, options); !why.empty()) {
      if (extra) continue;
      e.decision = why;
      dropped->insert(e.name);
      continue;
    }
    auto h = heldout->Evaluate(f.next);
    if (!h.ok()) {
      // As a candidate whose training fit fails: rejected, and the diagnosis goes on.
      if (extra) continue;
      e.decision = "rejected: the held-out fit failed: " + h.status().message();
      dropped->insert(e.name);
      continue;
    }
    RecordHeldout(rules, h.value(), &e);
    if (extra) continue;
    if (std::string why = HeldoutTestFailure(e, options); !why.empty()) {
      e.decision = why;
      dropped->insert(e.name);
      continue;
    }
    e.decision = "accepted";
    e.accepted = true;
    f.next.heldout_chi2 = h.value().chi2;
    f.next.heldout = h.value().streams;
    f.next.heldout_components = h.value().components;
    kept = &f;
  }
  return kept;
}

void Verdict(const std::map<std::string, double>& heldout_levels, Diagnosis* out) {
  const LocateOptions locate_options;
  for (const LocatedComponent& lc : out->located) {
    if (!lc.inconsistent) continue;
    const std::string key = ComponentKey(lc.stream, lc.component);
    std::ostringstream line;
    line << key;
    if (!lc.correlates.empty())
      line << " depends on " << lc.correlates.front().condition << " (rho " << lc.correlates.front().rho << ")";
    if (!out->effects.empty()) {
      const auto after = out->heldout_components_after.find(key);
      if (after == out->heldout_components_after.end()) continue;
      const auto level = heldout_levels.find(key);
      const double expected = level != heldout_levels.end() ? level->second : 1.0;
      if (!Inconsistent(after->second, expected, locate_options.inconsistency_ratio) ||
          !SignificantExcess(after->second, expected))
        continue;
      line << "; held-out chi2/dof " << after->second.chi2_per_dof << " with the named effects (level " << expected
           << ")";
    }
    out->unexplained.push_back(line.str());
  }
  out->verdict = out->unexplained.empty() ? (out->effects.empty() ? "none" : "named") : "unknown";
}

}  // namespace internal

double HeldoutExcess(const std::map<std::string, ComponentLevel>& components, const std::vector<std::string>& keys,
                     const std::map<std::string, double>& expected) {
  double excess = 0.0;
  for (const std::string& key : keys) {
    const auto c = components.find(key);
    if (c == components.end()) continue;
    const auto level = expected.find(key);
    const double nominal = level != expected.end() ? level->second : 1.0;
    excess += std::max(0.0, (c->second.chi2_per_dof - nominal) * c->second.count);
  }
  return excess;
}

double ExplainedShare(double heldout_drop, double remaining_excess) {
  if (!(heldout_drop > 0.0)) return 0.0;
  return heldout_drop / (heldout_drop + std::max(0.0, remaining_excess));
}

Baseline BaselineFrom(const Diagnosis& nominal_simulation) {
  Baseline b;
  b.component_levels = ComponentLevels(nominal_simulation.residuals);
  for (const auto& [key, level] : nominal_simulation.heldout_components_before)
    b.heldout_component_levels[key] = level.chi2_per_dof;
  b.streams = nominal_simulation.whole_run;
  for (const EffectEstimate& e : nominal_simulation.candidates) {
    b.candidate_lr[e.name] = e.lr_raw;
    for (const auto& [name, value] : e.parameters)
      b.candidate_parameters[e.name][name] = {value, e.std.count(name) ? e.std.at(name) : 0.0};
  }
  return b;
}

}  // namespace roamlab::gap
