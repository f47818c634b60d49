#include "gap/benchmark/score.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

#include "common/json.h"

namespace roamlab::gap::benchmark {
namespace {

using nlohmann::json;

constexpr double kAlphas[] = {1e-2, 1e-3, 1e-4, 1e-6};
constexpr double kDeltaBics[] = {0.0, -10.0, -30.0, -100.0};
constexpr double kHeldouts[] = {0.0, 0.01, 0.03};
constexpr double kShares[] = {0.0, 0.1, kDefaultMinExplainedShare, 0.5};

double Median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// A fraction as JSON (null when there is nothing to count).
json Fraction(int k, int n) { return n > 0 ? json(static_cast<double>(k) / n) : json(nullptr); }
// Index of x in a grid array (exact values from the same array).
template <std::size_t N>
int IndexOf(const double (&grid)[N], double x) {
  for (std::size_t i = 0; i < N; ++i)
    if (grid[i] == x) return static_cast<int>(i);
  return 0;
}

json Target(const json& value, double target, bool at_least) {
  json t = {{"value", value}, {"target", target}, {"comparison", at_least ? ">=" : "<="}};
  t["met"] = value.is_number() && (at_least ? value.get<double>() >= target : value.get<double>() <= target);
  return t;
}

}  // namespace

double NeutralValue(const std::string& parameter) {
  return parameter.rfind("scale_", 0) == 0 || parameter.rfind("ratio_", 0) == 0 ? 1.0 : 0.0;
}

std::string ReplayFirstRound(std::vector<CandidateStats> candidates, const Thresholds& t) {
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const CandidateStats& a, const CandidateStats& b) { return a.delta_bic < b.delta_bic; });
  for (const CandidateStats& c : candidates) {
    if (!(c.lr_pvalue < t.alpha) || !(c.delta_bic < t.max_delta_bic)) continue;
    if (!c.evaluated_heldout || !(c.heldout_improvement > t.min_heldout_improvement)) continue;
    if (!std::isfinite(c.explained_share) || c.explained_share >= t.min_explained_share) return c.name;
  }
  return "";
}

bool Identified(const CaseResult& c, const std::string& first_kept) {
  return c.kind == "effect" && !first_kept.empty() && first_kept == c.truth_name;
}

bool FalseDiscovery(const CaseResult& c, const std::string& first_kept) {
  return c.kind != "effect" && !first_kept.empty();
}

std::string FirstKept(const CaseResult& c) { return c.named.empty() ? "" : c.named.front(); }

bool ReplayCorrect(const CaseResult& c, const std::string& kept) {
  return c.kind == "effect" ? Identified(c, kept) : !FalseDiscovery(c, kept);
}

std::string CalibrationKind(int index) {
  const int stratum = index % 4;
  return stratum == 0 ? "none" : stratum == 1 ? "decoy" : "effect";
}

std::vector<Thresholds> ThresholdGrid() {
  std::vector<Thresholds> grid;
  for (double a : kAlphas)
    for (double b : kDeltaBics)
      for (double h : kHeldouts)
        for (double f : kShares) grid.push_back({a, b, h, f});
  return grid;
}

Thresholds Loosest() { return {kAlphas[0], kDeltaBics[0], kHeldouts[0], kShares[0]}; }

