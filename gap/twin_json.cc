// TwinDiagnosisJson (gap/twin.h).
#include "common/json.h"
#include "gap/twin.h"

namespace roamlab::gap {
namespace {

nlohmann::json StreamsJson(const std::map<std::string, SimulatedStreamFit>& streams) {
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [name, f] : streams)
    out[name] = {{"rms", Number(f.rms)},
                 {"rms_1s", Number(f.rms_1s)},
                 {"component_rms", NumberArray(f.component_rms)},
                 {"samples", f.samples}};
  return out;
}

nlohmann::json ComparisonJson(const TwinComparison& c) {
  return {{"from_s", c.from_s},
          {"to_s", c.to_s},
          {"increment_window_s", c.increment_window_s},
          {"chi2", Number(c.chi2)},
          {"residuals", c.residuals},
          {"streams", StreamsJson(c.streams)},
          {"drift", TwinDriftJson(c.drift)},
          {"left_out", c.left_out}};
}

nlohmann::json EffectJson(const TwinEffect& e) {
  const EffectEstimate& x = e.estimate;
  nlohmann::json parameters = nlohmann::json::object(), applied = nlohmann::json::array();
  for (const auto& [name, value] : x.parameters) parameters[name] = Number(value);
  const auto numbers = [](const std::map<std::string, double>& values) {
    nlohmann::json out = nlohmann::json::object();
    for (const auto& [name, value] : values) out[name] = Number(value);
    return out;
  };
  for (const sim::EffectOptions& effect : e.applied)
    applied.push_back({{"name", effect.name}, {"parameters", numbers(effect.parameters)}});
  return {{"name", x.name},
          {"effect", applied},
          {"dof", x.dof},
          {"parameters", parameters},
          {"std", numbers(x.std)},
          {"std_white", numbers(e.std_white)},
          {"std_hac", numbers(e.std_hac)},
          {"std_batch", numbers(e.std_batch)},
          {"not_informed", e.not_informed},
          {"hac_lags", e.hac_lags},
          {"chi2_before", Number(e.chi2_before)},
          {"chi2_after", Number(e.chi2_after)},
          {"refitted_with_kept", e.refitted},
          {"lr", Number(x.lr)},
          {"p", Number(x.lr_pvalue)},
          {"delta_bic", Number(x.delta_bic)},
          {"heldout_improvement", x.evaluated_heldout ? Number(x.heldout_improvement) : nlohmann::json()},
          {"accepted", x.accepted},
          {"decision", x.decision},
          {"iterations", e.iterations},
          {"runs", e.runs}};
}

// Null when no joint fit was made; each effect as EffectJson without the naming's scores and std_batch (time shifts
// are not refitted jointly), with std_white_conditional.
nlohmann::json JointJson(const TwinJointFit& j) {
  if (j.effects.empty() && j.failed.empty()) return nullptr;
  nlohmann::json effects = nlohmann::json::array();
  for (std::size_t i = 0; i < j.effects.size(); ++i) {
    nlohmann::json x = EffectJson(j.effects[i]);
    for (const char* key :
         {"lr", "p", "delta_bic", "heldout_improvement", "accepted", "std_batch", "refitted_with_kept"})
      x.erase(key);
    x["std_white_conditional"] = nlohmann::json::object();
    if (i < j.std_white_conditional.size())
      for (const auto& [name, value] : j.std_white_conditional[i]) x["std_white_conditional"][name] = Number(value);
    effects.push_back(x);
  }
  return {{"effects", effects},
          {"held", j.held},
          {"failed", j.failed},
          {"chi2_before", Number(j.chi2_before)},
          {"chi2_after", Number(j.chi2_after)},
          {"iterations", j.iterations},
          {"runs", j.runs}};
}

}  // namespace

nlohmann::json TwinDriftJson(const std::map<std::string, TwinDrift>& drift) {
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [name, d] : drift) {
    out[name] = {{"window_s", d.window_s},
                 {"windows", d.windows},
                 {"mean_position_m", Number(d.mean_position_m)},
                 {"max_position_m", Number(d.max_position_m)}};
    if (d.heading_measured) {
      out[name]["mean_heading_rad"] = Number(d.mean_heading_rad);
      out[name]["max_heading_rad"] = Number(d.max_heading_rad);
    }
  }
  return out;
}

nlohmann::json TwinDiagnosisJson(const TwinDiagnosis& d) {
  nlohmann::json located = nlohmann::json::array();
  for (const LocatedComponent& c : d.located) {
    nlohmann::json intervals = nlohmann::json::array(), correlates = nlohmann::json::array();
    for (const auto& [t0, t1] : c.intervals) intervals.push_back({t0, t1});
    for (const Correlate& k : c.correlates)
      correlates.push_back({{"condition", k.condition}, {"rho", Number(k.rho)}, {"lag_s", k.lag_s}});
    located.push_back({{"stream", c.stream},
                       {"component", c.component},
                       {"count", c.count},
                       {"chi2_per_dof", Number(c.chi2_per_dof)},
                       {"inconsistent", c.inconsistent},
                       {"intervals", intervals},
                       {"correlates", correlates}});
  }
  nlohmann::json candidates = nlohmann::json::array(), effects = nlohmann::json::array(),
                 patch = nlohmann::json::array();
  for (const TwinEffect& e : d.candidates) candidates.push_back(EffectJson(e));
  nlohmann::json rounds = nlohmann::json::array();
  for (const std::vector<TwinEffect>& round : d.rounds) {
    rounds.push_back(nlohmann::json::array());
    for (const TwinEffect& e : round) rounds.back().push_back(EffectJson(e));
  }
  for (const TwinEffect& e : d.effects) effects.push_back(EffectJson(e));
  for (const sim::EffectOptions& e : d.patch) patch.push_back({{"name", e.name}, {"parameters", e.parameters}});
  nlohmann::json heldout_runs = nlohmann::json::array();
  for (const TwinHeldOutRun& h : d.heldout_runs)
    heldout_runs.push_back({{"recording", h.recording},
                            {"replayed", h.replayed},
                            {"before", ComparisonJson(h.before)},
                            {"after", ComparisonJson(h.after)}});
  nlohmann::json out = {
      {"replayed", d.replayed},
      {"verdict", d.verdict},
      {"std_method", d.std_method},
      {"train_end_s", d.train_end_s},
      {"located", located},
      {"candidates", candidates},
      {"rounds", rounds},
      {"effects", effects},
      {"joint", JointJson(d.joint)},
      {"unexplained", d.unexplained},
      {"heldout", {{"before", ComparisonJson(d.heldout_before)}, {"after", ComparisonJson(d.heldout_after)}}},
      {"whole_run", ComparisonJson(d.whole_run)},
      {"patch", patch},
      {"heldout_runs", heldout_runs},
      {"increment_window_s", d.increment_window_s},
      {"train_weight", d.train_weight},
      {"run_weights", d.run_weights},
      {"runs", d.runs},
      {"seconds", d.seconds}};
  if (d.training_runs.empty()) return out;
  out["training_runs"] = nlohmann::json::array();
  for (const TwinTrainingFigures& t : d.training_runs)
    out["training_runs"].push_back(
        {{"recording", t.recording},
         {"replayed", t.replayed},
         {"train_end_s", t.train_end_s},
         {"heldout", {{"before", ComparisonJson(t.heldout_before)}, {"after", ComparisonJson(t.heldout_after)}}}});
  return out;
}

}  // namespace roamlab::gap
