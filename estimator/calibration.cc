#include "estimator/calibration.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <utility>

#include "common/chi_square.h"
#include "common/interrupt.h"
#include "estimator/factor.h"
#include "estimator/geometry.h"
#include "estimator/internal/after_gap.h"
#include "estimator/internal/linearization.h"
#include "estimator/internal/normal_equations.h"
#include "estimator/models/prior.h"

namespace roamlab::estimator {

namespace {

struct GateRow {
  FactorId id;
  bool was_active;
  bool pass;  // within the quantile
};

// Marks, in one stream's rows in time order, the active rows that pass the test but lie next to a burst of failing
// rows (GateOptions::burst_margin).
void RejectAroundBursts(const std::vector<GateRow>& rows, double margin, std::vector<char>* reject) {
  constexpr int kMaxGapRows = 10;  // failing rows this close belong to one burst
  constexpr int kMinFailing = 3;   // fewer are single outliers, tested alone
  const int n = static_cast<int>(rows.size());
  for (int first = 0; first < n;) {
    if (rows[first].pass) {
      ++first;
      continue;
    }
    int last = first;
    int failing = 1;
    bool newly = rows[first].was_active;
    for (int k = first + 1; k < n && k - last <= kMaxGapRows; ++k) {
      if (rows[k].pass) continue;
      last = k;
      ++failing;
      newly |= rows[k].was_active;
    }
    // A burst is dense: at least half its rows fail (a skid). Outliers scattered at random (one row in ten) come within
    // kMaxGapRows of each other all along a stream; as one burst, their margin would take the whole stream out.
    if (newly && failing >= kMinFailing && 2 * failing >= last - first + 1) {
      const int m = static_cast<int>(margin * (last - first + 1));
      for (int k = std::max(0, first - m); k <= std::min(n - 1, last + m); ++k)
        if (rows[k].pass && rows[k].was_active) (*reject)[k] = 1;
    }
    first = last + 1;
  }
}

// An active factor that fails the gate, with its squared error over the quantile of its dimension.
struct FailingFactor {
  FactorId id;
  double excess;
};

// Of `failing`, those that fail worst at every pose they join (GateOptions::worst_per_pose).
std::vector<FactorId> WorstPerPose(const std::vector<FailingFactor>& failing, const Graph& graph,
                                   const std::deque<PoseNode>& poses) {
  std::set<VariableId> pose_ids;
  for (const PoseNode& p : poses) pose_ids.insert(p.id);
  std::map<VariableId, double> worst;
  for (const FailingFactor& f : failing)
    for (VariableId v : graph.factor(f.id).variables)
      if (pose_ids.count(v) > 0) worst[v] = std::max(worst[v], f.excess);
  std::vector<FactorId> out;
  for (const FailingFactor& f : failing) {
    const std::vector<VariableId>& vars = graph.factor(f.id).variables;
    if (std::all_of(vars.begin(), vars.end(),
                    [&](VariableId v) { return pose_ids.count(v) == 0 || worst[v] <= f.excess; }))
      out.push_back(f.id);
  }
  return out;
}

// One measurement factor as a gating pass tested it.
struct TestedFactor {
  FactorId id;
  int stream;
  bool active;
  bool pass;            // within the quantile
  double squared_norm;  // its whitened squared error (infinite where it could not be evaluated)
  int dim;
};

// A bridge leaves out at most this many consecutive readings: one outlying reading fails the two spans it joins, two
// consecutive ones three spans.
constexpr std::size_t kMaxBridgedReadings = 3;

// Bridges over the spikes at the ends of the failing spans (not bridges) of cumulative wheel streams
// (ProblemBuilder::IsCumulativeSpike, read up to each stream's newest span): groups of up to kMaxBridgedReadings
// consecutive spiking readings, each left out by a bridge whether or not it passes the test at the current estimate.
// Where two outlying readings lie a row or two apart the estimate can follow them (the reading between them bent
// instead), so that at that estimate the bridges over the outliers fail and those over their good neighbours pass;
// the readings alone tell them apart.
// Removes the spans bridged from *by_row and adds them to *bridged, the readings left out to *readings and each
// bridged run to *runs.
void BridgeSpikes(const std::map<FactorId, bool>& failing_now, const std::function<double(int)>& threshold,
                  const std::map<int, FactorId>& newest, ProblemBuilder* builder,
                  std::map<std::pair<int, int>, FactorId>* by_row, std::set<FactorId>* bridged, int* readings,
                  std::vector<std::vector<FactorId>>* runs) {
  const std::map<FactorId, ProblemBuilder::CumulativeSpan>& spans = builder->cumulative_spans();
  std::set<std::pair<int, int>> spikes;  // (stream, row)
  for (const auto& [id, fails] : failing_now) {
    const auto span = spans.find(id);
    if (!fails || span == spans.end() || span->second.replaced || span->second.bridge) continue;
    const int stream = span->second.stream;
    const auto stream_newest = newest.find(stream);
    if (stream_newest == newest.end()) continue;
    const int last_row = spans.at(stream_newest->second).row_end;
    for (const int row : {span->second.row_begin, span->second.row_end})
      if (spikes.count({stream, row}) == 0 && builder->IsCumulativeSpike(stream, row, last_row, threshold))
        spikes.insert({stream, row});
  }
  for (auto it = spikes.begin(); it != spikes.end();) {
    auto end = std::next(it);
    while (end != spikes.end() && end->first == it->first && end->second == std::prev(end)->second + 1) ++end;
    const int stream = it->first, first = it->second, count = static_cast<int>(std::distance(it, end));
    it = end;
    if (count > static_cast<int>(kMaxBridgedReadings)) continue;
    std::vector<FactorId> run;
    for (int row = first - 1; row < first + count; ++row) {
      const auto span = by_row->find({stream, row});
      if (span == by_row->end()) break;
      run.push_back(span->second);
    }
    if (static_cast<int>(run.size()) != count + 1 || !builder->BridgeCumulativeRun(run)) continue;
    for (int row = first - 1; row < first + count; ++row) by_row->erase({stream, row});
    bridged->insert(run.begin(), run.end());
    runs->push_back(run);
    *readings += count;
  }
}

// Bridges (ProblemBuilder::BridgeCumulativeRun) over outlying readings of cumulative wheel streams. A reading off by
// delta makes the span before it delta / dt too fast and the one after it delta / dt too slow; tested alone, each
// span fails and is rejected, and the poses around the reading lose both. In each run of consecutive failing spans
// (tested now and failing, or older than the pass's first factor and rejected before; at least one of them, or the
// passing span after them, tested now), bridges over 1 to kMaxBridgedReadings readings that pass the test at the
// current estimate replace the spans they cover, the narrowest first; their poses are not those the reading bent, so
// their test is not fooled by the bend. Spans no passing bridge covers (a skid) are left to the gate. Returns the
// factors bridged; adds the readings left out to *readings and each bridged run to *runs.
std::set<FactorId> BridgeFailingRuns(const std::vector<TestedFactor>& tested,
                                     const std::function<double(int)>& threshold, ProblemBuilder* builder,
                                     int* readings, std::vector<std::vector<FactorId>>* runs) {
  std::map<FactorId, bool> failing_now;  // tested spans: id -> fails
  for (const TestedFactor& t : tested) failing_now[t.id] = !t.pass;
  // The unreplaced spans of every cumulative stream, by (stream, first row).
  std::map<std::pair<int, int>, FactorId> by_row;
  for (const auto& [id, span] : builder->cumulative_spans())
    if (!span.bridge && !span.replaced && builder->graph().factors().count(id) > 0)
      by_row[{span.stream, span.row_begin}] = id;
  std::set<FactorId> bridged;
  std::vector<const double*> values;
  internal::WhitenedFactor wf;
  const auto passes = [&](const FactorEntry& entry) {
    values.clear();
    for (VariableId v : entry.variables) values.push_back(builder->graph().variable(v).value.data());
    return internal::LinearizeFactorAt(entry, values.data(), 0, &wf) &&
           wf.squared_norm <= threshold(entry.factor->residual_dim());
  };
  // A span fails when tested now and failing, or not tested now and rejected before.
  const auto fails = [&](FactorId id) {
    const auto now = failing_now.find(id);
    return now != failing_now.end() ? now->second : !builder->graph().factor(id).active;
  };
  // The narrowest bridges first, each from every start in turn: a span the reading beside it bent fails too, and a
  // bridge from it would leave out a good reading with the outlier. In an open run (ending at its stream's newest span,
  // which may go on), only the starts whose every width is recorded: a narrower bridge from a later start would keep
  // outlying readings at its ends.
  const auto bridge_run = [&](const std::vector<FactorId>& run, bool open) {
    std::vector<char> covered(run.size(), 0);
    for (std::size_t w = 1; w <= kMaxBridgedReadings; ++w) {
      for (std::size_t i = 0; i + w < run.size(); ++i) {
        if (open && i + kMaxBridgedReadings >= run.size()) break;
        if (std::any_of(covered.begin() + static_cast<std::ptrdiff_t>(i),
                        covered.begin() + static_cast<std::ptrdiff_t>(i + w + 1), [](char c) { return c != 0; }))
          continue;
        const std::vector<FactorId> spans(run.begin() + static_cast<std::ptrdiff_t>(i),
                                          run.begin() + static_cast<std::ptrdiff_t>(i + w + 1));
        const std::optional<FactorEntry> candidate = builder->CumulativeBridge(spans);
        if (candidate && passes(*candidate) && builder->BridgeCumulativeRun(spans)) {
          bridged.insert(spans.begin(), spans.end());
          runs->push_back(spans);
          std::fill(covered.begin() + static_cast<std::ptrdiff_t>(i),
                    covered.begin() + static_cast<std::ptrdiff_t>(i + w + 1), 1);
          *readings += static_cast<int>(w);
        }
      }
    }
  };
  // The last span of each stream.
  std::map<int, FactorId> newest;
  for (const auto& [key, id] : by_row) newest[key.first] = id;
  BridgeSpikes(failing_now, threshold, newest, builder, &by_row, &bridged, readings, runs);
  int last_stream = -1, last_end = -1;
  std::vector<FactorId> run;
  bool tested_in_run = false;
  const auto close_run = [&] {
    const bool open = !run.empty() && newest[last_stream] == run.back();
    if (run.size() >= 2 && tested_in_run) bridge_run(run, open);
    run.clear();
    tested_in_run = false;
  };
  for (const auto& [key, id] : by_row) {
    const bool bad = fails(id);
    const bool chained = key.first == last_stream && key.second == last_end;
    // A span tested now that passes closes the run before it: the run is tested (a start in it that waited for the
    // span is tried now).
    if (!bad && chained) tested_in_run |= failing_now.count(id) > 0;
    if (!bad || !chained) close_run();
    if (bad) {
      run.push_back(id);
      tested_in_run |= failing_now.count(id) > 0;
    }
    last_stream = key.first;
    last_end = builder->cumulative_spans().at(id).row_end;
  }
  close_run();
  return bridged;
}

// The poses inside a bridged run (those of the readings left out), each set between the run's end poses at its time
// (position linear, rotation along the geodesic): where the bent estimate had them, the left-out reading still pulled
// them off. Returns them.
std::vector<VariableId> UnbendBridgedPoses(const std::vector<FactorId>& run, Graph* graph) {
  const VariableId a_id = graph->factor(run.front()).variables[0];
  const VariableId b_id = graph->factor(run.back()).variables[1];
  const Pose<double> a = PoseFromArray(graph->variable(a_id).value.data());
  const Pose<double> b = PoseFromArray(graph->variable(b_id).value.data());
  const Time t_a = *graph->variable(a_id).stamp, t_b = *graph->variable(b_id).stamp;
  std::vector<VariableId> inside;
  for (std::size_t i = 0; i + 1 < run.size(); ++i) {
    const VariableId id = graph->factor(run[i]).variables[1];
    Variable& pose = graph->mutable_variable(id);
    const double w = SecondsBetween(t_a, *pose.stamp) / SecondsBetween(t_a, t_b);
    const Pose<double> between{a.p_world_body + w * (b.p_world_body - a.p_world_body),
                               a.q_world_body.slerp(w, b.q_world_body)};
    PoseToArray(between, pose.value.data());
    inside.push_back(id);
  }
  return inside;
}

// Every measurement factor with an id in [first, end) but the spans bridges replaced, tested against the
// gate at the current estimate: with the last solve's linearization where it has the factor, else evaluated here.
// One walk over the measurement factors and the graph's factors in id order (a whole recording's 10^5-10^6).
std::vector<TestedFactor> TestMeasurementFactors(const std::function<double(int)>& threshold,
                                                 const ProblemBuilder& builder, FactorId first,
                                                 const SolverWorkspace* last_solve, FactorId end) {
  const Graph& graph = builder.graph();
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  const std::map<FactorId, ProblemBuilder::CumulativeSpan>& spans = builder.cumulative_spans();
  std::vector<const double*> values;
  internal::WhitenedFactor wf;  // reused: its buffers keep their size
  std::vector<TestedFactor> tested;
  auto factor = graph.factors().lower_bound(first);
  for (auto stream = builder.factor_streams().lower_bound(first); stream != builder.factor_streams().end();
       ++stream) {
    const FactorId id = stream->first;
    if (id >= end) break;
    while (factor != graph.factors().end() && factor->first < id) ++factor;
    if (factor == graph.factors().end()) break;
    if (factor->first != id) continue;  // (no longer in the graph)
    if (const auto span = spans.find(id); span != spans.end() && span->second.replaced) continue;
    const FactorEntry& entry = factor->second;
    if (!builder.StreamGated(stream->second)) continue;
    const int dim = entry.factor->residual_dim();
    // The solve's linearization (of an active factor, with the Jacobians of its free variables), else the error.
    const internal::WhitenedFactor* linearized = nullptr;
    if (last_solve != nullptr && entry.active) {
      std::uint64_t free_mask = 0;
      for (std::size_t i = 0; i < entry.variables.size() && i < 64; ++i)
        if (!graph.variable(entry.variables[i]).fixed) free_mask |= std::uint64_t{1} << i;
      linearized = last_solve->Linearization(id, free_mask);
    }
    bool ok = linearized != nullptr;
    if (!ok) {
      values.clear();
      for (VariableId v : entry.variables) values.push_back(graph.variable(v).value.data());
      ok = internal::LinearizeFactorAt(entry, values.data(), 0, &wf);
      linearized = &wf;
    }
    tested.push_back({id, stream->second, entry.active, ok && linearized->squared_norm <= threshold(dim),
                      ok ? linearized->squared_norm : kInfinity, dim});
  }
  return tested;
}

// The poses of the readings the bridges of `runs` left out go back between their neighbours (UnbendBridgedPoses), and
// their measurements rejected before (as that reading bent them) that fit there now. Returns those measurements.
std::set<FactorId> RefitAroundBridges(const std::vector<std::vector<FactorId>>& runs,
                                      const std::set<FactorId>& bridged,
                                      const std::function<double(int)>& threshold, ProblemBuilder* builder) {
  Graph& graph = builder->graph();
  const std::map<FactorId, ProblemBuilder::CumulativeSpan>& spans = builder->cumulative_spans();
  std::vector<const double*> values;
  internal::WhitenedFactor wf;
  std::set<FactorId> refit;
  for (const std::vector<FactorId>& run : runs)
    for (const VariableId pose : UnbendBridgedPoses(run, &graph))
      for (const FactorId id : graph.FactorsOf(pose)) {
        const FactorEntry& entry = graph.factor(id);
        if (entry.active || builder->StreamOfFactor(id) < 0 || bridged.count(id) > 0) continue;
        if (const auto span = spans.find(id); span != spans.end() && span->second.replaced) continue;
        values.clear();
        for (VariableId v : entry.variables) values.push_back(graph.variable(v).value.data());
        if (internal::LinearizeFactorAt(entry, values.data(), 0, &wf) &&
            wf.squared_norm <= threshold(entry.factor->residual_dim()))
          refit.insert(id);
      }
  return refit;
}

// Switches the factors of `switched` (rejects the active ones, re-admits the others) and counts them into *result,
// unless the changes are by chance (GateOptions::ignore_chance_changes): no more newly failing factors than the
// test's false alarms among the `tested` factors, and none of `failing` (squared norm, dimension) beyond the quantile
// that all of them pass with the test's probability (1 - (1 - p) / N each): a gross outlier is rejected however few
// there are. The factors that fit again are re-admitted, unless they and the failing ones together are no more than
// the false alarms either.
void ApplySwitches(const std::vector<FactorId>& switched, const std::vector<std::pair<double, int>>& failing,
                   int tested, double probability, bool ignore_chance_changes, ProblemBuilder* builder,
                   GateSwitches* result) {
  Graph& graph = builder->graph();
  for (FactorId id : switched) (graph.factor(id).active ? result->rejected : result->readmitted) += 1;
  const double false_alarms = static_cast<double>(tested) * (1.0 - probability);
  const bool by_chance =
      ignore_chance_changes && static_cast<double>(result->rejected) <= false_alarms &&
      std::none_of(failing.begin(), failing.end(), [&](const std::pair<double, int>& f) {
        return f.first > ChiSquareQuantile(1.0 - (1.0 - probability) / static_cast<double>(tested), f.second);
      });
  if (by_chance) {
    std::swap(result->ignored, result->rejected);
    if (static_cast<double>(switched.size()) <= false_alarms) result->readmitted = 0;
  }
  for (FactorId id : switched) {
    FactorEntry& entry = graph.mutable_factor(id);
    if (by_chance && (entry.active || result->readmitted == 0)) continue;
    entry.active = !entry.active;
    builder->mutable_counts(entry.stream).rejected += entry.active ? -1 : 1;
  }
}

}  // namespace

GateSwitches GateOutliers(double probability, ProblemBuilder* builder, FactorId first,
                          const SolverWorkspace* last_solve, const GateOptions& options) {
  Graph& graph = builder->graph();
  // Quantiles per (probability, dimension), kept across calls: online tracking gates at every update.
  thread_local std::map<std::pair<double, int>, double> quantiles;
  const auto threshold = [&](int dim) {
    const auto key = std::make_pair(probability, dim);
    const auto it = quantiles.find(key);
    return it != quantiles.end() ? it->second : (quantiles[key] = ChiSquareQuantile(probability, dim));
  };
  const std::vector<TestedFactor> tested_factors =
      TestMeasurementFactors(threshold, *builder, first, last_solve, options.end);
  const int tested = static_cast<int>(tested_factors.size());
  GateSwitches result;
  // A reading of a cumulative wheel stream that fails both spans it joins is left out, not both spans.
  std::vector<std::vector<FactorId>> runs;
  const std::set<FactorId> bridged = BridgeFailingRuns(tested_factors, threshold, builder, &result.bridged, &runs);
  const std::set<FactorId> refit = RefitAroundBridges(runs, bridged, threshold, builder);
  // The other measurements of the poses a bridged reading bent wait for the re-solve without it: failing there now,
  // they would be rejected with it and leave those poses held by nothing, where they stay bent.
  std::set<VariableId> bent_poses;
  for (const FactorId id : bridged) {
    const std::vector<VariableId>& vars = graph.factor(id).variables;
    bent_poses.insert(vars.begin(), vars.begin() + 2);
  }
  // With defer_when_bridging, every failing measurement of a bridging pass waits, not only those of the bent poses.
  const auto waits_for_resolve = [&](FactorId id) {
    if (options.defer_when_bridging) return true;
    const std::vector<VariableId>& vars = graph.factor(id).variables;
    return std::any_of(vars.begin(), vars.end(), [&](VariableId v) { return bent_poses.count(v) > 0; });
  };
  std::vector<FactorId> switched;
  std::vector<std::pair<double, int>> failing;  // (ignore_chance_changes) squared norm and dimension of each active
                                                // factor that fails
  std::vector<FailingFactor> failing_factors;   // (worst_per_pose)
  const bool bursts = options.burst_margin > 0.0;
  std::vector<std::vector<GateRow>> rows(bursts ? builder->stream_names().size() : 0);  // per stream, in time order
  for (const TestedFactor& t : tested_factors) {
    if (refit.count(t.id) > 0) continue;
    if (bridged.count(t.id) > 0 || (!t.pass && !bent_poses.empty() && waits_for_resolve(t.id))) continue;
    if (options.ignore_chance_changes && !t.pass && t.active) failing.push_back({t.squared_norm, t.dim});
    if (bursts)
      rows[t.stream].push_back({t.id, t.active, t.pass});
    else if (options.worst_per_pose && !t.pass && t.active)
      failing_factors.push_back({t.id, t.squared_norm / threshold(t.dim)});
    else if (t.pass != t.active)
      switched.push_back(t.id);
  }
  if (bursts) {
    std::vector<char> reject;
    for (const std::vector<GateRow>& r : rows) {
      reject.assign(r.size(), 0);
      RejectAroundBursts(r, options.burst_margin, &reject);
      for (std::size_t k = 0; k < r.size(); ++k)
        if ((r[k].pass && !reject[k]) != r[k].was_active) switched.push_back(r[k].id);
    }
    std::sort(switched.begin(), switched.end());
  }
  if (!refit.empty()) {
    switched.insert(switched.end(), refit.begin(), refit.end());
    std::sort(switched.begin(), switched.end());
  }
  if (!failing_factors.empty()) {
    const std::vector<FactorId> worst = WorstPerPose(failing_factors, graph, builder->poses());
    switched.insert(switched.end(), worst.begin(), worst.end());
    std::sort(switched.begin(), switched.end());
  }
  ApplySwitches(switched, failing, tested, probability, options.ignore_chance_changes, builder, &result);
  return result;
}

namespace {

// The weak prior of every free pose in ReadmitOnInnovation's covariance when the active problem is singular: wide
// enough that a pose which anything holds keeps the uncertainty its rows give it (millimetres to centimetres), finite
// for a pose that nothing holds, whose innovation then passes whatever its rows say (the gate re-tests them once the
// re-solve has placed the pose).
constexpr double kWeakPriorPosition_m = 100.0;
constexpr double kWeakPriorRotation_rad = 10.0;

// Adds the weak prior (kWeakPriorPosition_m, kWeakPriorRotation_rad) on every free pose at its current value; returns
// the factors added.
std::vector<FactorId> AddWeakPosePriors(ProblemBuilder* builder) {
  Eigen::Matrix<double, 6, 1> variance;
  variance << Eigen::Vector3d::Constant(kWeakPriorPosition_m * kWeakPriorPosition_m),
      Eigen::Vector3d::Constant(kWeakPriorRotation_rad * kWeakPriorRotation_rad);
  Graph& graph = builder->graph();
  std::vector<FactorId> priors;
  for (const PoseNode& node : builder->poses()) {
    const Variable& pose = graph.variable(node.id);
    if (pose.fixed) continue;
    priors.push_back(graph.AddFactor(MakeFactor(PriorError<PoseBlock>(pose.value)), {node.id},
                                     Eigen::MatrixXd(variance.asDiagonal()), Loss::Trivial(), "weak pose prior",
                                     node.t));
  }
  return priors;
}

// Whether factor `id`'s innovation at the current estimate passes the chi-square quantile `probability` of its
// dimension (internal::InnovationWithin), with the joint marginal covariance of its free variables from `system`'s
// factorization; nullopt where that covariance cannot be had.
std::optional<bool> InnovationPasses(double probability, const Graph& graph, internal::NormalEquations& system,
                                     FactorId id) {
  const FactorEntry& entry = graph.factor(id);
  std::vector<const double*> values;
  std::vector<VariableId> free_variables;
  std::vector<int> free;
  std::uint64_t free_mask = 0;
  for (std::size_t i = 0; i < entry.variables.size(); ++i) {
    const Variable& v = graph.variable(entry.variables[i]);
    values.push_back(v.value.data());
    if (v.fixed || system.OffsetOf(entry.variables[i]) < 0) continue;
    free_variables.push_back(entry.variables[i]);
    free.push_back(static_cast<int>(i));
    free_mask |= std::uint64_t{1} << i;
  }
  Eigen::MatrixXd covariance;
  if (!free_variables.empty() && !system.Covariance(free_variables, &covariance)) return std::nullopt;
  internal::WhitenedFactor wf;
  return internal::LinearizeFactorAt(entry, values.data(), free_mask, &wf) &&
         internal::InnovationWithin(probability, wf, free, covariance);
}

}  // namespace

int ReadmitOnInnovation(double probability, ProblemBuilder* builder, const std::set<FactorId>& excluded) {
  Graph& graph = builder->graph();
  // The rejected measurement factors, but the bridges, the spans they replace and the excluded ones.
  const std::map<FactorId, ProblemBuilder::CumulativeSpan>& spans = builder->cumulative_spans();
  std::vector<FactorId> candidates;
  for (const auto& [id, stream] : builder->factor_streams()) {
    if (excluded.count(id) > 0 || graph.factors().count(id) == 0 || graph.factor(id).active) continue;
    if (const auto span = spans.find(id); span != spans.end() && (span->second.bridge || span->second.replaced))
      continue;
    candidates.push_back(id);
  }
  if (candidates.empty()) return 0;
  // One factorization of the active problem; when it is singular, one with the weak pose priors.
  internal::NormalEquations system(graph, FreeVariableOrder(graph));
  Eigen::VectorXd unused;
  bool factored = system.Linearize(graph) && system.Solve(0.0, &unused);
  std::vector<FactorId> priors;
  if (!factored) {
    priors = AddWeakPosePriors(builder);
    system.Reset(graph, FreeVariableOrder(graph));
    factored = system.Linearize(graph) && system.Solve(0.0, &unused);
  }
  // Each candidate's innovation at the current estimate, all against the same factorization.
  std::vector<FactorId> passing;
  for (const FactorId id : candidates) {
    if (!factored) break;
    if (InnovationPasses(probability, graph, system, id).value_or(false)) passing.push_back(id);
  }
  for (const FactorId id : priors) graph.RemoveFactor(id);
  for (const FactorId id : passing) {
    FactorEntry& entry = graph.mutable_factor(id);
    entry.active = true;
    --builder->mutable_counts(entry.stream).rejected;
  }
  return static_cast<int>(passing.size());
}

namespace {

// Gating in calibration: a burst's neighbours within 1.5 times its length are rejected for one round
// (GateOptions::burst_margin), so that the rounds do not peel a skid's edges a few rows at a time.
constexpr double kBurstMargin = 1.5;

// Gating rounds per stage: re-tests of every measurement at the re-solved estimate.
constexpr int kMaxGatingRounds = 5;

void SetFree(const std::set<std::string>& free, ProblemBuilder* builder) {
  for (const auto& [name, id] : builder->parameters())
    builder->graph().mutable_variable(id).fixed = free.count(name) == 0;
}

Trajectory ExtractTrajectory(const ProblemBuilder& builder) {
  Trajectory out;
  for (const PoseNode& node : builder.poses()) {
    const Pose<double> p = PoseFromArray(builder.graph().variable(node.id).value.data());
    out.push_back({node.t, p.p_world_body, p.q_world_body});
  }
  return out;
}

void Say(const CalibrationOptions& options, const std::string& line) {
  if (options.progress) options.progress(line);
}

// The whole recording in one graph, dead-reckoned from the master stream, then started from the given trajectory
// (the nearest pose in time) or aligned to the absolute fixes and the IMU misalignment to the motion.
Status BuildGraph(const CalibrationOptions& options, ProblemBuilder* builder_ptr) {
  ProblemBuilder& builder = *builder_ptr;
  // (A long recording's graph takes seconds to build on a loaded machine: an interruption is checked along the way.)
  std::size_t added = 0;
  for (const MeasurementRef& m : builder.Measurements()) {
    if (++added % 4096 == 0 && InterruptRequested()) return InterruptedError();
    builder.Add(m);
  }
  builder.Finish();
  if (InterruptRequested()) return InterruptedError();
  if (builder.poses().size() < 3) return Status::Error("the recording gives fewer than 3 poses on the master stream");
  if (options.initial_trajectory && !options.initial_trajectory->empty()) {
    const Trajectory& initial = *options.initial_trajectory;
    for (const PoseNode& node : builder.poses()) {
      auto it = std::lower_bound(initial.begin(), initial.end(), node.t,
                                 [](const StampedPose& p, Time t) { return p.t < t; });
      if (it == initial.end()) --it;
      if (it != initial.begin() &&
          node.t.nanoseconds() - std::prev(it)->t.nanoseconds() < it->t.nanoseconds() - node.t.nanoseconds())
        --it;
      PoseToArray(Pose<double>{it->p_world_body, it->q_world_body},
                  builder.graph().mutable_variable(node.id).value.data());
    }
    Say(options, "initial poses from the given trajectory");
  } else {
    builder.AlignToAbsoluteFixes();
    if (const auto q = builder.AlignImuToMotion()) {
      std::ostringstream line;
      line << "initial IMU misalignment from the motion (Wahba): [" << q->w() << ", " << q->x() << ", " << q->y()
           << ", " << q->z() << "]";
      Say(options, line.str());
    }
  }
  Say(options, "graph: " + std::to_string(builder.poses().size()) + " poses, " +
                   std::to_string(builder.graph().factors().size()) + " factors");
  return Status::Ok();
}

// Rounds of admission of the absolute rows held out after a gap (AdmitConsistentRows), each followed by a re-solve.
constexpr int kMaxAdmissionRounds = 5;

// The measurement factors of the absolute streams (a motion-capture pose, a GPS fix) stamped at or after their
// stream's first resumption after a gap (internal::GapResumes; within a millisecond, the stamps' rounding). After a
// clock jump every later row is stamped late, and a row a second late bends the first solve until the good wheel and
// IMU rows of its poses fail with it; after an outage the rows resume consistent. Each is held out (counted as
// rejected) and admitted on its own innovation (AdmitConsistentRows), not with the stream's later rows once one passes
// as in tracking: in one batch, a late row far into a long dead-reckoned stretch can pass where the estimate's
// uncertainty has grown to cover its lateness, and it would take every row after it in with it.
std::vector<FactorId> HoldOutAbsoluteRowsAfterGaps(const EstimatorConfig& config, const recording::Recording& recording,
                                                   ProblemBuilder* builder) {
  constexpr std::int64_t kSlackNs = 1000000;
  const std::map<std::string, std::vector<Time>> resumes = internal::GapResumes(config, recording, true);
  std::vector<FactorId> held;
  for (const auto& [id, entry] : builder->graph().factors()) {
    const auto resume = resumes.find(entry.stream);
    const int stream = builder->StreamOfFactor(id);
    if (resume == resumes.end() || stream < 0 || !builder->StreamGated(stream) || !entry.active) continue;
    if (entry.stamp.nanoseconds() >= resume->second.front().nanoseconds() - kSlackNs) held.push_back(id);
  }
  for (const FactorId id : held) {
    builder->graph().mutable_factor(id).active = false;
    ++builder->mutable_counts(builder->graph().factor(id).stream).rejected;
  }
  return held;
}

// Admits each factor of `held` (held out, HoldOutAbsoluteRowsAfterGaps) whose innovation at the current estimate
// passes the chi-square quantile `probability` of its dimension (internal::InnovationWithin, with the joint marginal
// covariance of its free variables from one factorization of the whole problem); `held` keeps the others. Where that
// covariance cannot be had (the problem is singular), a row is admitted untested, to be tested by the gate. Returns
// how many it admitted.
int AdmitConsistentRows(double probability, std::vector<FactorId>* held, ProblemBuilder* builder) {
  Graph& graph = builder->graph();
  internal::NormalEquations system(graph, FreeVariableOrder(graph));
  const bool linearized = system.Linearize(graph);
  std::vector<FactorId> still_held;
  int admitted = 0;
  for (const FactorId id : *held) {
    const bool passes = !linearized || InnovationPasses(probability, graph, system, id).value_or(true);
    if (!passes) {
      still_held.push_back(id);
      continue;
    }
    FactorEntry& entry = graph.mutable_factor(id);
    entry.active = true;
    --builder->mutable_counts(entry.stream).rejected;
    ++admitted;
  }
  held->swap(still_held);
  return admitted;
}

// The scale of the robust start's Huber loss: the chi-square 95 % quantile of a factor's dimension, in whitened units.
// Errors within it (19 in 20 good ones) count as in least squares; a gross one pulls with the force of one at the
// scale.
constexpr double kRobustStartProbability = 0.95;

// Gives every measurement factor of a stream configured with the trivial loss Huber's loss at the
// kRobustStartProbability quantile of its dimension (robust), or the trivial loss back (not robust); the streams
// configured with a robust loss keep theirs. Returns `robust` when some factor took Huber's loss.
bool UseRobustStartLoss(const EstimatorConfig& config, bool robust, ProblemBuilder* builder) {
  std::map<int, double> scale;  // by dimension
  bool any = false;
  Graph& graph = builder->graph();
  for (const auto& [id, entry] : graph.factors()) {
    if (builder->StreamOfFactor(id) < 0) continue;
    const auto stream = config.streams.find(entry.stream);
    if (stream == config.streams.end() || stream->second.loss.type != Loss::Type::kTrivial) continue;
    const int dim = entry.factor->residual_dim();
    if (scale.count(dim) == 0) scale[dim] = std::sqrt(ChiSquareQuantile(kRobustStartProbability, dim));
    graph.mutable_factor(id).loss = robust ? Loss::Huber(scale[dim]) : Loss::Trivial();
    any = true;
  }
  return any && robust;
}

// Rounds of re-admission on the innovation (ReadmitOnInnovation) per stage, each followed by a re-solve and a gate.
constexpr int kMaxReadmissionRounds = 3;

// One stage (stage index s of `stage_count`, its parameters free): a solve, the admission of the `held` rows (held
// out after a gap; those never admitted are left in it), then gating rounds with their re-solves, then the rounds
// that re-admit rejected rows on their innovation (all but the `after_gap` rows: every row held out after a gap).
// `lambda` carries Levenberg-Marquardt's damping from solve to solve: the first stage starts from the configured one,
// as its parameters and the dead-reckoned poses may be far from the minimum; every later solve starts where the last
// one ended, as a restart from the configured damping holds the steps back along weakly observed directions (lever
// arm against height, magnetometer b against A) for many iterations while the damping comes down again.
Result<StageSummary> SolveStage(const EstimatorConfig& config, const CalibrationOptions& options,
                                const std::vector<std::string>& free, std::size_t s, std::size_t stage_count,
                                ProblemBuilder* builder_ptr, SolverWorkspace* workspace, double* lambda,
                                std::vector<FactorId>* held, const std::vector<FactorId>& after_gap) {
  ProblemBuilder& builder = *builder_ptr;
  const bool lm = config.solver.method == SolverOptions::Method::kLevenbergMarquardt;
  SetFree({free.begin(), free.end()}, &builder);
  StageSummary stage;
  stage.free_parameters = free;
  // Checked before each gating, admission and re-admission pass (each tests every measurement, and the re-admission
  // factorizes); the solves check their own iterations.
  const auto interrupted = [s]() -> std::optional<Status> {
    if (!InterruptRequested()) return std::nullopt;
    return Status::Error("stage " + std::to_string(s + 1) + ": " + InterruptedError().message());
  };
  SolverOptions stage_options = config.solver;
  if (lm) stage_options.initial_lambda = std::max(*lambda, std::numeric_limits<double>::epsilon());
  bool robust = config.gate_probability && config.gate_robust_start && UseRobustStartLoss(config, true, &builder);
  stage.solver = Solve(stage_options, &builder.graph(), nullptr, workspace);
  if (!stage.solver.usable()) return Status::Error("stage " + std::to_string(s + 1) + ": " + stage.solver.message);
  // Gate gross outliers at the converged estimate and re-solve without them. Gross outliers bend the estimate and make
  // inliers look bad too: every measurement is re-tested after each re-solve, re-admitting those that fit again, until
  // a round switches nothing (at most kMaxGatingRounds rounds; a round that rejects no more newly failing measurements
  // than the test's own false alarms rejects none, GateOutliers). The first round also rejects a burst's neighbours
  // (kBurstMargin).
  // Each round's re-solve runs to convergence, and a round that only re-admits is followed by another: a round that
  // switches many rows (a burst's margin, the good rows of poses an outlier bent) moves the estimate far, and rows
  // tested short of where it leads stay rejected though they fit there (a GPS fix beside a stretch of late ones, a
  // motion-capture pose beside an outlier). Each re-solve starts from the last one's damping.
  *lambda = stage.solver.final_lambda;
  const auto resolve = [&](const std::string& what) -> Status {
    SolverOptions warm = config.solver;
    if (lm) warm.initial_lambda = std::max(*lambda, std::numeric_limits<double>::epsilon());
    const SolverSummary again = Solve(warm, &builder.graph(), nullptr, workspace);
    *lambda = again.final_lambda;
    Say(options, "stage " + std::to_string(s + 1) + ": " + what + " in " + std::to_string(again.iterations) +
                     " iterations, " + std::to_string(again.seconds) + " s");
    if (!again.usable()) return Status::Error("stage " + std::to_string(s + 1) + ": " + again.message);
    stage.solver.iterations += again.iterations;
    stage.solver.final_cost = again.final_cost;
    stage.solver.cost_history.insert(stage.solver.cost_history.end(), again.cost_history.begin(),
                                     again.cost_history.end());
    stage.solver.termination = again.termination;
    stage.solver.seconds += again.seconds;
    return Status::Ok();
  };
  // The absolute rows held out after a gap: admitted on their innovation at the estimate solved without them, then
  // re-solved with them, until a round admits none (the rows left out count as rejected; the gate tests them again).
  for (int admission = 0; config.gate_probability && admission < kMaxAdmissionRounds && !held->empty(); ++admission) {
    if (auto stop = interrupted()) return *stop;
    const int admitted = AdmitConsistentRows(*config.gate_probability, held, &builder);
    if (admitted == 0) break;
    const Status solved = resolve(std::to_string(admitted) + " rows after a gap admitted, " +
                                  std::to_string(held->size()) + " held out, re-solved");
    if (!solved.ok()) return solved;
  }
  // Passes that bridge wheel readings reject nothing else (GateOptions::defer_when_bridging) and are not counted as
  // rounds, up to kMaxGatingRounds of them: the rounds, burst margin first, start at the estimate re-solved without
  // the readings they left out.
  int round = 0;
  for (int pass = 0; config.gate_probability && round < kMaxGatingRounds; ++pass) {
    if (auto stop = interrupted()) return *stop;
    // (Not handed the workspace: Levenberg-Marquardt's last point had its cost evaluated, not its linearization.)
    GateOptions gate;
    gate.burst_margin = round == 0 ? kBurstMargin : 0.0;
    gate.ignore_chance_changes = true;
    gate.defer_when_bridging = pass - round < kMaxGatingRounds;
    const GateSwitches changed = GateOutliers(*config.gate_probability, &builder, 0, nullptr, gate);
    if (changed.bridged == 0 || !gate.defer_when_bridging) ++round;
    if (changed.switched() == 0 && !robust) break;
    if (changed.switched() == 0) {
      // Settled under Huber's loss: least squares on what it kept, tested again by the next pass.
      robust = UseRobustStartLoss(config, false, &builder);
      const Status solved = resolve("gate settled under Huber's loss: least squares");
      if (!solved.ok()) return solved;
      continue;
    }
    const Status solved = resolve(
        "gating round " + std::to_string(pass + 1) + ": " + std::to_string(changed.rejected) +
        " measurements rejected, " + std::to_string(changed.readmitted) + " re-admitted" +
        (changed.bridged > 0 ? ", " + std::to_string(changed.bridged) + " wheel readings bridged" : "") +
        (changed.ignored > 0 ? ", " + std::to_string(changed.ignored) + " failing by chance" : "") + ", re-solved");
    if (!solved.ok()) return solved;
  }
  if (robust) {
    UseRobustStartLoss(config, false, &builder);
    const Status solved = resolve("rounds ended under Huber's loss: least squares");
    if (!solved.ok()) return solved;
  }
  // The rejected rows that fit on their innovation come back (ReadmitOnInnovation: a good row of a pose that an
  // outlier bent, rejected with it, fails the gate's own test at an estimate that nothing holds there), each round
  // re-solved and gated once more, rejecting only the worst failing row at a pose (GateOptions::worst_per_pose): rows
  // of a pose that nothing held all pass their innovation, an outlier among them too. A row comes back once a stage.
  std::set<FactorId> not_readmitted(after_gap.begin(), after_gap.end());
  for (int round = 0; config.gate_probability && round < kMaxReadmissionRounds; ++round) {
    if (auto stop = interrupted()) return *stop;
    std::set<FactorId> rejected_now;
    for (const auto& [id, stream] : builder.factor_streams())
      if (builder.graph().factors().count(id) > 0 && !builder.graph().factor(id).active) rejected_now.insert(id);
    const int readmitted = ReadmitOnInnovation(*config.gate_probability, &builder, not_readmitted);
    if (readmitted == 0) break;
    stage.readmitted += readmitted;
    for (const FactorId id : rejected_now)
      if (builder.graph().factor(id).active) not_readmitted.insert(id);
    Status solved = resolve(std::to_string(readmitted) + " rejected rows re-admitted on their innovation, re-solved");
    if (!solved.ok()) return solved;
    GateOptions gate;
    gate.ignore_chance_changes = true;
    gate.worst_per_pose = true;
    gate.defer_when_bridging = true;
    const GateSwitches changed = GateOutliers(*config.gate_probability, &builder, 0, nullptr, gate);
    if (changed.switched() == 0) break;
    solved = resolve("gated after the re-admission: " + std::to_string(changed.rejected) + " measurements rejected, " +
                     std::to_string(changed.readmitted) + " re-admitted, re-solved");
    if (!solved.ok()) return solved;
  }
  for (const auto& [stream, c] : builder.counts()) stage.rejected += c.rejected;
  Say(options, "stage " + std::to_string(s + 1) + "/" + std::to_string(stage_count) + ": " +
                   std::to_string(stage.rejected) + " measurements rejected, " + std::to_string(stage.readmitted) +
                   " re-admitted on their innovation; cost " + std::to_string(stage.solver.initial_cost) + " -> " +
                   std::to_string(stage.solver.final_cost) + " in " + std::to_string(stage.solver.iterations) +
                   " iterations (" + TerminationName(stage.solver.termination) + "), " +
                   std::to_string(stage.solver.seconds) + " s");
  return stage;
}

// The estimate of every parameter free in some stage, with its standard deviations, observability and correlations
// from their joint marginal information at the final estimate (when options.analyze_observability).
Status EstimateParameters(const CalibrationOptions& options, const std::vector<std::vector<std::string>>& stages,
                          bool hac, ProblemBuilder* builder_ptr, SolverWorkspace* workspace,
                          CalibrationResult* result) {
  ProblemBuilder& builder = *builder_ptr;
  std::set<std::string> ever_free;
  for (const auto& st : stages) ever_free.insert(st.begin(), st.end());
  SetFree(ever_free, &builder);
  std::vector<VariableId> ids;
  std::vector<std::string> names;
  for (const auto& [name, id] : builder.parameters()) {
    if (!ever_free.count(name)) continue;
    ids.push_back(id);
    names.push_back(name);
  }
  ObservabilityAnalysis analysis;
  Eigen::MatrixXd hac_covariance;
  std::vector<int> offsets;
  if (!ids.empty() && options.analyze_observability) {
    const auto analysis_start = std::chrono::steady_clock::now();
    auto info = ComputeMarginalInformation(builder.graph(), ids, workspace);
    if (!info.ok()) return info.status();
    analysis = AnalyzeObservability(info.value().information, info.value().conditional, options.observability);
    offsets = info.value().offsets;
    result->information = info.value().information;
    auto sandwich = ComputeHacCovariance(builder.graph(), ids, analysis.covariance);
    if (!sandwich.ok()) return sandwich.status();
    hac_covariance = std::move(sandwich.value().covariance);
    result->hac_lags = std::move(sandwich.value().lags);
    Say(options,
        "observability analysis: " +
            std::to_string(std::chrono::duration<double>(std::chrono::steady_clock::now() - analysis_start).count()) +
            " s");
  }
  for (std::size_t i = 0; i < ids.size(); ++i) {
    const Variable& v = builder.graph().variable(ids[i]);
    ParameterEstimate p;
    p.name = names[i];
    p.manifold = v.manifold;
    p.estimate = v.value;
    const int dim = v.manifold.tangent_dim();
    if (!options.analyze_observability) {
      p.std = Eigen::VectorXd::Constant(dim, std::numeric_limits<double>::quiet_NaN());
      p.std_white = p.std_hac = p.std;
      p.components.assign(dim, Observability::kObservable);
      result->parameters.push_back(std::move(p));
      continue;
    }
    p.std_white = analysis.std.segment(offsets[i], dim);
    p.std_hac = p.std_white;
    for (int c = 0; c < dim; ++c)
      if (std::isfinite(p.std_white[c])) p.std_hac[c] = std::sqrt(hac_covariance(offsets[i] + c, offsets[i] + c));
    p.std = hac ? p.std_hac.cwiseMax(p.std_white) : p.std_white;
    for (int c = 0; c < dim; ++c) {
      const Observability o = analysis.observability[offsets[i] + c];
      p.components.push_back(o);
      if (static_cast<int>(o) > static_cast<int>(p.observability)) p.observability = o;
    }
    result->parameters.push_back(std::move(p));
  }
  // The strongest correlation between the components of each pair of parameters, when above the threshold.
  for (std::size_t i = 0; i < ids.size() && options.analyze_observability; ++i) {
    for (std::size_t j = i + 1; j < ids.size(); ++j) {
      double best = 0.0;
      const int di = builder.graph().variable(ids[i]).manifold.tangent_dim();
      const int dj = builder.graph().variable(ids[j]).manifold.tangent_dim();
      for (int a = 0; a < di; ++a)
        for (int b = 0; b < dj; ++b) {
          const double rho = analysis.correlation(offsets[i] + a, offsets[j] + b);
          if (std::abs(rho) > std::abs(best)) best = rho;
        }
      if (std::abs(best) >= options.correlation_threshold) result->correlations.push_back({names[i], names[j], best});
    }
  }
  return Status::Ok();
}

// Poses per joint marginal covariance in EstimatePoseCovariances: each chunk's solves hold a dense block of the
// problem's dimension times 6 columns per pose.
constexpr std::size_t kPoseCovarianceChunk = 40;

// The position covariance of every `every`-th pose, white and HAC, with the parameters that were free in some stage
// still free (EstimateParameters leaves them so), chunk by chunk.
Status EstimatePoseCovariances(int every, bool hac, const ProblemBuilder& builder, CalibrationResult* result) {
  const std::deque<PoseNode>& poses = builder.poses();
  std::vector<std::size_t> wanted;
  for (std::size_t i = 0; i < poses.size(); i += static_cast<std::size_t>(every)) wanted.push_back(i);
  for (std::size_t first = 0; first < wanted.size(); first += kPoseCovarianceChunk) {
    const std::size_t last = std::min(wanted.size(), first + kPoseCovarianceChunk);
    std::vector<VariableId> ids;
    for (std::size_t k = first; k < last; ++k) ids.push_back(poses[wanted[k]].id);
    auto info = ComputeMarginalInformation(builder.graph(), ids);
    if (!info.ok()) return info.status();
    const ObservabilityAnalysis white = AnalyzeObservability(info.value().information, info.value().conditional);
    auto sandwich = ComputeHacCovariance(builder.graph(), ids, white.covariance);
    if (!sandwich.ok()) return sandwich.status();
    for (std::size_t k = first; k < last; ++k) {
      const int offset = info.value().offsets[k - first];
      PoseCovariance c;
      c.pose = wanted[k];
      c.white = white.covariance.block<3, 3>(offset, offset);
      c.hac = sandwich.value().covariance.block<3, 3>(offset, offset);
      c.covariance = hac && c.hac.trace() > c.white.trace() ? c.hac : c.white;
      result->pose_covariances.push_back(c);
    }
  }
  return Status::Ok();
}

// Every measurement factor's whitened residual at the final estimate, without the loss weighting.
void KeepResiduals(const ProblemBuilder& builder, CalibrationResult* result) {
  for (const auto& [id, entry] : builder.graph().factors()) {
    if (builder.StreamOfFactor(id) < 0) continue;
    internal::WhitenedFactor wf;
    const bool ok =
        internal::LinearizeFactor(builder.graph(), entry, std::vector<bool>(entry.variables.size(), false), &wf);
    if (!ok) continue;
    // Undo the loss weighting: sqrt(s) along the weighted residual's direction.
    Eigen::VectorXd whitened = wf.residual;
    if (whitened.norm() > 0.0) whitened *= std::sqrt(wf.squared_norm) / whitened.norm();
    result->residuals.push_back({entry.stream, entry.stamp, whitened, entry.active});
  }
}

}  // namespace

std::vector<std::string> HeavilyGatedStreams(const CalibrationResult& result, double share) {
  std::vector<std::string> lines;
  for (const auto& [stream, c] : result.counts) {
    if (c.attached <= 0 || c.rejected <= share * c.attached) continue;
    const long percent = std::lround(100.0 * c.rejected / c.attached);
    lines.push_back("stream '" + stream + "': the gate rejected " + std::to_string(c.rejected) + " of " +
                    std::to_string(c.attached) + " measurements (" + std::to_string(percent) +
                    " %); the estimate rests on the other streams, and the calibration may have failed");
  }
  return lines;
}

bool UsesHac(CalibrationOptions::StdMethod method, const recording::Recording& recording) {
  return method == CalibrationOptions::StdMethod::kHac ||
         (method == CalibrationOptions::StdMethod::kAuto && recording.provenance.source == "imported");
}

Result<CalibrationResult> Calibrate(const EstimatorConfig& config, const recording::Recording& recording,
                                    const CalibrationOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  auto built = ProblemBuilder::Create(config, recording);
  if (!built.ok()) return built.status();
  ProblemBuilder& builder = *built.value();
  const Status graph = BuildGraph(options, &builder);
  if (!graph.ok()) return graph;

  // Stages: the configured ones, or all free parameters at once.
  std::vector<std::vector<std::string>> stages = config.stages;
  const std::vector<std::string> all_free = builder.FreeParameterNames();
  if (stages.empty()) stages.push_back(all_free);

  CalibrationResult result;
  double lambda = config.solver.initial_lambda;
  // The solves' buffers, carried from one solve to the next (a gating round's re-solve would otherwise allocate and
  // page in its pattern and envelope again); the observability analysis at the end uses them too. The factors'
  // linearizations are not kept (the gate evaluates the errors at the converged point, where no solve linearized
  // them).
  auto workspace = std::make_unique<SolverWorkspace>();
  workspace->set_keep_linearizations(false);
  // The absolute rows after a gap wait out the first stage's first solve; the later stages gate them as any other.
  std::vector<FactorId> held;
  if (config.gate_probability) held = HoldOutAbsoluteRowsAfterGaps(config, recording, &builder);
  const std::vector<FactorId> after_gap = held;
  for (std::size_t s = 0; s < stages.size(); ++s) {
    Result<StageSummary> stage =
        SolveStage(config, options, stages[s], s, stages.size(), &builder, workspace.get(), &lambda, &held, after_gap);
    held.clear();
    if (!stage.ok()) return stage.status();
    result.iterations += stage.value().solver.iterations;
    result.termination = TerminationName(stage.value().solver.termination);
    result.stages.push_back(std::move(stage).value());
  }
  result.initial_cost = result.stages.front().solver.initial_cost;
  result.final_cost = result.stages.back().solver.final_cost;

  // The estimate's covariances factorize the whole problem again.
  if (InterruptRequested()) return InterruptedError();
  const bool hac = UsesHac(options.std_method, recording);
  result.std_method = hac ? "hac" : "white";
  const Status estimated = EstimateParameters(options, stages, hac, &builder, workspace.get(), &result);
  if (!estimated.ok()) return estimated;
  if (options.pose_covariance_every > 0) {
    if (InterruptRequested()) return InterruptedError();
    const Status poses = EstimatePoseCovariances(options.pose_covariance_every, hac, builder, &result);
    if (!poses.ok()) return poses;
  }
  if (options.keep_residuals) KeepResiduals(builder, &result);
  result.counts = builder.counts();
  result.trajectory = ExtractTrajectory(builder);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace roamlab::estimator
