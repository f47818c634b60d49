#include "gap/internal/fit.h"

#include <cmath>
#include <cstdint>

namespace roamlab::gap::internal {
namespace {

using estimator::EstimatorConfig;
using recording::Recording;

// The initial damping of a warm or fixed fit (see Fit).
constexpr double kWarmInitialLambda = 1e-11;

}  // namespace

Recording Slice(const Recording& in, double t0, double t1, const std::set<std::string>& master,
                const std::set<std::string>& position, double margin_s) {
  Recording out;
  out.format_version = in.format_version;
  out.platform = in.platform;
  out.origin = in.origin;
  out.provenance = in.provenance;
  for (const recording::Stream& s : in.streams) {
    const double m = master.count(s.info.name) ? margin_s : position.count(s.info.name) ? 2.0 * margin_s : 0.0;
    recording::Stream c;
    c.info = s.info;
    std::vector<Eigen::Index> rows;
    for (std::size_t i = 0; i < s.t.size(); ++i) {
      const double t = s.t[i].seconds();
      if (t >= t0 + m && t <= t1 - m) rows.push_back(static_cast<Eigen::Index>(i));
    }
    c.values.resize(static_cast<Eigen::Index>(rows.size()), s.values.cols());
    for (std::size_t k = 0; k < rows.size(); ++k) {
      c.t.push_back(s.t[static_cast<std::size_t>(rows[k])]);
      c.values.row(static_cast<Eigen::Index>(k)) = s.values.row(rows[k]);
      if (!s.text.empty()) c.text.push_back(s.text[static_cast<std::size_t>(rows[k])]);
    }
    out.streams.push_back(std::move(c));
  }
  return out;
}

Recording Shifted(const Recording& in, const std::map<std::string, double>& shift_s) {
  Recording out = in;
  for (recording::Stream& s : out.streams) {
    const auto it = shift_s.find(s.info.name);
    if (it == shift_s.end() || it->second == 0.0) continue;
    const std::int64_t ns = std::llround(it->second * 1e9);
    for (Time& t : s.t) t = Time::FromNanoseconds(t.nanoseconds() - ns);
  }
  return out;
}

std::optional<Eigen::VectorXd> ConfiguredValue(const EstimatorConfig& config, const std::string& name) {
  const auto it = config.parameters.find(name);
  if (it != config.parameters.end() && it->second.value) return *it->second.value;
  for (const auto& [stream, sc] : config.streams) {
    const estimator::ModelSpec* spec = estimator::FindModelSpec(sc.model);
    if (!spec) continue;
    for (const estimator::SlotSpec& slot : spec->slots) {
      const auto mapped = sc.parameters.find(slot.name);
      const std::string full = mapped != sc.parameters.end() ? mapped->second : stream + "." + slot.name;
      if (full == name) return slot.default_value;
    }
  }
  return std::nullopt;
}

std::string SlotParameter(const std::string& stream, const estimator::StreamConfig& sc, const std::string& slot) {
  const auto mapped = sc.parameters.find(slot);
  return mapped != sc.parameters.end() ? mapped->second : stream + "." + slot;
}

Result<FitOutcome> Fit(const EstimatorConfig& nominal, const Recording& recording, const FitSpec& spec) {
  EstimatorConfig config = nominal;
  std::vector<std::string> free;
  for (const auto& [name, p] : config.parameters)
    if (p.free) free.push_back(name);
  for (const std::string& name : spec.extra_free) {
    estimator::ParameterConfig& p = config.parameters[name];
    if (!p.value) p.value = ConfiguredValue(nominal, name);
    if (!p.free) free.push_back(name);
    p.free = true;
  }
  for (const auto& [name, value] : spec.values) config.parameters[name].value = value;
  if (spec.mode != FitMode::kStaged) config.stages.clear();
  if (spec.mode == FitMode::kWarm) config.stages.push_back(free);
  if (spec.mode == FitMode::kFixed)
    for (auto& [name, p] : config.parameters) p.free = false;

  // A warm or fixed fit starts next to its minimum: the staged fits' initial damping (relative to diag(H)) would
  // dominate the weakly determined directions (a few calibration parameters that trade against each other) and
  // Levenberg-Marquardt would spend a dozen iterations cutting it by 3 per step while the cost barely moves, or stop
  // there on the function tolerance before the minimum. A damping that small still rises if a step is rejected.
  if (spec.mode != FitMode::kStaged) config.solver.initial_lambda = kWarmInitialLambda;
  estimator::CalibrationOptions options;
  options.keep_residuals = spec.keep_residuals;
  options.analyze_observability = spec.observability;
  options.std_method = spec.std_method;
  options.initial_trajectory = spec.initial;
  auto result = estimator::Calibrate(config, Shifted(recording, spec.shift_s), options);
  if (!result.ok()) return result.status();
  FitOutcome out;
  out.chi2 = 2.0 * result.value().final_cost;
  for (const auto& [name, p] : config.parameters)
    if (p.value) out.values[name] = *p.value;
  for (const estimator::ParameterEstimate& p : result.value().parameters) {
    out.values[p.name] = p.estimate;
    if (spec.observability) out.std[p.name] = p.std;
  }
  for (const auto& [stream, c] : result.value().counts) out.measurements += c.attached - c.rejected;
  out.residuals = std::move(result.value().residuals);
  out.trajectory = std::move(result.value().trajectory);
  return out;
}

double MasterPeriod(const EstimatorConfig& config, const Recording& recording) {
  const auto it = config.streams.find(config.master);
  if (it == config.streams.end() || it->second.sources.empty()) return 0.01;
  const recording::Stream* s = recording.Find(it->second.sources.begin()->second);
  if (!s || s->t.size() < 2) return 0.01;
  return SecondsBetween(s->t.front(), s->t.back()) / static_cast<double>(s->t.size() - 1);
}

}  // namespace roamlab::gap::internal
