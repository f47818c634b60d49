// roamlab_bench: the speed yardsticks of the ATV issue, measured in one run on this machine and printed as ratios to
// their targets. Not a test: timings depend on the machine and its load.
//
//   roamlab_bench [--quick] [--json OUT.json]
//
// simulation of scenarios/atv_hills.yaml with all sensors (multiple of real time; target >= 10x), online tracking of
// that recording with scenarios/atv_tracking.yaml and a 40-pose window (multiple of real time, target >= 20x; p99
// update latency), and a Monte-Carlo of N runs on all cores (50 runs must take under 3 minutes; --quick runs 4 and
// extrapolates, saying so); CGP (seed 001) training on 2000 pairs with its hyper-parameter optimization (target < 30 s)
// and its mean prediction per query (target < 50 us).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "apps/montecarlo.h"
#include "estimator/odometry/gaussian_process.h"
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

// CGP (seed 001) training with n = 2000 pairs of a differential drive (hyper-parameter optimization included; mean
// linear, kernel rbf, the default subset) and the mean prediction per query (targets: < 30 s, < 50 us).
struct CgpTiming {
  double train_s = 0.0;
  double predict_us = 0.0;
};
CgpTiming BenchCgp() {
  const int n = 2000;
  std::mt19937_64 rng(1);
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::MatrixXd X(n, 2), Y(n, 3);
  for (int k = 0; k < n; ++k) {
    const double forward = 4.0 + 2.0 * normal(rng), turn = 1.5 * normal(rng);
    X.row(k) << forward + turn, forward - turn;
    const double th = 0.205 * (X(k, 0) - X(k, 1)), v = 0.021 * (X(k, 0) + X(k, 1));
    Y.row(k) << v * std::cos(0.5 * th) + 1e-3 * normal(rng), v * std::sin(0.5 * th) + 1e-3 * normal(rng),
        th + 1e-3 * normal(rng);
  }
  const Eigen::MatrixXd noise = Eigen::MatrixXd::Constant(n, 3, 1e-6);
  const auto t_train = Clock::now();
  auto gp = roamlab::estimator::odometry::GaussianProcess::Train(X, Y, noise, {});
  CgpTiming timing;
  timing.train_s = Since(t_train);
  if (!gp.ok()) return timing;
  const int queries = 20000;
  double sink = 0.0;
  const auto t_predict = Clock::now();
  for (int q = 0; q < queries; ++q) sink += gp.value().PredictMean(X.row(q % n).transpose())[2];
  timing.predict_us = 1e6 * Since(t_predict) / queries;
  if (!std::isfinite(sink)) timing.predict_us = std::nan("");  // uses the predictions: they cannot be elided
  return timing;
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

  const CgpTiming cgp = BenchCgp();

  // Report: value, target, ratio (>= 1 means the target is met).
  std::printf("roamlab_bench on %u cores%s\n", std::thread::hardware_concurrency(), quick ? " (--quick)" : "");
  std::printf("  simulation, all sensors        %7.1fx real time   target >= 10x   ratio %.2f\n", sim_factor,
              sim_factor / 10.0);
  std::printf("  tracking, 40-pose window       %7.1fx real time   target >= 20x   ratio %.2f   (p99 update %.2f ms)\n",
              track_factor, track_factor / 20.0, 1e3 * tracked.value().p99_update_s);
  std::printf("  montecarlo, 50 runs            %7.2f min%s     target <= 3 min ratio %.2f\n", mc50_minutes,
              quick ? " (from 4)" : "        ", 3.0 / mc50_minutes);
  std::printf("  CGP training, n = 2000         %7.2f s             target <= 30 s  ratio %.2f\n", cgp.train_s,
              30.0 / cgp.train_s);
  std::printf("  CGP mean prediction            %7.2f us per query  target <= 50 us ratio %.2f\n", cgp.predict_us,
              50.0 / cgp.predict_us);
  if (!json_path.empty()) {
    const nlohmann::json j = {{"simulation_realtime_factor", sim_factor},
                              {"tracking_realtime_factor_w40", track_factor},
                              {"tracking_p99_ms_w40", 1e3 * tracked.value().p99_update_s},
                              {"montecarlo_runs", runs},
                              {"montecarlo_50_runs_minutes", mc50_minutes},
                              {"cgp_train_s_n2000", cgp.train_s},
                              {"cgp_predict_us", cgp.predict_us},
                              {"quick", quick}};
    std::ofstream(json_path) << j.dump(2) << "\n";
  }
  return 0;
}