Thresholds ChooseThresholds(const std::vector<CaseResult>& calibration, double max_none_false_rate,
                            double max_decoy_false_rate, json* table) {
  // Distance from diagnose's defaults (1e-3, 0, 0, the default share) in grid steps: ties go to the point that
  // departs least from them, then to the stricter alpha and Delta BIC.
  const Thresholds defaults;
  const auto distance = [&](const Thresholds& t) {
    return std::abs(IndexOf(kAlphas, t.alpha) - IndexOf(kAlphas, defaults.alpha)) +
           IndexOf(kDeltaBics, t.max_delta_bic) + IndexOf(kHeldouts, t.min_heldout_improvement) +
           std::abs(IndexOf(kShares, t.min_explained_share) - IndexOf(kShares, defaults.min_explained_share));
  };
  struct Point {
    Thresholds t;
    int correct = 0, none_false = 0, nones = 0, decoy_false = 0, decoys = 0;
    bool feasible = true;
  };
  const auto within = [](int k, int n, double rate) { return n == 0 || k <= rate * n + 1e-9; };
  std::vector<Point> points;
  for (const Thresholds& t : ThresholdGrid()) {
    Point p{t};
    for (const CaseResult& c : calibration) {
      const std::string kept = ReplayFirstRound(c.candidates, t);
      p.correct += ReplayCorrect(c, kept);
      if (c.kind == "none") {
        ++p.nones;
        p.none_false += FalseDiscovery(c, kept);
      } else if (c.kind == "decoy") {
        ++p.decoys;
        p.decoy_false += FalseDiscovery(c, kept);
      }
    }
    p.feasible =
        within(p.none_false, p.nones, max_none_false_rate) && within(p.decoy_false, p.decoys, max_decoy_false_rate);
    points.push_back(p);
  }
  const bool any_feasible = std::any_of(points.begin(), points.end(), [](const Point& p) { return p.feasible; });
  const auto key = [&](const Point& p) {
    return std::make_tuple(!(p.feasible || !any_feasible), -p.correct, distance(p.t), p.t.alpha, p.t.max_delta_bic);
  };
  const Point& best =
      *std::min_element(points.begin(), points.end(), [&](const Point& a, const Point& b) { return key(a) < key(b); });
  if (table) {
    *table = json::array();
    for (const Point& p : points)
      table->push_back({{"alpha", p.t.alpha},
                        {"max_delta_bic", p.t.max_delta_bic},
                        {"min_heldout_improvement", p.t.min_heldout_improvement},
                        {"min_explained_share", p.t.min_explained_share},
                        {"correct", p.correct},
                        {"none_false_discoveries", p.none_false},
                        {"none_cases", p.nones},
                        {"decoy_false_discoveries", p.decoy_false},
                        {"decoy_cases", p.decoys},
                        {"feasible", p.feasible}});
  }
  return best.t;
}

std::map<std::string, std::map<std::string, double>> CalibrationSigmas(const std::vector<CaseResult>& calibration) {
  std::map<std::string, std::map<std::string, std::vector<double>>> samples;
  for (const CaseResult& c : calibration)
    for (const CandidateStats& cand : c.candidates)
      for (const auto& [parameter, sigma] : cand.std)
        if (std::isfinite(sigma) && sigma > 0.0) samples[c.platform][cand.name + "/" + parameter].push_back(sigma);
  std::map<std::string, std::map<std::string, double>> out;
  for (const auto& [platform, by_parameter] : samples)
    for (const auto& [key, v] : by_parameter) out[platform][key] = Median(v);
  return out;
}

double NoiseRatio(const std::map<std::string, std::map<std::string, double>>& sigmas, const std::string& platform,
                  const std::string& effect, const std::string& parameter, double value) {
  const auto p = sigmas.find(platform);
  if (p == sigmas.end()) return -1.0;
  const auto s = p->second.find(effect + "/" + parameter);
  if (s == p->second.end() || !(s->second > 0.0)) return -1.0;
  return std::abs(value - NeutralValue(parameter)) / s->second;
}

double RearCorneringCompliance(const Trajectory& truth) {
  std::vector<Eigen::Vector3d> rows;
  std::vector<double> v_y;
  for (std::size_t k = 0; k + 1 < truth.size(); ++k) {
    const double t0 = SecondsBetween(truth.front().t, truth[k].t);
    const double dt = SecondsBetween(truth[k].t, truth[k + 1].t);
    if (t0 < 2.0 || !(dt > 0.0)) continue;
    const Eigen::AngleAxisd turn(truth[k].q_world_body.conjugate() * truth[k + 1].q_world_body);
    const Eigen::Vector3d omega = turn.angle() * turn.axis() / dt;
    const Eigen::Quaterniond q_mid =
        truth[k].q_world_body * Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * turn.angle(), turn.axis()));
    const Eigen::Vector3d v = q_mid.conjugate() * (truth[k + 1].p_world_body - truth[k].p_world_body) / dt;
    if (v.x() < 0.5) continue;
    rows.emplace_back(1.0, v.x() * omega.z(), omega.x());
    v_y.push_back(v.y());
  }
  if (rows.size() < 10) return std::numeric_limits<double>::quiet_NaN();
  Eigen::MatrixXd X(static_cast<Eigen::Index>(rows.size()), 3);
  Eigen::VectorXd y(static_cast<Eigen::Index>(rows.size()));
  for (std::size_t i = 0; i < rows.size(); ++i) {
    X.row(static_cast<Eigen::Index>(i)) = rows[i].transpose();
    y[static_cast<Eigen::Index>(i)] = v_y[i];
  }
  return -X.colPivHouseholderQr().solve(y)[1];
}

