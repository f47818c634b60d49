#include "apps/montecarlo.h"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <mutex>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "apps/simulate.h"
#include "estimator/calibration.h"
#include "estimator/config.h"
#include "estimator/tracking.h"
#include "eval/nees.h"
#include "eval/plots.h"
#include "sim/scenario.h"
#include "sim/simulator.h"

namespace roamlab::apps {
namespace {

struct RunResult {
  std::vector<Time> t;
  std::vector<double> nees;
  double ate_m = 0.0;
  double mean_nees = 0.0;
  double track_seconds = 0.0;
  std::string error;  // empty when the run succeeded
};

// One realization: simulate, track, NEES of every tracked pose against the ground truth at the same time stamp.
RunResult OneRun(const sim::Scenario& scenario, const estimator::EstimatorConfig& config,
                 const std::map<std::string, Eigen::VectorXd>& calibration,
                 const estimator::TrackingOptions& tracking_options, std::uint64_t seed) {
  RunResult r;
  sim::SimulateOptions sim_options;
  sim_options.seed = seed;
  auto simulation = sim::Simulate(scenario, sim_options);
  if (!simulation.ok()) {
    r.error = "seed " + std::to_string(seed) + ": " + simulation.status().message();
    return r;
  }
  const recording::Recording& rec = simulation.value().recording;
  auto tracked = estimator::Track(config, rec, calibration, tracking_options);
  if (!tracked.ok()) {
    r.error = "seed " + std::to_string(seed) + ": " + tracked.status().message();
    return r;
  }
  const estimator::TrackingResult& tr = tracked.value();
  const Trajectory& truth = *rec.ground_truth;
  std::size_t j = 0;
  double sq = 0.0;
  for (std::size_t i = 0; i < tr.trajectory.size(); ++i) {
    while (j < truth.size() && truth[j].t < tr.trajectory[i].t) ++j;
    if (j == truth.size() || truth[j].t != tr.trajectory[i].t) continue;
    const Eigen::Vector3d e = tr.trajectory[i].p_world_body - truth[j].p_world_body;
    r.t.push_back(tr.trajectory[i].t);
    r.nees.push_back(eval::PositionNees(e, tr.position_covariance[i]));
    sq += e.squaredNorm();
  }
  if (r.t.empty()) {
    r.error = "seed " + std::to_string(seed) + ": no tracked pose has a ground-truth pose at the same time";
    return r;
  }
  r.ate_m = std::sqrt(sq / r.t.size());
  double sum = 0.0;
  for (double n : r.nees) sum += n;
  r.mean_nees = sum / r.nees.size();
  r.track_seconds = tr.total_seconds;
  return r;
}

// The calibration a run tracks with: its values and, under tracking.calibration_prior, their prior.
struct RunCalibration {
  std::map<std::string, Eigen::VectorXd> values;
  estimator::TrackingOptions options;
};

// Run `seed`'s own calibration: the scenario simulated with `seed` (a realization apart from the tracked one) and
// calibrated with `warm`, the calibration configuration warm-started at the shared calibration (see RunMonteCarlo).
Result<RunCalibration> CalibrateRun(const sim::Scenario& scenario, const estimator::EstimatorConfig& warm,
                                    bool prior, std::uint64_t seed) {
  sim::SimulateOptions sim_options;
  sim_options.seed = seed;
  auto simulation = sim::Simulate(scenario, sim_options);
  if (!simulation.ok()) return Status::Error("calibration seed " + std::to_string(seed) + ": " +
                                             simulation.status().message());
  auto calibrated = estimator::Calibrate(warm, simulation.value().recording);
  if (!calibrated.ok()) return Status::Error("calibration seed " + std::to_string(seed) + ": " +
                                             calibrated.status().message());
  RunCalibration out;
  estimator::CalibrationPrior p;
  for (const estimator::ParameterEstimate& e : calibrated.value().parameters) {
    out.values[e.name] = e.estimate;
    p.names.push_back(e.name);
  }
  p.information = calibrated.value().information;
  if (prior) out.options.calibration_prior = std::move(p);
  return out;
}

// The calibration configuration `path` warm-started at `values`: one stage with every free parameter.
Result<estimator::EstimatorConfig> WarmCalibrationConfig(const std::string& path,
                                                         const std::map<std::string, Eigen::VectorXd>& values) {
  auto config = estimator::LoadEstimatorConfig(path);
  if (!config.ok()) return config.status();
  std::vector<std::string> free;
  for (auto& [name, p] : config.value().parameters) {
    if (values.count(name)) p.value = values.at(name);
    if (p.free) free.push_back(name);
  }
  config.value().stages = {free};
  return config;
}

int Fail(std::ostream* err, const std::string& message, int code) {
  (err ? *err : std::cerr) << "roamlab montecarlo: " << message << "\n";
  return code;
}

// Simulates the scenario with `seed` into OUT/calibration/recording and calibrates it with `calibration_config` into
// OUT/calibration; `file` receives OUT/calibration/calibration.json. Returns the failing command's exit code.
int CalibrateOnce(const MonteCarloArgs& args, std::uint64_t seed, const std::string& calibration_config,
                  std::string* file) {
  const std::string dir = (std::filesystem::path(args.out) / "calibration").string();
  if (!args.quiet)
    std::cerr << "montecarlo: calibrating once with " << calibration_config << " on the scenario's own noise seed "
              << seed << " (" << dir << ")\n";
  SimulateArgs simulate;
  simulate.scenario = args.scenario;
  simulate.out = dir + "/recording";
  simulate.seed = seed;
  simulate.quiet = true;
  simulate.err = args.err;
  if (const int code = RunSimulate(simulate); code != 0) return code;
  CalibrateArgs calibrate;
  calibrate.recording = simulate.out;
  calibrate.config = calibration_config;
  calibrate.out = dir;
  calibrate.quiet = true;
  calibrate.err = args.err;
  if (const int code = RunCalibrate(calibrate); code != 0) return code;
  *file = dir + "/calibration.json";
  return 0;
}

}  // namespace

int RunMonteCarlo(const MonteCarloArgs& args) {
  if (args.runs < 1) return Fail(args.err, "--runs must be at least 1", 2);
  if (args.jobs < 0) return Fail(args.err, "--jobs must be >= 0", 2);
  auto scenario = sim::LoadScenario(args.scenario);
  if (!scenario.ok()) return Fail(args.err, scenario.status().message(), 2);
  auto config = estimator::LoadEstimatorConfig(args.config);
  if (!config.ok()) return Fail(args.err, config.status().message(), 2);
  if (args.no_time_budget) config.value().tracking.time_budget_s = std::numeric_limits<double>::infinity();
  std::error_code ec;
  std::filesystem::create_directories(args.out, ec);
  if (ec) return Fail(args.err, args.out + ": cannot create the output directory: " + ec.message(), 2);

  // The calibration tracking starts from: the given file, or (tracking.calibrate) one offline calibration of the
  // scenario simulated with its own noise seed, a realization apart from the runs' (seed_base + i).
  std::string calibration_file = args.calibration;
  if (calibration_file.empty() && !config.value().tracking.calibrate.empty()) {
    const int code = CalibrateOnce(args, scenario.value().seed, config.value().tracking.calibrate, &calibration_file);
    if (code != 0) return code;
  }
  std::map<std::string, Eigen::VectorXd> calibration;
  if (!calibration_file.empty()) {
    auto cal = ReadCalibrationValues(calibration_file);
    if (!cal.ok()) return Fail(args.err, cal.status().message(), 2);
    calibration = std::move(cal).value();
  }
  auto tracking_options = TrackingOptionsFor(config.value(), calibration_file);
  if (!tracking_options.ok()) return Fail(args.err, tracking_options.status().message(), 2);
  const bool per_run = args.calibration.empty() && !config.value().tracking.calibrate.empty() && args.calibrate_each_run;
  estimator::EstimatorConfig warm;
  if (per_run) {
    auto w = WarmCalibrationConfig(config.value().tracking.calibrate, calibration);
    if (!w.ok()) return Fail(args.err, w.status().message(), 2);
    warm = std::move(w).value();
    if (!args.quiet)
      std::cerr << "montecarlo: each run also calibrates a drive of its own (noise seed " << args.seed_base
                << " + " << kCalibrationSeedOffset << " + i), warm-started there\n";
  }

  // Runs spread over worker threads; each writes only its own slot, so the result does not depend on scheduling.
  const int jobs = args.jobs > 0 ? args.jobs : std::max(1u, std::thread::hardware_concurrency());
  std::vector<RunResult> results(args.runs);
  std::atomic<int> next{0}, done{0};
  std::mutex print;
  const auto worker = [&] {
    for (int i = next++; i < args.runs; i = next++) {
      if (per_run) {
        auto own = CalibrateRun(scenario.value(), warm, config.value().tracking.calibration_prior,
                                args.seed_base + kCalibrationSeedOffset + i);
        if (own.ok()) {
          results[i] = OneRun(scenario.value(), config.value(), own.value().values, own.value().options,
                              args.seed_base + i);
        } else {
          results[i].error = own.status().message();
        }
      } else {
        results[i] =
            OneRun(scenario.value(), config.value(), calibration, tracking_options.value(), args.seed_base + i);
      }
      const int finished = ++done;
      if (!args.quiet) {
        std::lock_guard<std::mutex> lock(print);
        const int width = 40, filled = width * finished / args.runs;
        std::cerr << "\rmontecarlo [" << std::string(filled, '#') << std::string(width - filled, ' ') << "] "
                  << finished << "/" << args.runs << std::flush;
      }
    }
  };
  std::vector<std::thread> threads;
  for (int k = 0; k < std::min(jobs, args.runs); ++k) threads.emplace_back(worker);
  for (auto& th : threads) th.join();
  if (!args.quiet) std::cerr << "\n";
  for (const RunResult& r : results)
    if (!r.error.empty()) return Fail(args.err, r.error, 1);

  // A common time grid: the stamps every run has (they share the master stream's rate).
  std::vector<Time> grid = results.front().t;
  for (const RunResult& r : results) {
    std::vector<Time> common;
    std::set_intersection(grid.begin(), grid.end(), r.t.begin(), r.t.end(), std::back_inserter(common));
    grid = std::move(common);
  }
  if (grid.empty()) return Fail(args.err, "the runs share no time stamp", 1);
  std::vector<std::vector<double>> series;
  for (const RunResult& r : results) {
    std::vector<double> s;
    std::size_t j = 0;
    for (Time t : grid) {
      while (r.t[j] != t) ++j;
      s.push_back(std::isnan(r.nees[j]) ? std::numeric_limits<double>::infinity() : r.nees[j]);
    }
    series.push_back(std::move(s));
  }
  const eval::MonteCarloNees nees = eval::AggregateNees(grid, series, 3, args.t0_s);

  // Outputs: nees.json, runs.json, nees.png.
  std::ofstream(args.out + "/nees.json") << eval::NeesJson(nees).dump(2) << "\n";
  nlohmann::json runs = nlohmann::json::array();
  for (int i = 0; i < args.runs; ++i)
    runs.push_back({{"seed", args.seed_base + i},
                    {"ate_m", results[i].ate_m},
                    {"mean_nees", results[i].mean_nees},
                    {"track_seconds", results[i].track_seconds}});
  std::ofstream(args.out + "/runs.json") << nlohmann::json{{"runs", runs}}.dump(2) << "\n";
  std::string plot_note;
  if (eval::GnuplotAvailable()) {
    auto plot = eval::WriteNeesPlot(args.out, "Average position NEES over " + std::to_string(args.runs) + " runs",
                                    nees);
    Status drawn = plot.ok() ? eval::RunGnuplot(args.out, plot.value().script) : plot.status();
    if (!drawn.ok()) plot_note = " (plot failed: " + drawn.message() + ")";
  } else {
    plot_note = " (gnuplot not found: no nees.png)";
  }
  if (args.quiet) return 0;
  std::printf("%d runs: mean NEES in the 95%% band [%.3f, %.3f] for %.1f%% of the time steps after %.1f s; wrote %s%s\n",
              args.runs, nees.band.lo, nees.band.hi, 100.0 * nees.fraction_in_band, args.t0_s,
              (args.out + "/nees.json").c_str(), plot_note.c_str());
  return 0;
}

}  // namespace roamlab::apps
