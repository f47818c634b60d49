// roamlab_bench: the speed yardsticks of the ATV issue, measured in one run on this machine and printed as ratios to
// their targets. Not a test: timings depend on the machine and its load.
//
//   roamlab_bench [--quick] [--json OUT.json]
//
// simulation of scenarios/atv_hills.yaml with all sensors (multiple of real time; target >= 10x), online tracking of
// that recording with scenarios/atv_tracking.yaml and a 40-pose window (multiple of real time, target >= 20x; p99
// update latency), and a Monte-Carlo of N runs on all cores (50 runs must take under 3 minutes; --quick runs 4 and
// extrapolates, saying so). Also the indoor issue's yardstick: simulation of scenarios/indoor_diffdrive_slip.yaml
// (differential drive, IMU, encoders, 683-beam laser with scan matching; no rendering), target >= 10x.
#include <chrono>
#include <ctime>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "apps/montecarlo.h"
#include "estimator/config.h"
#include "estimator/tracking.h"
#include "sim/scenario.h"
#include "sim/simulator.h"

namespace {

using Clock = std::chrono::steady_clock;
double Since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

int Fail(const std::string& message) {
  std::fprintf(stderr, "roamlab_bench: %s\n", message.c_str());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  std::string json_path;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--quick") == 0) {
      quick = true;
    } else if (std::strcmp(argv[i], "--json") == 0 && i + 1 < argc) {
      json_path = argv[++i];
    } else {
      std::fprintf(stderr, "usage: roamlab_bench [--quick] [--json OUT.json]\n");
      return 2;
    }
  }
  const std::string root = ROAMLAB_SOURCE_DIR;
  const std::string scenario_path = root + "/scenarios/atv_hills.yaml";
  const std::string tracking_path = root + "/scenarios/atv_tracking.yaml";
  auto scenario = roamlab::sim::LoadScenario(scenario_path);
  if (!scenario.ok()) return Fail(scenario.status().message());
  auto config = roamlab::estimator::LoadEstimatorConfig(tracking_path);
  if (!config.ok()) return Fail(config.status().message());

  // Simulation with every sensor.
  const auto t_sim = Clock::now();
  auto simulation = roamlab::sim::Simulate(scenario.value());
  const double sim_wall = Since(t_sim);
  if (!simulation.ok()) return Fail(simulation.status().message());
  const double simulated = simulation.value().stats.simulated_s;
  const double sim_factor = simulated / sim_wall;

  // Indoor simulation without rendering (laser ray casts and scan matching included); CPU time is printed too, since
  // on a shared machine the wall clock also counts other processes.
  auto indoor = roamlab::sim::LoadScenario(root + "/scenarios/indoor_diffdrive_slip.yaml");
  if (!indoor.ok()) return Fail(indoor.status().message());
  const auto t_indoor = Clock::now();
  const std::clock_t cpu_indoor = std::clock();
  auto indoor_simulation = roamlab::sim::Simulate(indoor.value());
  const double indoor_wall = Since(t_indoor);
  const double indoor_cpu = static_cast<double>(std::clock() - cpu_indoor) / CLOCKS_PER_SEC;
  if (!indoor_simulation.ok()) return Fail(indoor_simulation.status().message());
  const double indoor_factor = indoor_simulation.value().stats.simulated_s / indoor_wall;
  const double indoor_cpu_factor = indoor_simulation.value().stats.simulated_s / indoor_cpu;

  // Online tracking, 40-pose window.
  config.value().tracking.window = 40;
  auto tracked = roamlab::estimator::Track(config.value(), simulation.value().recording, {});
  if (!tracked.ok()) return Fail(tracked.status().message());
  const auto& traj = tracked.value().trajectory;
  const double duration = roamlab::SecondsBetween(traj.front().t, traj.back().t);
  const double track_factor = duration / tracked.value().total_seconds;

  // Monte-Carlo over all cores.
  const int runs = quick ? 4 : 50;
  const std::string mc_dir = (std::filesystem::temp_directory_path() / "roamlab_bench_mc").string();
  roamlab::apps::MonteCarloArgs mc;
  mc.scenario = scenario_path;
  mc.config = tracking_path;
  mc.out = mc_dir;
  mc.runs = runs;
  mc.quiet = true;
  const auto t_mc = Clock::now();
  if (roamlab::apps::RunMonteCarlo(mc) != 0) return Fail("montecarlo failed");
  const double mc_seconds = Since(t_mc);
  std::filesystem::remove_all(mc_dir);
  const double mc50_minutes = mc_seconds / runs * 50.0 / 60.0;

  // Report: value, target, ratio (>= 1 means the target is met).
  std::printf("roamlab_bench on %u cores%s\n", std::thread::hardware_concurrency(), quick ? " (--quick)" : "");
  std::printf("  simulation, all sensors        %7.1fx real time   target >= 10x   ratio %.2f\n", sim_factor,
              sim_factor / 10.0);
  std::printf("  indoor simulation, no render   %7.1fx real time   target >= 10x   ratio %.2f   (CPU time: %.1fx)\n",
              indoor_factor, indoor_factor / 10.0, indoor_cpu_factor);
  std::printf("  tracking, 40-pose window       %7.1fx real time   target >= 20x   ratio %.2f   (p99 update %.2f ms)\n",
              track_factor, track_factor / 20.0, 1e3 * tracked.value().p99_update_s);
  std::printf("  montecarlo, 50 runs            %7.2f min%s     target <= 3 min ratio %.2f\n", mc50_minutes,
              quick ? " (from 4)" : "        ", 3.0 / mc50_minutes);
  if (!json_path.empty()) {
    const nlohmann::json j = {{"simulation_realtime_factor", sim_factor},
                              {"indoor_simulation_realtime_factor", indoor_factor},
                              {"tracking_realtime_factor_w40", track_factor},
                              {"tracking_p99_ms_w40", 1e3 * tracked.value().p99_update_s},
                              {"montecarlo_runs", runs},
                              {"montecarlo_50_runs_minutes", mc50_minutes},
                              {"quick", quick}};
    std::ofstream(json_path) << j.dump(2) << "\n";
  }
  return 0;
}