namespace {

// The counts and per-case figures Summarize reduces.
struct Tally {
  int effects = 0, top1 = 0, top3 = 0, strong = 0, strong_top1 = 0, strong_top3 = 0;
  int nones = 0, none_false = 0, none_none = 0, decoys = 0, decoy_false = 0, decoy_unknown = 0, decoy_unknown_any = 0;
  int top1_unknown = 0;
  std::vector<double> relative_error, rms_named, rms_all, rms_1s_named, rms_1s_all, sim_named, sim_all, sim_1s_named,
      sim_1s_all;
  // The top-1 cases split by whether the simulation as believed misses the stream by more than its sample noise
  // (per-sample RMS >= sqrt(2): the effect's trace at least the noise): below it, per-sample reductions are small
  // whatever the model does.
  std::vector<double> sim_above, rms_above, sim_below, rms_below;
  std::map<std::string, std::pair<int, int>> by_effect;  // name -> (top-1 correct, cases)
};

// 1 - after / before into `all`, and into `named` when the case's effect was identified (`first`).
void AddReduction(double before, double after, bool first, std::vector<double>* all, std::vector<double>* named) {
  const double reduction = 1.0 - after / before;
  all->push_back(reduction);
  if (first) named->push_back(reduction);
}

// An effect case's RMS reductions (held-out fit and re-simulation, per sample and of the 1 s means); `first`: its
// effect was identified.
void CountReductions(const CaseResult& c, bool first, Tally* t) {
  if (c.has_rms && c.rms_before > 0.0) AddReduction(c.rms_before, c.rms_after, first, &t->rms_all, &t->rms_named);
  if (c.has_sim_rms && c.sim_rms_before > 0.0) {
    AddReduction(c.sim_rms_before, c.sim_rms_after, first, &t->sim_all, &t->sim_named);
    const bool above = c.sim_rms_before >= std::sqrt(2.0);
    if (first) (above ? t->sim_above : t->sim_below).push_back(1.0 - c.sim_rms_after / c.sim_rms_before);
    if (first && c.has_rms && c.rms_before > 0.0)
      (above ? t->rms_above : t->rms_below).push_back(1.0 - c.rms_after / c.rms_before);
  }
  if (c.has_sim_rms && c.sim_rms_1s_before > 0.0)
    AddReduction(c.sim_rms_1s_before, c.sim_rms_1s_after, first, &t->sim_1s_all, &t->sim_1s_named);
  if (c.has_rms && c.rms_1s_before > 0.0)
    AddReduction(c.rms_1s_before, c.rms_1s_after, first, &t->rms_1s_all, &t->rms_1s_named);
}

void Count(const CaseResult& c, double min_noise_ratio, Tally* t) {
  const std::string kept = FirstKept(c);
  if (c.kind == "none") {
    ++t->nones;
    t->none_false += FalseDiscovery(c, kept);
    t->none_none += c.verdict == "none";
    return;
  }
  if (c.kind == "decoy") {
    ++t->decoys;
    t->decoy_false += FalseDiscovery(c, kept);
    t->decoy_unknown += c.verdict == "unknown" && !FalseDiscovery(c, kept);
    t->decoy_unknown_any += c.verdict == "unknown";
    return;
  }
  ++t->effects;
  const bool first = Identified(c, kept);
  const auto end3 = c.ranked.begin() + static_cast<std::ptrdiff_t>(std::min<std::size_t>(3, c.ranked.size()));
  const bool in3 = !kept.empty() && std::find(c.ranked.begin(), end3, c.truth_name) != end3;
  t->top1 += first;
  t->top1_unknown += first && c.verdict == "unknown";
  t->top3 += in3;
  ++t->by_effect[c.truth_name].second;
  t->by_effect[c.truth_name].first += first;
  if (c.noise_ratio >= min_noise_ratio) {
    ++t->strong;
    t->strong_top1 += first;
    t->strong_top3 += in3;
  }
  // Relative to the effect's size (its departure from neutral), so that a scale of 1.03 estimated as 1.02 is a
  // 33 % error, not 1 %.
  const double size = std::abs(c.truth_value - NeutralValue(c.truth_parameter));
  if (first && c.has_estimate && size > 0.0) t->relative_error.push_back(std::abs(c.estimate - c.truth_value) / size);
  CountReductions(c, first, t);
}

}  // namespace

