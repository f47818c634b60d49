#include "gap/resimulate.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>

#include "gap/internal/twin_residuals.h"
#include "gap/twin.h"
#include "sim/replay.h"
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

// The twin's duration [s] to the recording's last stamp: the plain simulation counts from 0, the replay from the
// recording's first stamp (stamps may be absolute, e.g. Unix time).
double TwinDurationS(const recording::Recording& recording, bool replayed) {
  std::optional<Time> first, last;
  for (const Stream& s : recording.streams) {
    if (s.t.empty()) continue;
    if (!first || s.t.front() < *first) first = s.t.front();
    if (!last || *last < s.t.back()) last = s.t.back();
  }
  if (!first) return 1.0;
  return std::max(replayed ? SecondsBetween(*first, *last) : last->seconds(), 1.0);
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
  const bool shift =
      effect.name == "gps_latency" || effect.name == "imu_time_offset" || effect.name == "pose_time_offset";
  for (const auto& [name, value] : effect.parameters) {
    if (!known->second.count(name)) continue;
    e.parameters[name] = shift && physics_step_s > 0.0 ? std::round(value / physics_step_s) * physics_step_s : value;
    if (std && effect.std.count(name)) (*std)[name] = effect.std.at(name);
  }
  return e;
}

Result<TwinChoice> ChooseTwin(const sim::Scenario& nominal, const recording::Recording& recording, TwinDrive drive) {
  TwinChoice out;
  if (drive == TwinDrive::kPlain) {
    out.reason = "forced: the scenario's own drive";
    return out;
  }
  if (drive == TwinDrive::kReplay) {
    if (auto inputs = sim::DriveInputsFrom(recording, nominal); !inputs.ok()) return inputs.status();
    out.replayed = true;
    out.reason = "forced: the replay of the recorded drive";
    return out;
  }
  sim::Scenario scenario = nominal;
  scenario.effects.clear();
  scenario.duration_s = TwinDurationS(recording, false);
  auto plain = PlainSimulationRunner()(scenario);
  if (!plain.ok()) return Status::Error("the nominal simulation: " + plain.status().message());
  const DriveComparison drive_difference = CompareDrive(recording, plain.value());
  out.stream = drive_difference.stream;
  if (!drive_difference.stream.empty()) out.mismatch = drive_difference.relative;
  if (!drive_difference.stream.empty() && drive_difference.relative < kMaxDriveMismatch) {
    out.reason = "own drive detected";
    return out;
  }
  if (auto inputs = sim::DriveInputsFrom(recording, nominal); !inputs.ok()) {
    out.reason = "not shown to be the scenario's own drive, but no replay (" + inputs.status().message() + ")";
    return out;
  }
  out.replayed = true;
  out.reason = "other drive detected";
  return out;
}

Result<SimulationComparison> CompareWithSimulation(const sim::Scenario& nominal,
                                                   const std::vector<EffectEstimate>& effects,
                                                   const recording::Recording& recording, double from_s,
                                                   const TwinChoice& twin,
                                                   const std::optional<std::vector<sim::EffectOptions>>& patch) {
  if (recording.platform.kind != nominal.robot.kind)
    return Status::Error("the recording's platform kind '" + recording.platform.kind + "' is not the scenario's '" +
                         nominal.robot.kind + "'");
  SimulationComparison out;
  out.from_s = from_s;
  out.twin = twin;
  sim::Scenario scenario = nominal;
  scenario.effects.clear();
  scenario.duration_s = TwinDurationS(recording, twin.replayed);
  out.duration_s = scenario.duration_s;
  const TwinRunner runner = twin.replayed ? ReplayRunner(recording) : PlainSimulationRunner();
  const Time from = Time::FromSeconds(from_s);
  auto simulator = sim::Simulator::Create(scenario, {});
  if (!simulator.ok()) return Status::Error("the nominal scenario: " + simulator.status().message());
  const double step_s = simulator.value()->PhysicsStepS();
  for (const bool patched : {false, true}) {
    if (patched) {
      if (patch) {
        scenario.effects = *patch;
      } else {
        for (const EffectEstimate& e : effects) scenario.effects.push_back(SimulatorEffect(e, nullptr, step_s));
      }
      out.effects = scenario.effects;
    }
    auto simulated = runner(scenario);
    if (!simulated.ok() && !patched) return Status::Error("the nominal twin: " + simulated.status().message());
    if (!simulated.ok()) {
      out.not_simulated = simulated.status().message();
      break;
    }
    (patched ? out.after : out.before) = Compare(recording, simulated.value(), from, patched ? nullptr : &out.left_out);
    (patched ? out.twin_after : out.twin_before) = std::move(simulated).value();
  }
  return out;
}

}  // namespace roamlab::gap
