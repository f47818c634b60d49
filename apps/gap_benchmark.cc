#include "apps/gap_benchmark.h"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <random>
#include <sstream>

#include <nlohmann/json.hpp>

#include "gap/diagnose.h"
#include "recording/recording.h"
#include "recording/truth.h"
#include "sim/scenario.h"
#include "sim/simulator.h"

namespace roamlab::apps {
namespace {

using nlohmann::json;

constexpr std::uint64_t kBaselineSeed = 900001;

// One drawn case: the effect hidden in the scenario (empty name: none) and its kind.
struct Draw {
  std::string kind;   // none | effect | decoy
  sim::EffectOptions effect;
};

Draw DrawCase(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto sign = [&] { return u(rng) < 0.5 ? -1.0 : 1.0; };
  const auto round_to = [](double x, double step) { return std::round(x / step) * step; };
  Draw d;
  const double kind = u(rng);
  if (kind < 0.2) {
    d.kind = "none";
    return d;
  }
  if (kind < 0.35) {
    d.kind = "decoy";
    Eigen::Vector3d direction(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5);
    direction = direction.normalized() * (3e-4 + 3e-4 * u(rng));
    d.effect = {"magnetometer_motor_interference",
                {{"b_per_nm_x", direction.x()}, {"b_per_nm_y", direction.y()}, {"b_per_nm_z", direction.z()}}};
    return d;
  }
  d.kind = "effect";
  switch (static_cast<int>(4.0 * u(rng))) {
    case 0:
      d.effect = {"gps_latency", {{"latency_s", round_to(0.2 + 0.2 * u(rng), 0.001)}}};
      break;
    case 1:
      d.effect = {"imu_time_offset", {{"offset_s", sign() * round_to(0.02 + 0.03 * u(rng), 0.001)}}};
      break;
    case 2:
      d.effect = {"steering_offset", {{"offset_rad", sign() * (0.015 + 0.025 * u(rng))}}};
      break;
    default: {
      const std::string axis(1, "xyz"[static_cast<int>(3.0 * u(rng)) % 3]);
      d.effect = {"gyro_scale_error", {{"scale_" + axis, 1.0 + sign() * (0.03 + 0.03 * u(rng))}}};
    }
  }
  return d;
}

// Scores a diagnosis against the truth (read after the diagnosis): whether it is right, and why not.
bool Score(const std::string& kind, const recording::Truth& truth, const gap::Diagnosis& d, std::string* why) {
  if (kind == "none") {
    *why = d.verdict == "none" ? "" : "expected none, got " + d.verdict;
    return d.verdict == "none";
  }
  if (kind == "decoy") {
    const bool ok = d.verdict != "named";
    *why = ok ? "" : "a decoy outside the library was named " + d.effects.front().name;
    return ok;
  }
  if (d.verdict != "named" || truth.effects.empty() || d.effects.front().name != truth.effects.front().name) {
    *why = "expected " + (truth.effects.empty() ? std::string("?") : truth.effects.front().name) + ", got " +
           (d.effects.empty() ? d.verdict : d.effects.front().name);
    return false;
  }
  const gap::EffectEstimate& e = d.effects.front();
  for (const auto& [name, value] : truth.effects.front().parameters) {
    if (!e.parameters.count(name) || !e.std.count(name)) continue;
    const double error = e.parameters.at(name) - value;
    if (!(std::abs(error) <= 3.0 * e.std.at(name))) {
      std::ostringstream s;
      s << name << " off by " << error << " (" << error / e.std.at(name) << " std)";
      *why = s.str();
      return false;
    }
  }
  return true;
}

}  // namespace

int RunGapBenchmark(const GapBenchmarkArgs& args) {
  std::ostream& err = args.err ? *args.err : std::cerr;
  const auto say = [&](const std::string& line) {
    if (!args.quiet) std::cout << line << std::endl;
  };
  if (args.cases < 1) {
    err << "roamlab gap-benchmark: --cases must be >= 1\n";
    return 2;
  }
  auto scenario = sim::LoadScenario(args.scenario);
  if (!scenario.ok()) {
    err << "roamlab gap-benchmark: " << scenario.status().message() << "\n";
    return 2;
  }
  auto config = gap::NominalConfig(scenario.value());
  if (!config.ok()) {
    err << "roamlab gap-benchmark: " << args.scenario << ": " << config.status().message() << "\n";
    return 2;
  }
  std::error_code ec;
  std::filesystem::create_directories(args.out + "/cases", ec);
  if (ec) {
    err << "roamlab gap-benchmark: " << args.out << ": cannot create the output directory\n";
    return 2;
  }
  const auto start = std::chrono::steady_clock::now();

  // The baseline, once.
  sim::Scenario nominal = scenario.value();
  nominal.effects.clear();
  sim::SimulateOptions base_options;
  base_options.seed = kBaselineSeed;
  say("baseline: nominal simulation, seed " + std::to_string(kBaselineSeed));
  auto base_sim = sim::Simulate(nominal, base_options);
  if (!base_sim.ok()) {
    err << "roamlab gap-benchmark: nominal simulation: " << base_sim.status().message() << "\n";
    return 1;
  }
  gap::DiagnoseOptions learn;
  learn.max_effects = 0;
  auto learned = gap::Diagnose(config.value(), base_sim.value().recording, learn);
  if (!learned.ok()) {
    err << "roamlab gap-benchmark: baseline: " << learned.status().message() << "\n";
    return 1;
  }
  const gap::Baseline baseline = gap::BaselineFrom(learned.value());

  std::mt19937_64 rng(args.seed);
  json cases = json::array();
  int correct = 0;
  std::map<std::string, std::pair<int, int>> by_kind;
  for (int i = 0; i < args.cases; ++i) {
    std::ostringstream name;
    name << std::setw(3) << std::setfill('0') << i;
    const std::string dir = args.out + "/cases/" + name.str() + "/rec";
    const Draw draw = DrawCase(rng);
    sim::Scenario s = scenario.value();
    s.effects.clear();
    if (draw.kind != "none") s.effects.push_back(draw.effect);
    sim::SimulateOptions options;
    options.seed = args.seed * 1000 + static_cast<std::uint64_t>(i);
    say("case " + name.str() + ": simulating (" + draw.kind + ")");
    auto simulated = sim::Simulate(s, options);
    if (!simulated.ok()) {
      err << "roamlab gap-benchmark: case " << name.str() << ": " << simulated.status().message() << "\n";
      return 1;
    }
    std::filesystem::create_directories(dir, ec);
    if (Status st = recording::WriteRecording(simulated.value().recording, dir); !st.ok()) {
      err << "roamlab gap-benchmark: " << st.message() << "\n";
      return 1;
    }
    if (Status st = recording::WriteTruth(simulated.value().truth, dir); !st.ok()) {
      err << "roamlab gap-benchmark: " << st.message() << "\n";
      return 1;
    }
    // Blind: the diagnosis reads the written recording's streams only.
    recording::ReadOptions read;
    read.load_ground_truth = false;
    auto rec = recording::ReadRecording(dir, read);
    if (!rec.ok()) {
      err << "roamlab gap-benchmark: " << rec.status().message() << "\n";
      return 1;
    }
    gap::DiagnoseOptions options_d;
    options_d.baseline = &baseline;
    auto d = gap::Diagnose(config.value(), rec.value(), options_d);
    if (!d.ok()) {
      err << "roamlab gap-benchmark: case " << name.str() << ": " << d.status().message() << "\n";
      return 1;
    }
    // Scoring: now, and only now, the truth.
    auto truth = recording::ReadTruth(dir);
    if (!truth.ok()) {
      err << "roamlab gap-benchmark: " << truth.status().message() << "\n";
      return 1;
    }
    std::string why;
    const bool ok = Score(draw.kind, truth.value(), d.value(), &why);
    correct += ok;
    by_kind[draw.kind].first += ok;
    ++by_kind[draw.kind].second;
    json named = json::array(), parameters = json::object(), stds = json::object(), truth_parameters = json::object();
    for (const gap::EffectEstimate& e : d.value().effects) named.push_back(e.name);
    if (!d.value().effects.empty()) {
      for (const auto& [k, v] : d.value().effects.front().parameters) parameters[k] = v;
      for (const auto& [k, v] : d.value().effects.front().std) stds[k] = std::isfinite(v) ? json(v) : json(nullptr);
    }
    for (const auto& [k, v] : draw.effect.parameters) truth_parameters[k] = v;
    cases.push_back({{"case", name.str()},
                     {"kind", draw.kind},
                     {"truth", {{"name", draw.effect.name}, {"parameters", truth_parameters}}},
                     {"verdict", d.value().verdict},
                     {"named", named},
                     {"parameters", parameters},
                     {"std", stds},
                     {"correct", ok},
                     {"why", why}});
    say("case " + name.str() + ": " + draw.kind + " " + draw.effect.name + " -> " + d.value().verdict +
        (d.value().effects.empty() ? std::string() : " " + d.value().effects.front().name) +
        (ok ? ": correct" : ": wrong (" + why + ")"));
  }
  json kinds = json::object();
  for (const auto& [kind, c] : by_kind) kinds[kind] = {{"correct", c.first}, {"total", c.second}};
  const json score = {{"cases", cases},
                      {"correct", correct},
                      {"total", args.cases},
                      {"by_kind", kinds},
                      {"seed", args.seed},
                      {"seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()}};
  std::ofstream out(args.out + "/score.json");
  out << score.dump(2) << "\n";
  if (!out) {
    err << "roamlab gap-benchmark: " << args.out << "/score.json: cannot write\n";
    return 1;
  }
  say("score: " + std::to_string(correct) + "/" + std::to_string(args.cases) + " (" + args.out + "/score.json)");
  return 0;
}

}  // namespace roamlab::apps