json Summarize(const std::vector<CaseResult>& cases, double min_noise_ratio) {
  Tally t;
  for (const CaseResult& c : cases) Count(c, min_noise_ratio, &t);
  json per_effect = json::object();
  for (const auto& [name, k] : t.by_effect) per_effect[name] = {{"top1", k.first}, {"cases", k.second}};
  const json top1_strong = Fraction(t.strong_top1, t.strong);
  const json false_rate = Fraction(t.none_false, t.nones);
  const json unknown_rate = Fraction(t.decoy_unknown, t.decoys);
  const json rel = Number(Median(t.relative_error));
  const json rms = Number(Median(t.rms_named));
  const json rms_1s = Number(Median(t.rms_1s_named));
  const json sim = Number(Median(t.sim_named));
  const json sim_1s = Number(Median(t.sim_1s_named));
  json figures = {{"effect_cases", t.effects},
                  {"top1", Fraction(t.top1, t.effects)},
                  {"top3", Fraction(t.top3, t.effects)},
                  {"top1_with_verdict_unknown", t.top1_unknown},
                  {"min_noise_ratio", min_noise_ratio},
                  {"strong_effect_cases", t.strong},
                  {"top1_strong", top1_strong},
                  {"top3_strong", Fraction(t.strong_top3, t.strong)},
                  {"by_effect", per_effect},
                  {"none_cases", t.nones},
                  {"false_discovery_rate", false_rate},
                  {"none_reported_none", Fraction(t.none_none, t.nones)},
                  {"decoy_cases", t.decoys},
                  {"decoys_unknown", unknown_rate},
                  {"decoy_false_discovery_rate", Fraction(t.decoy_false, t.decoys)},
                  {"decoys_unknown_effect_kept_or_not", Fraction(t.decoy_unknown_any, t.decoys)},
                  {"median_parameter_relative_error", rel},
                  {"parameter_errors", t.relative_error.size()},
                  {"median_heldout_rms_reduction", rms},
                  {"median_heldout_rms_reduction_all_effect_cases", Number(Median(t.rms_all))},
                  {"median_heldout_rms_1s_reduction", rms_1s},
                  {"median_heldout_rms_1s_reduction_all_effect_cases", Number(Median(t.rms_1s_all))},
                  {"median_resimulated_rms_reduction", sim},
                  {"median_resimulated_rms_reduction_all_effect_cases", Number(Median(t.sim_all))},
                  {"median_resimulated_rms_1s_reduction", sim_1s},
                  {"median_resimulated_rms_1s_reduction_all_effect_cases", Number(Median(t.sim_1s_all))},
                  {"above_noise",
                   {{"cases", t.sim_above.size()},
                    {"median_resimulated_rms_reduction", Number(Median(t.sim_above))},
                    {"median_heldout_rms_reduction", Number(Median(t.rms_above))}}},
                  {"below_noise",
                   {{"cases", t.sim_below.size()},
                    {"median_resimulated_rms_reduction", Number(Median(t.sim_below))},
                    {"median_heldout_rms_reduction", Number(Median(t.rms_below))}}},
                  {"targets",
                   {{"top1_strong", Target(top1_strong, 0.85, true)},
                    {"false_discovery_rate", Target(false_rate, kMaxNoneFalseRate, false)},
                    {"decoys_unknown", Target(unknown_rate, kMinDecoysUnknown, true)},
                    {"median_parameter_relative_error", Target(rel, 0.15, false)},
                    {"median_heldout_rms_reduction", Target(rms, 0.30, true)},
                    {"median_heldout_rms_1s_reduction", Target(rms_1s, 0.30, true)},
                    {"median_resimulated_rms_reduction", Target(sim, 0.30, true)},
                    {"median_resimulated_rms_1s_reduction", Target(sim_1s, 0.30, true)}}}};
  std::vector<CaseResult> own, other;
  for (const CaseResult& c : cases) (c.other_drive ? other : own).push_back(c);
  if (own.empty() || other.empty()) return figures;
  const auto replayed = [](const std::vector<CaseResult>& v) {
    return static_cast<int>(std::count_if(v.begin(), v.end(), [](const CaseResult& c) { return c.replayed; }));
  };
  figures["drive"] = {{"own_cases", own.size()},
                      {"own_replayed", replayed(own)},
                      {"other_cases", other.size()},
                      {"other_replayed", replayed(other)}};
  figures["by_drive"] = {{"own", Summarize(own, min_noise_ratio)}, {"other", Summarize(other, min_noise_ratio)}};
  return figures;
}

