#include "gap/resimulate.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "gap/internal/twin_residuals.h"
#include "sim/simulator.h"

namespace roamlab::gap {
namespace {

using recording::Stream;

// lateral_slip: the rear cornering compliance the tires' contact time scale adds per unit above 1 [s]
// (sim/scenario.h, measured on the truth of atv_hills_sines.yaml).
constexpr double kRearCompliancePerContactScale = 0.0203;

// Compares every stream of `recorded` with the same-named stream of `simulated`, from `from` on.
std::map<std::string, SimulatedStreamFit> Compare(const recording::Recording& recorded,
                                                  const recording::Recording& simulated, Time from,
                                                  std::vector<std::string>* left_out) {
  const internal::Layout layout =
      internal::MakeLayout(recorded, from, Time::FromNanoseconds(std::numeric_limits<std::int64_t>::max()));
  std::vector<std::string> missing;
  const Eigen::VectorXd whitened = internal::WhitenedResiduals(layout, recorded, simulated, &missing);
  if (left_out) {
    left_out->insert(left_out->end(), layout.left_out.begin(), layout.left_out.end());
    left_out->insert(left_out->end(), missing.begin(), missing.end());
  }
  return internal::SeriesFits(layout, whitened);
}

}  // namespace

sim::EffectOptions SimulatorEffect(const EffectEstimate& effect, std::map<std::string, double>* std,
                                   double physics_step_s) {
  sim::EffectOptions e;
  e.name = effect.name;
  if (effect.name == "lateral_slip") {
    const auto c = effect.parameters.find("cornering_rear_s");
    const double scale = c == effect.parameters.end() ? 1.0 : 1.0 + c->second / kRearCompliancePerContactScale;
    e.parameters["contact_time_scale"] = std::clamp(scale, 1.0, 4.0);
    if (std && effect.std.count("cornering_rear_s"))
      (*std)["contact_time_scale"] = effect.std.at("cornering_rear_s") / kRearCompliancePerContactScale;
    return e;
  }
  const auto known = sim::KnownEffects().find(effect.name);
  if (known == sim::KnownEffects().end()) return e;
  const bool shift = effect.name == "gps_latency" || effect.name == "imu_time_offset";
  for (const auto& [name, value] : effect.parameters) {
    if (!known->second.count(name)) continue;
    e.parameters[name] = shift && physics_step_s > 0.0 ? std::round(value / physics_step_s) * physics_step_s : value;
    if (std && effect.std.count(name)) (*std)[name] = effect.std.at(name);
  }
  return e;
}

Result<SimulationComparison> CompareWithSimulation(const sim::Scenario& nominal,
                                                   const std::vector<EffectEstimate>& effects,
                                                   const recording::Recording& recording, double from_s) {
  if (recording.platform.kind != nominal.robot.kind)
    return Status::Error("the recording's platform kind '" + recording.platform.kind + "' is not the scenario's '" +
                         nominal.robot.kind + "'");
  double span_s = 0.0;
  for (const Stream& s : recording.streams)
    if (!s.t.empty()) span_s = std::max(span_s, s.t.back().seconds());
  SimulationComparison out;
  out.from_s = from_s;
  sim::Scenario scenario = nominal;
  scenario.effects.clear();
  scenario.duration_s = std::max(span_s, 1.0);
  out.duration_s = scenario.duration_s;
  sim::SimulateOptions options;
  options.noise = false;
  const Time from = Time::FromSeconds(from_s);
  double step_s = 0.0;
  for (const bool patched : {false, true}) {
    if (patched) {
      for (const EffectEstimate& e : effects) scenario.effects.push_back(SimulatorEffect(e, nullptr, step_s));
      out.effects = scenario.effects;
    }
    auto simulator = sim::Simulator::Create(scenario, options);
    if (!patched && simulator.ok()) step_s = simulator.value()->PhysicsStepS();
    auto simulated = simulator.ok() ? simulator.value()->Run() : Result<sim::Simulation>(simulator.status());
    if (!simulated.ok() && !patched) return Status::Error("the nominal simulation: " + simulated.status().message());
    if (!simulated.ok()) {
      out.not_simulated = simulated.status().message();
      break;
    }
    (patched ? out.after : out.before) =
        Compare(recording, simulated.value().recording, from, patched ? nullptr : &out.left_out);
  }
  return out;
}

}  // namespace roamlab::gap
