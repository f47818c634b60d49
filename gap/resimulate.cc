#include "gap/resimulate.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "estimator/models/enu.h"
#include "sim/simulator.h"

namespace roamlab::gap {
namespace {

using recording::Stream;
using recording::StreamType;

// lateral_slip: the rear cornering compliance the tires' contact time scale adds per unit above 1 [s]
// (sim/scenario.h, measured on the truth of atv_hills_sines.yaml).
constexpr double kRearCompliancePerContactScale = 0.0203;

double Noise(const recording::StreamInfo& info, const std::string& key) {
  const auto it = info.noise.find(key);
  return it != info.noise.end() ? it->second : 0.0;
}

// The stated noise of each compared column (positive), or empty when the stream states none.
std::vector<double> ColumnSigmas(const recording::StreamInfo& info) {
  const auto repeat = [](double sigma, int n) { return std::vector<double>(static_cast<std::size_t>(n), sigma); };
  switch (info.type) {
    case StreamType::kImu: {
      std::vector<double> s = repeat(Noise(info, "gyro_sigma_radps"), 3);
      const std::vector<double> a = repeat(Noise(info, "accel_sigma_mps2"), 3);
      s.insert(s.end(), a.begin(), a.end());
      return s;
    }
    case StreamType::kGps:
    case StreamType::kPosition:
      return repeat(Noise(info, "sigma_m"), 3);
    case StreamType::kOdometry:
    case StreamType::kVisualOdometry:
    case StreamType::kScanMatching: {
      std::vector<double> s = repeat(Noise(info, "sigma_mps"), 3);
      const std::vector<double> w = repeat(Noise(info, "sigma_radps"), 3);
      s.insert(s.end(), w.begin(), w.end());
      return s;
    }
    case StreamType::kWheelEncoders: {
      const int n = static_cast<int>(info.columns.size());
      const auto ticks = info.attributes.find("ticks_per_revolution");
      if (info.units == "rad" && ticks != info.attributes.end() && ticks->second > 0.0)
        return repeat(2.0 * M_PI / ticks->second / std::sqrt(12.0), n);
      for (const char* key : {"sigma_mps", "sigma_radps", "sigma_rad"})
        if (Noise(info, key) > 0.0) return repeat(Noise(info, key), n);
      return {};
    }
    case StreamType::kCamera:
    case StreamType::kInputs:
    case StreamType::kPose:
      return {};
    default:
      // One stated sigma for every column (gyroscope, accelerometer, magnetometer, steering).
      if (info.noise.size() != 1) return {};
      return repeat(info.noise.begin()->second, static_cast<int>(info.columns.size()));
  }
}

// Whitened residuals of one stream (or the imu's gyroscope or accelerometer columns): sums of squares per component,
// and their 1 s means (WindowMeans, as StreamFits).
struct Accumulator {
  explicit Accumulator(int components) : sum_squares(static_cast<std::size_t>(components), 0.0) {}

  void Add(Time t, const Eigen::VectorXd& whitened) {
    for (int k = 0; k < whitened.size(); ++k) sum_squares[static_cast<std::size_t>(k)] += whitened[k] * whitened[k];
    ++samples;
    windows.Add(t, whitened);
  }

  SimulatedStreamFit Fit() const {
    SimulatedStreamFit f;
    f.samples = samples;
    double total = 0.0;
    for (double s : sum_squares) {
      f.component_rms.push_back(samples > 0 ? std::sqrt(s / samples) : 0.0);
      total += s;
    }
    const double count = static_cast<double>(samples) * static_cast<double>(sum_squares.size());
    f.rms = count > 0.0 ? std::sqrt(total / count) : 0.0;
    f.rms_1s = windows.Rms();
    return f;
  }

  std::vector<double> sum_squares;
  int samples = 0;
  WindowMeans windows;
};

// Compares every stream of `recorded` with the same-named stream of `simulated`, from `from` on.
std::map<std::string, SimulatedStreamFit> Compare(const recording::Recording& recorded,
                                                  const recording::Recording& simulated, Time from,
                                                  std::vector<std::string>* left_out) {
  std::map<std::string, SimulatedStreamFit> out;
  std::optional<estimator::EnuConverter> enu;
  if (recorded.origin) enu.emplace(*recorded.origin);
  for (const Stream& rec : recorded.streams) {
    const Stream* sim = simulated.Find(rec.info.name);
    const std::vector<double> sigma = ColumnSigmas(rec.info);
    const bool stated = !sigma.empty() && std::all_of(sigma.begin(), sigma.end(), [](double s) { return s > 0.0; });
    std::string why;
    if (!sim || sim->info.type != rec.info.type || sim->info.columns.size() < sigma.size())
      why = "not in the simulation";
    else if (!stated)
      why = "no stated noise";
    else if (rec.info.type == StreamType::kGps && !enu)
      why = "no origin";
    if (!why.empty()) {
      if (left_out) left_out->push_back(rec.info.name + ": " + why);
      continue;
    }
    const int n = static_cast<int>(sigma.size());
    const auto value = [&](const Stream& s, std::size_t row) {
      Eigen::VectorXd v = s.values.row(static_cast<Eigen::Index>(row)).head(n).transpose();
      if (s.info.type == StreamType::kGps) v = enu->ToEnu(v[0], v[1], v[2]);
      return v;
    };
    const bool imu = rec.info.type == StreamType::kImu;
    Accumulator gyro(3), accel(3), whole(n);
    std::size_t j = 0;
    for (std::size_t i = 0; i < rec.t.size(); ++i) {
      if (rec.t[i] < from) continue;
      while (j < sim->t.size() && sim->t[j] < rec.t[i]) ++j;
      if (j == sim->t.size()) break;
      if (sim->t[j] != rec.t[i]) continue;
      Eigen::VectorXd w = value(rec, i) - value(*sim, j);
      for (int k = 0; k < n; ++k) w[k] /= sigma[static_cast<std::size_t>(k)];
      if (imu) {
        gyro.Add(rec.t[i], w.head(3));
        accel.Add(rec.t[i], w.tail(3));
      } else {
        whole.Add(rec.t[i], w);
      }
    }
    if (imu) {
      out["gyroscope"] = gyro.Fit();
      out["accelerometer"] = accel.Fit();
    } else {
      out[rec.info.name] = whole.Fit();
    }
  }
  return out;
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