json CaseRow(const CaseResult& c) {
  json candidates = json::array();
  for (const CandidateStats& s : c.candidates) {
    json stds = json::object();
    for (const auto& [k, v] : s.std) stds[k] = Number(v);
    candidates.push_back({{"name", s.name},
                          {"lr_pvalue", s.lr_pvalue},
                          {"delta_bic", s.delta_bic},
                          {"evaluated_heldout", s.evaluated_heldout},
                          {"heldout_improvement", s.heldout_improvement},
                          {"explained_share", Number(s.explained_share)},
                          {"std", stds}});
  }
  return {{"case", c.id},
          {"platform", c.platform},
          {"kind", c.kind},
          {"truth", {{"name", c.truth_name}, {"parameter", c.truth_parameter}, {"value", c.truth_value}}},
          {"noise_ratio", c.noise_ratio >= 0.0 ? json(c.noise_ratio) : json(nullptr)},
          {"verdict", c.verdict},
          {"named", c.named},
          {"ranked", c.ranked},
          {"estimate", c.has_estimate ? json(c.estimate) : json(nullptr)},
          {"heldout_rms_before", c.has_rms ? json(c.rms_before) : json(nullptr)},
          {"heldout_rms_after", c.has_rms ? json(c.rms_after) : json(nullptr)},
          {"heldout_rms_1s_before", c.has_rms ? json(c.rms_1s_before) : json(nullptr)},
          {"heldout_rms_1s_after", c.has_rms ? json(c.rms_1s_after) : json(nullptr)},
          {"resimulated_stream", c.has_sim_rms ? json(c.sim_stream) : json(nullptr)},
          {"resimulated_rms_before", c.has_sim_rms ? json(c.sim_rms_before) : json(nullptr)},
          {"resimulated_rms_after", c.has_sim_rms ? json(c.sim_rms_after) : json(nullptr)},
          {"resimulated_rms_1s_before", c.has_sim_rms ? json(c.sim_rms_1s_before) : json(nullptr)},
          {"resimulated_rms_1s_after", c.has_sim_rms ? json(c.sim_rms_1s_after) : json(nullptr)},
          {"candidates", candidates},
          {"other_drive", c.other_drive},
          {"replayed", c.replayed},
          {"seconds", c.seconds}};
}

