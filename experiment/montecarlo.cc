#include "experiment/montecarlo.h"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/html.h"
#include "estimator/calibration.h"
#include "estimator/calibration_io.h"
#include "estimator/config.h"
#include "estimator/tracking.h"
#include "eval/montecarlo.h"
#include "eval/plots.h"
#include "recording/stream_health.h"
#include "sim/scenario.h"
#include "sim/simulator.h"

namespace roamlab::experiment {
namespace {

using Values = std::map<std::string, Eigen::VectorXd>;

struct RunResult {
  eval::RunNees nees;
  double track_seconds = 0.0;
  std::string error;  // empty when the run succeeded
};

// One realization: simulate, track, NEES of every tracked pose against the ground truth at the same time stamp.
RunResult OneRun(const sim::Scenario& scenario, const estimator::EstimatorConfig& config, const Values& calibration,
                 const estimator::TrackingOptions& tracking_options, std::uint64_t seed) {
  RunResult r;
  sim::SimulateOptions sim_options;
  sim_options.seed = seed;
  auto simulation = sim::Simulate(scenario, sim_options);
  if (!simulation.ok()) {
    r.error = "seed " + std::to_string(seed) + ": " + simulation.status().message();
    return r;
  }
  recording::Recording& rec = simulation.value().recording;
  recording::DropDuplicateRows(&rec);  // as the reader does for a recording on disk (a duplicates fault)
  auto tracked = estimator::Track(config, rec, calibration, tracking_options);
  if (!tracked.ok()) {
    r.error = "seed " + std::to_string(seed) + ": " + tracked.status().message();
    return r;
  }
  const estimator::TrackingResult& tr = tracked.value();
  r.nees = eval::MatchedNees(tr.trajectory, tr.position_covariance, *rec.ground_truth);
  if (r.nees.t.empty()) {
    r.error = "seed " + std::to_string(seed) + ": no tracked pose has a ground-truth pose at the same time";
    return r;
  }
  r.track_seconds = tr.total_seconds;
  return r;
}

// The calibration a run tracks with: its values and, under tracking.calibration_prior, their prior.
struct RunCalibration {
  Values values;
  estimator::TrackingOptions options;
};

// Run `seed`'s own calibration: the scenario simulated with `seed` (a realization apart from the tracked one) and
// calibrated with `warm`, the calibration configuration warm-started at the shared calibration (see RunMonteCarlo).
Result<RunCalibration> CalibrateRun(const sim::Scenario& scenario, const estimator::EstimatorConfig& warm, bool prior,
                                    std::uint64_t seed) {
  sim::SimulateOptions sim_options;
  sim_options.seed = seed;
  auto simulation = sim::Simulate(scenario, sim_options);
  if (!simulation.ok())
    return Status::Error("calibration seed " + std::to_string(seed) + ": " + simulation.status().message());
  recording::DropDuplicateRows(&simulation.value().recording);  // as the reader does (a duplicates fault)
  auto calibrated = estimator::Calibrate(warm, simulation.value().recording);
  if (!calibrated.ok())
    return Status::Error("calibration seed " + std::to_string(seed) + ": " + calibrated.status().message());
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
Result<estimator::EstimatorConfig> WarmCalibrationConfig(const std::string& path, const Values& values) {
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

// Simulates the scenario with `seed` into OUT/calibration/recording and calibrates it with `calibration_config` into
// OUT/calibration; `file` receives OUT/calibration/calibration.json.
Outcome CalibrateOnce(const MonteCarloOptions& options, std::uint64_t seed, const std::string& calibration_config,
                      std::string* file) {
  const std::string dir = (std::filesystem::path(options.out) / "calibration").string();
  if (options.log)
    options.log("calibrating once with " + calibration_config + " on the scenario's own noise seed " +
                std::to_string(seed) + " (" + dir + ")");
  SimulateRequest simulate;
  simulate.scenario = options.scenario;
  simulate.out = dir + "/recording";
  simulate.seed = seed;
  Outcome outcome = SimulateToDirectory(simulate);
  if (!outcome.ok()) {
    outcome.step = "simulate";
    return outcome;
  }
  CalibrateRequest calibrate;
  calibrate.recording = simulate.out;
  calibrate.config = calibration_config;
  calibrate.out = dir;
  outcome = CalibrateToDirectory(calibrate);
  if (!outcome.ok()) {
    outcome.step = "calibrate";
    return outcome;
  }
  *file = dir + "/calibration.json";
  return outcome;
}

// What every run shares: the scenario, the tracking configuration and calibration, and (calibrate_each_run) the warm
// calibration configuration each run calibrates its own drive with.
struct Shared {
  sim::Scenario scenario;
  estimator::EstimatorConfig config;
  Values calibration;
  estimator::TrackingOptions tracking;
  bool per_run = false;
  estimator::EstimatorConfig warm;
};

// The inputs every run shares, read (and, with tracking.calibrate, calibrated once) before any run.
Outcome Prepare(const MonteCarloOptions& options, Shared* shared) {
  auto scenario = sim::LoadScenario(options.scenario);
  if (!scenario.ok()) return Outcome::BadInput(scenario.status());
  shared->scenario = std::move(scenario).value();
  auto config = estimator::LoadEstimatorConfig(options.config);
  if (!config.ok()) return Outcome::BadInput(config.status());
  shared->config = std::move(config).value();
  if (options.no_time_budget) shared->config.tracking.time_budget_s = std::numeric_limits<double>::infinity();
  if (const Status dir = MakeOutputDirectory(options.out); !dir.ok()) return Outcome::BadInput(dir);

  // The calibration tracking starts from: the given file, or (tracking.calibrate) one offline calibration of the
  // scenario simulated with its own noise seed, a realization apart from the runs' (seed_base + i).
  const std::string& calibrate = shared->config.tracking.calibrate;
  std::string calibration_file = options.calibration;
  if (calibration_file.empty() && !calibrate.empty()) {
    const Outcome once = CalibrateOnce(options, shared->scenario.seed, calibrate, &calibration_file);
    if (!once.ok()) return once;
  }
  if (!calibration_file.empty()) {
    auto values = estimator::ReadCalibrationValues(calibration_file);
    if (!values.ok()) return Outcome::BadInput(values.status());
    shared->calibration = std::move(values).value();
  }
  auto tracking = estimator::TrackingOptionsFor(shared->config, calibration_file);
  if (!tracking.ok()) return Outcome::BadInput(tracking.status());
  shared->tracking = std::move(tracking).value();
  shared->per_run = options.calibration.empty() && !calibrate.empty() && options.calibrate_each_run;
  if (shared->per_run) {
    auto warm = WarmCalibrationConfig(calibrate, shared->calibration);
    if (!warm.ok()) return Outcome::BadInput(warm.status());
    shared->warm = std::move(warm).value();
    if (options.log)
      options.log("each run also calibrates a drive of its own (noise seed " + std::to_string(options.seed_base) +
                  " + " + std::to_string(kCalibrationSeedOffset) + " + i), warm-started there");
  }
  return Outcome::Ok();
}

// Run i: with its own calibration (per_run) or the shared one.
RunResult RunOne(const MonteCarloOptions& options, const Shared& shared, int i) {
  if (!shared.per_run)
    return OneRun(shared.scenario, shared.config, shared.calibration, shared.tracking, options.seed_base + i);
  auto own = CalibrateRun(shared.scenario, shared.warm, shared.config.tracking.calibration_prior,
                          options.seed_base + kCalibrationSeedOffset + i);
  if (!own.ok()) {
    RunResult failed;
    failed.error = own.status().message();
    return failed;
  }
  return OneRun(shared.scenario, shared.config, own.value().values, own.value().options, options.seed_base + i);
}

// The runs spread over worker threads; each writes only its own slot, so the result does not depend on scheduling.
std::vector<RunResult> RunAll(const MonteCarloOptions& options, const Shared& shared) {
  const int jobs = options.jobs > 0 ? options.jobs : std::max(1u, std::thread::hardware_concurrency());
  std::vector<RunResult> results(options.runs);
  std::atomic<int> next{0}, done{0};
  std::mutex print;
  const auto worker = [&] {
    for (int i = next++; i < options.runs; i = next++) {
      results[i] = RunOne(options, shared, i);
      const int finished = ++done;
      if (options.progress) {
        std::lock_guard<std::mutex> lock(print);
        options.progress(finished, options.runs);
      }
    }
  };
  std::vector<std::thread> threads;
  for (int k = 0; k < std::min(jobs, options.runs); ++k) threads.emplace_back(worker);
  for (auto& th : threads) th.join();
  return results;
}

std::string Format(double x, const char* format = "%.4g") {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, x);
  return buffer;
}

// OUT/report.html: the in-band fraction first, the summary and per-run tables, the NEES figure (when drawn).
// Returns "" or why it could not be written, as " (...)".
std::string WriteReport(const MonteCarloOptions& options, const eval::MonteCarloNees& nees,
                        const std::vector<RunResult>& results, const std::string& plot_note) {
  html::Page page("Monte-Carlo consistency: " + options.scenario);
  page.Paragraph("Average position NEES over " + std::to_string(options.runs) + " runs in the " +
                     Format(100.0 * (1.0 - nees.alpha), "%.0f") + " % band [" + Format(nees.band.lo, "%.3f") + ", " +
                     Format(nees.band.hi, "%.3f") + "] for " + Format(100.0 * nees.fraction_in_band, "%.1f") +
                     " % of the time steps after " + Format(options.t0_s, "%.1f") + " s",
                 "headline");
  page.Paragraph("Scenario " + options.scenario + ", configuration " + options.config +
                 (options.calibration.empty() ? "" : ", calibration " + options.calibration) + ".");
  page.Heading(2, "Runs");
  html::Table runs{{"seed", "ATE [m]", "mean NEES (3 when consistent)", "tracking [s]"}, {}};
  for (int i = 0; i < options.runs; ++i)
    runs.rows.push_back({std::to_string(options.seed_base + i), Format(results[i].nees.ate_m),
                         Format(results[i].nees.mean_nees), Format(results[i].track_seconds, "%.2f")});
  page.AddTable(runs);
  page.Heading(2, "Figures");
  if (!plot_note.empty())
    page.Paragraph("No figure" + plot_note, "note");
  else if (Status s = page.AddImage(options.out + "/nees.png", "Average position NEES with its band"); !s.ok())
    page.Paragraph(s.message(), "note");
  const Status written = page.Write(options.out + "/report.html");
  return written.ok() ? "" : " (" + written.message() + ")";
}

// OUT/nees.json, OUT/runs.json and OUT/nees.png; returns the plot note.
std::string WriteData(const MonteCarloOptions& options, const eval::MonteCarloNees& nees,
                      const std::vector<RunResult>& results) {
  std::ofstream(options.out + "/nees.json") << eval::NeesJson(nees).dump(2) << "\n";
  nlohmann::json runs = nlohmann::json::array();
  for (int i = 0; i < options.runs; ++i)
    runs.push_back({{"seed", options.seed_base + i},
                    {"ate_m", results[i].nees.ate_m},
                    {"mean_nees", results[i].nees.mean_nees},
                    {"track_seconds", results[i].track_seconds}});
  std::ofstream(options.out + "/runs.json") << nlohmann::json{{"runs", runs}}.dump(2) << "\n";
  if (!eval::GnuplotAvailable()) return " (gnuplot not found: no nees.png)";
  auto plot =
      eval::WriteNeesPlot(options.out, "Average position NEES over " + std::to_string(options.runs) + " runs", nees);
  const Status drawn = plot.ok() ? eval::RunGnuplot(options.out, plot.value().script) : plot.status();
  return drawn.ok() ? "" : " (plot failed: " + drawn.message() + ")";
}

// OUT/nees.json, OUT/runs.json, OUT/nees.png and OUT/report.html; returns the notes of what was not written.
std::string WriteOutputs(const MonteCarloOptions& options, const eval::MonteCarloNees& nees,
                         const std::vector<RunResult>& results) {
  const std::string note = WriteData(options, nees, results);
  return note + WriteReport(options, nees, results, note);
}

}  // namespace

std::string MonteCarloOptions::Validate() const {
  if (runs < 1) return "--runs must be at least 1";
  if (jobs < 0) return "--jobs must be >= 0";
  return "";
}

Outcome RunMonteCarlo(const MonteCarloOptions& options, MonteCarloSummary* summary) {
  if (const std::string problem = options.Validate(); !problem.empty())
    return Outcome::BadInput(Status::Error(problem));
  Shared shared;
  if (Outcome prepared = Prepare(options, &shared); !prepared.ok()) return prepared;

  const std::vector<RunResult> results = RunAll(options, shared);
  std::vector<eval::RunNees> runs;
  for (const RunResult& r : results) {
    if (!r.error.empty()) return Outcome::Failed(Status::Error(r.error));
    runs.push_back(r.nees);
  }
  Result<eval::MonteCarloNees> nees = eval::AggregateRunNees(runs, options.t0_s);
  if (!nees.ok()) return Outcome::Failed(nees.status());
  const std::string plot_note = WriteOutputs(options, nees.value(), results);
  if (summary) *summary = {std::move(nees).value(), plot_note};
  return Outcome::Ok();
}

}  // namespace roamlab::experiment