namespace {

// Readers of a case row that never throw: each answers false when the key is missing or of another type. A null
// number reads as NaN (Number writes what is not finite as null).
bool Get(const json& j, const char* key, std::string* out) {
  const auto it = j.find(key);
  if (it == j.end() || !it->is_string()) return false;
  *out = it->get<std::string>();
  return true;
}
bool Get(const json& j, const char* key, bool* out) {
  const auto it = j.find(key);
  if (it == j.end() || !it->is_boolean()) return false;
  *out = it->get<bool>();
  return true;
}

bool Get(const json& j, const char* key, double* out) {
  const auto it = j.find(key);
  if (it == j.end() || !(it->is_number() || it->is_null())) return false;
  *out = it->is_null() ? std::numeric_limits<double>::quiet_NaN() : it->get<double>();
  return true;
}
bool Get(const json& j, const char* key, std::vector<std::string>* out) {
  const auto it = j.find(key);
  if (it == j.end() || !it->is_array()) return false;
  for (const json& e : *it) {
    if (!e.is_string()) return false;
    out->push_back(e.get<std::string>());
  }
  return true;
}
// An optional number: *has false when null.
bool GetOptional(const json& j, const char* key, double* out, bool* has) {
  const auto it = j.find(key);
  if (it == j.end() || !(it->is_number() || it->is_null())) return false;
  *has = it->is_number();
  if (*has) *out = it->get<double>();
  return true;
}

bool ReadCandidate(const json& j, CandidateStats* s) {
  const auto evaluated = j.find("evaluated_heldout");
  const auto stds = j.find("std");
  if (!j.is_object() || evaluated == j.end() || !evaluated->is_boolean() || stds == j.end() || !stds->is_object())
    return false;
  s->evaluated_heldout = evaluated->get<bool>();
  for (const auto& [key, value] : stds->items()) {
    if (!value.is_number() && !value.is_null()) return false;
    s->std[key] = value.is_null() ? std::numeric_limits<double>::quiet_NaN() : value.get<double>();
  }
  return Get(j, "name", &s->name) && Get(j, "lr_pvalue", &s->lr_pvalue) && Get(j, "delta_bic", &s->delta_bic) &&
         Get(j, "heldout_improvement", &s->heldout_improvement) && Get(j, "explained_share", &s->explained_share);
}

// The held-out and re-simulation figures of a case row.
bool ReadFits(const json& j, CaseResult* c) {
  bool has_after = false, has_1s = false, has_1s_after = false, sim_after = false, sim_1s = false, sim_1s_after = false;
  const auto stream = j.find("resimulated_stream");
  if (stream == j.end() || !(stream->is_string() || stream->is_null())) return false;
  c->has_sim_rms = stream->is_string();
  if (c->has_sim_rms) c->sim_stream = stream->get<std::string>();
  bool has_sim_before = false;
  return GetOptional(j, "heldout_rms_before", &c->rms_before, &c->has_rms) &&
         GetOptional(j, "heldout_rms_after", &c->rms_after, &has_after) &&
         GetOptional(j, "heldout_rms_1s_before", &c->rms_1s_before, &has_1s) &&
         GetOptional(j, "heldout_rms_1s_after", &c->rms_1s_after, &has_1s_after) &&
         GetOptional(j, "resimulated_rms_before", &c->sim_rms_before, &has_sim_before) &&
         GetOptional(j, "resimulated_rms_after", &c->sim_rms_after, &sim_after) &&
         GetOptional(j, "resimulated_rms_1s_before", &c->sim_rms_1s_before, &sim_1s) &&
         GetOptional(j, "resimulated_rms_1s_after", &c->sim_rms_1s_after, &sim_1s_after);
}

}  // namespace

Result<CaseResult> CaseFromRow(const json& j) {
  CaseResult c;
  const auto truth = j.is_object() ? j.find("truth") : j.end();
  const auto candidates = j.is_object() ? j.find("candidates") : j.end();
  bool ok = truth != j.end() && truth->is_object() && candidates != j.end() && candidates->is_array();
  double noise_ratio = -1.0;
  bool has_noise_ratio = false;
  ok = ok && Get(j, "case", &c.id) && Get(j, "platform", &c.platform) && Get(j, "kind", &c.kind) &&
       Get(*truth, "name", &c.truth_name) && Get(*truth, "parameter", &c.truth_parameter) &&
       Get(*truth, "value", &c.truth_value) && GetOptional(j, "noise_ratio", &noise_ratio, &has_noise_ratio) &&
       Get(j, "verdict", &c.verdict) && Get(j, "named", &c.named) && Get(j, "ranked", &c.ranked) &&
       GetOptional(j, "estimate", &c.estimate, &c.has_estimate) && ReadFits(j, &c) &&
       Get(j, "other_drive", &c.other_drive) && Get(j, "replayed", &c.replayed) && Get(j, "seconds", &c.seconds);
  if (!ok) return Status::Error("not a case row as CaseRow writes it");
  c.noise_ratio = has_noise_ratio ? noise_ratio : -1.0;
  for (const json& candidate : *candidates) {
    CandidateStats s;
    if (!ReadCandidate(candidate, &s)) return Status::Error("a candidate is not as CaseRow writes it");
    c.candidates.push_back(std::move(s));
  }
  return c;
}

}  // namespace roamlab::gap::benchmark
