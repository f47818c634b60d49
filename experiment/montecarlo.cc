#include "experiment/montecarlo.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/atomic_file.h"
#include "common/html.h"
#include "common/json.h"
#include "common/interrupt.h"
#include "estimator/calibration.h"
#include "estimator/calibration_io.h"
#include "estimator/config.h"
#include "estimator/tracking.h"
#include "eval/association.h"
#include "eval/metrics.h"
#include "eval/montecarlo.h"
#include "eval/plots.h"
#include "recording/recording.h"
#include "recording/stream_health.h"
#include "sim/scenario.h"
#include "sim/simulator.h"

namespace roamlab::experiment {

using Values = std::map<std::string, Eigen::VectorXd>;

namespace {

struct RunResult {
  eval::RunNees nees;
  bool has_covariance = true;  // false: an external estimator wrote no covariance.csv (nees.nees and mean_nees NaN)
  double rpe_m = 0.0;  // translation RMSE of the relative pose error over pose pairs about 1 s apart [m]
  double track_seconds = 0.0;
  std::string error;  // empty when the run succeeded
};

// The translation RMSE [m] of the RPE over pose pairs about 1 s apart, on the poses with a truth pose at the same
// stamp; NaN when there is no such pair.
double RpeOverOneSecond(const Trajectory& estimate, const Trajectory& truth) {
  const eval::MatchedTrajectories matched =
      eval::SelectMatched(estimate, truth, eval::AssociateByTime(estimate, truth, eval::AssociationOptions{}));
  if (matched.estimate.size() < 2) return std::numeric_limits<double>::quiet_NaN();
  const std::size_t step = eval::StepForDuration(matched.reference, 1.0);
  return eval::RpeByStep(matched.estimate, matched.reference, step).translation.rmse;
}

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
  r.rpe_m = RpeOverOneSecond(tr.trajectory, *rec.ground_truth);
  r.track_seconds = tr.total_seconds;
  return r;
}

// Run `seed` of an external estimator (MonteCarloOptions::command) in `run_dir`: simulate, write the recording
// without the truth, run the command on it, pair its poses with the truth's.
RunResult ExternalRun(const sim::Scenario& scenario, const ExternalCommand& command, const std::string& run_dir,
                      std::uint64_t seed) {
  RunResult r;
  const std::string prefix = "seed " + std::to_string(seed) + ": ";
  sim::SimulateOptions sim_options;
  sim_options.seed = seed;
  auto simulation = sim::Simulate(scenario, sim_options);
  if (!simulation.ok()) {
    r.error = prefix + simulation.status().message();
    return r;
  }
  recording::Recording& rec = simulation.value().recording;
  const Trajectory truth = *rec.ground_truth;
  rec.ground_truth.reset();  // the estimator under test never sees the truth
  const std::string recording_dir = run_dir + "/recording";
  const std::string estimate_dir = run_dir + "/estimate";
  std::error_code ec;
  std::filesystem::remove_all(run_dir, ec);
  Status status = MakeOutputDirectory(run_dir);
  if (status.ok()) status = recording::WriteRecording(rec, recording_dir);
  const auto start = std::chrono::steady_clock::now();
  if (status.ok()) status = RunExternalCommand(command, recording_dir, estimate_dir, run_dir + "/estimator.log");
  r.track_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  Result<ExternalEstimate> estimate =
      status.ok() ? ReadExternalEstimate(estimate_dir) : Result<ExternalEstimate>(status);
  if (!estimate.ok()) {
    const bool named = status.ok();  // only a reading error does not name the command yet
    r.error = prefix + (named ? "estimator command '" + command.command + "': " : "") + estimate.status().message();
    return r;
  }
  const ExternalEstimate& e = estimate.value();
  r.has_covariance = e.position_covariance_world.has_value();
  const std::vector<Eigen::Matrix3d> identity(e.trajectory.size(), Eigen::Matrix3d::Identity());
  r.nees = eval::MatchedNees(e.trajectory, r.has_covariance ? *e.position_covariance_world : identity, truth);
  if (r.nees.t.empty()) {
    r.error = prefix + estimate_dir + "/trajectory.tum: no pose has a ground-truth pose at the same time stamp";
    return r;
  }
  if (!r.has_covariance) {
    r.nees.nees.assign(r.nees.t.size(), std::numeric_limits<double>::quiet_NaN());
    r.nees.mean_nees = std::numeric_limits<double>::quiet_NaN();
  }
  r.rpe_m = RpeOverOneSecond(e.trajectory, truth);
  std::filesystem::remove_all(recording_dir, ec);
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
  // The calibration of a long drive takes minutes: its stages are logged as they finish.
  if (options.log) calibrate.progress = [&options](const std::string& line) { options.log("calibration: " + line); };
  outcome = CalibrateToDirectory(calibrate);
  if (!outcome.ok()) {
    outcome.step = "calibrate";
    return outcome;
  }
  *file = dir + "/calibration.json";
  return outcome;
}

}  // namespace

// What every run shares: the scenario, the tracking configuration and calibration, and (calibrate_each_run) the warm
// calibration configuration each run calibrates its own drive with.
struct MonteCarloShared {
  sim::Scenario scenario;
  estimator::EstimatorConfig config;
  Values calibration;
  estimator::TrackingOptions tracking;
  bool per_run = false;
  estimator::EstimatorConfig warm;
};

namespace {

// The output directory (an external estimator's runs share nothing else).
Outcome PrepareOutput(const MonteCarloOptions& options) {
  if (const Status dir = MakeOutputDirectory(options.out); !dir.ok()) return Outcome::BadInput(dir);
  return Outcome::Ok();
}

// The inputs every run shares, read (and, with tracking.calibrate, calibrated once) before any run.
Outcome Prepare(const MonteCarloOptions& options, MonteCarloShared* shared) {
  auto scenario = sim::LoadScenario(options.scenario);
  if (!scenario.ok()) return Outcome::BadInput(scenario.status());
  shared->scenario = std::move(scenario).value();
  if (options.external()) return PrepareOutput(options);
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
    const std::string earlier = options.out + "/calibration/calibration.json";
    if (options.resume && std::filesystem::exists(earlier)) {
      calibration_file = earlier;
      if (options.log) options.log("resuming with the calibration of the earlier call (" + earlier + ")");
    } else if (const Outcome once = CalibrateOnce(options, shared->scenario.seed, calibrate, &calibration_file);
               !once.ok()) {
      return once;
    }
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
RunResult RunOne(const MonteCarloOptions& options, const MonteCarloShared& shared, int i) {
  if (options.external()) {
    const std::string file = MonteCarloRunFile(options.out, i);
    const std::string run_dir = file.substr(0, file.size() - std::string(".json").size());
    return ExternalRun(shared.scenario, options.command, run_dir, options.seed_base + i);
  }
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

// Run i's result file content (MonteCarloRunFile).
nlohmann::json RunJson(int i, std::uint64_t seed, const RunResult& r) {
  nlohmann::json t = nlohmann::json::array();
  for (Time time : r.nees.t) t.push_back(time.nanoseconds());
  return {{"run", i},
          {"seed", seed},
          {"ate_m", Number(r.nees.ate_m)},
          {"mean_nees", Number(r.nees.mean_nees)},
          {"rpe_m", Number(r.rpe_m)},
          {"track_seconds", r.track_seconds},
          {"covariance", r.has_covariance},
          {"t_ns", t},
          {"nees", NumberArray(r.nees.nees)}};
}

// j[key], or null when j has no such key (operator[] on a const object must not be asked for a missing key).
const nlohmann::json& Field(const nlohmann::json& j, const char* key) {
  static const nlohmann::json kNull;
  const auto it = j.find(key);
  return it == j.end() ? kNull : *it;
}

// A number of a run file, null read as NaN (Number writes what is not finite as null).
bool ReadNumber(const nlohmann::json& value, double* out) {
  if (value.is_null()) {
    *out = std::numeric_limits<double>::quiet_NaN();
    return true;
  }
  if (!value.is_number()) return false;
  *out = value.get<double>();
  return true;
}

// The numbers of a run file's "t_ns" and "nees" arrays, of equal length; false when malformed.
bool ReadSeries(const nlohmann::json& j, eval::RunNees* nees) {
  const nlohmann::json& t = Field(j, "t_ns");
  const nlohmann::json& values = Field(j, "nees");
  if (!t.is_array() || !values.is_array() || t.size() != values.size()) return false;
  for (std::size_t k = 0; k < t.size(); ++k) {
    double value = 0.0;
    if (!t[k].is_number_integer() || !ReadNumber(values[k], &value)) return false;
    nees->t.push_back(Time::FromNanoseconds(t[k].get<std::int64_t>()));
    nees->nees.push_back(value);
  }
  return true;
}

// Reads run i's result file; an error names the file and what is wrong with it.
Result<RunResult> ReadRun(const std::string& path, int i, std::uint64_t seed) {
  if (!std::filesystem::exists(path))
    return Status::Error(path + ": missing: run " + std::to_string(i) + " has no result (--resume runs it)");
  Result<std::string> text = ReadWholeFile(path);
  if (!text.ok()) return text.status();
  const nlohmann::json j = nlohmann::json::parse(text.value(), nullptr, false);
  RunResult r;
  const bool ok = j.is_object() && Field(j, "run").is_number_integer() && Field(j, "run").get<std::int64_t>() == i &&
                  Field(j, "seed").is_number_unsigned() && Field(j, "seed").get<std::uint64_t>() == seed &&
                  ReadNumber(Field(j, "ate_m"), &r.nees.ate_m) &&
                  ReadNumber(Field(j, "mean_nees"), &r.nees.mean_nees) && ReadNumber(Field(j, "rpe_m"), &r.rpe_m) &&
                  Field(j, "track_seconds").is_number() && ReadSeries(j, &r.nees);
  if (!ok)
    return Status::Error(path + ": not the result file of run " + std::to_string(i) + " with seed " +
                         std::to_string(seed) + " (malformed or of another call; delete it to run it again)");
  r.track_seconds = Field(j, "track_seconds").get<double>();
  const nlohmann::json& covariance = Field(j, "covariance");
  if (!covariance.is_null() && !covariance.is_boolean())
    return Status::Error(path + ": \"covariance\" is not true or false (delete the file to run it again)");
  r.has_covariance = !covariance.is_boolean() || covariance.get<bool>();
  return r;
}

}  // namespace

Outcome RunSpread(const std::vector<int>& todo, int jobs, const std::function<void(int, int)>& progress,
                  const std::function<Outcome(int)>& run) {
  const int n = static_cast<int>(todo.size());
  if (jobs <= 0) jobs = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  std::vector<Outcome> outcomes(todo.size());
  std::atomic<int> next{0}, done{0};
  std::mutex print;
  const auto worker = [&] {
    for (int k = next++; k < n && !InterruptRequested(); k = next++) {
      outcomes[k] = run(todo[k]);
      const int finished = ++done;
      if (progress) {
        std::lock_guard<std::mutex> lock(print);
        progress(finished, n);
      }
    }
  };
  if (progress) progress(0, n);
  std::vector<std::thread> threads;
  for (int k = 0; k < std::min(jobs, n); ++k) threads.emplace_back(worker);
  for (auto& th : threads) th.join();
  const auto failed = std::count_if(outcomes.begin(), outcomes.end(), [](const Outcome& o) { return !o.ok(); });
  for (const Outcome& o : outcomes)
    if (!o.ok()) {
      Outcome first = o;
      first.status = Status::Error(std::to_string(failed) + " of " + std::to_string(n) + " runs failed; first: " +
                                   o.status.message());
      return first;
    }
  return Outcome::Ok();
}

namespace {

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
  page.Paragraph("Scenario " + options.scenario +
                 (options.external() ? ", estimator command " + options.command.command
                                     : ", configuration " + options.config) +
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

// OUT/runs.json: per-run ATE, mean NEES, RPE and tracking time.
Status WriteRunsJson(const MonteCarloOptions& options, const std::vector<RunResult>& results) {
  nlohmann::json runs = nlohmann::json::array();
  for (int i = 0; i < options.runs; ++i)
    runs.push_back({{"seed", options.seed_base + i},
                    {"ate_m", results[i].nees.ate_m},
                    {"mean_nees", Number(results[i].nees.mean_nees)},
                    {"rpe_m", Number(results[i].rpe_m)},
                    {"track_seconds", results[i].track_seconds}});
  return WriteFileAtomic(options.out + "/runs.json", nlohmann::json{{"runs", runs}}.dump(2) + "\n");
}

// Without covariances: OUT/runs.json, and no nees.json, nees.png or report.html (stale ones are removed); returns the
// note that says so.
std::string WriteRunsOnly(const MonteCarloOptions& options, const std::vector<RunResult>& results) {
  for (const char* stale : {"/nees.json", "/nees.png", "/report.html"})
    if (Status s = RemoveStaleFile(options.out + stale); !s.ok()) return " (" + s.message() + ")";
  if (Status s = WriteRunsJson(options, results); !s.ok()) return " (" + s.message() + ")";
  return " (no NEES: the estimator wrote no covariance.csv)";
}

// OUT/nees.json, OUT/runs.json and OUT/nees.png; returns the plot note.
std::string WriteData(const MonteCarloOptions& options, const eval::MonteCarloNees& nees,
                      const std::vector<RunResult>& results) {
  if (Status s = WriteFileAtomic(options.out + "/nees.json", eval::NeesJson(nees).dump(2) + "\n"); !s.ok())
    return " (" + s.message() + ")";
  if (Status s = WriteRunsJson(options, results); !s.ok()) return " (" + s.message() + ")";
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
  if (terrain_seed_base && !calibration_consistency)
    return "--redraw-terrain is for --calibration-consistency (tracking runs keep the scenario's terrain)";
  if (config.empty() == command.command.empty())
    return "give the estimator either as --config (roamlab's) or as --command (an external one)";
  if (!external()) return "";
  if (!calibration.empty() || calibrate_each_run)
    return "--calibration and --calibrate-each-run are for --config; an external estimator calibrates itself";
  return command.Validate();
}

std::string MonteCarloRunFile(const std::string& out, int i) {
  char name[32];
  std::snprintf(name, sizeof name, "/runs/%06d.json", i);
  return out + name;
}

Outcome PrepareMonteCarlo(const MonteCarloOptions& options, std::shared_ptr<const MonteCarloShared>* shared) {
  if (const std::string problem = options.Validate(); !problem.empty())
    return Outcome::BadInput(Status::Error(problem));
  auto prepared = std::make_shared<MonteCarloShared>();
  if (Outcome outcome = Prepare(options, prepared.get()); !outcome.ok()) return outcome;
  if (const Status dir = MakeOutputDirectory(options.out + "/runs"); !dir.ok()) return Outcome::BadInput(dir);
  *shared = std::move(prepared);
  return Outcome::Ok();
}

Outcome RunMonteCarloRun(const MonteCarloOptions& options, const MonteCarloShared& shared, int i) {
  const RunResult r = RunOne(options, shared, i);
  if (!r.error.empty()) return Outcome::Failed(Status::Error("run " + std::to_string(i) + ", " + r.error));
  const Status written =
      WriteFileAtomic(MonteCarloRunFile(options.out, i), RunJson(i, options.seed_base + i, r).dump() + "\n");
  return written.ok() ? Outcome::Ok() : Outcome::Failed(written);
}

std::vector<int> MissingMonteCarloRuns(const MonteCarloOptions& options) {
  std::vector<int> missing;
  for (int i = 0; i < options.runs; ++i)
    if (!std::filesystem::exists(MonteCarloRunFile(options.out, i))) missing.push_back(i);
  return missing;
}

Outcome AggregateMonteCarlo(const MonteCarloOptions& options, MonteCarloSummary* summary) {
  std::vector<RunResult> results;
  std::vector<eval::RunNees> runs;
  for (int i = 0; i < options.runs; ++i) {
    Result<RunResult> r = ReadRun(MonteCarloRunFile(options.out, i), i, options.seed_base + i);
    if (!r.ok()) return Outcome::Failed(r.status());
    runs.push_back(r.value().nees);
    results.push_back(std::move(r).value());
  }
  // All runs with a covariance (NEES) or none (an external estimator that writes none).
  const auto with = std::count_if(results.begin(), results.end(), [](const RunResult& r) { return r.has_covariance; });
  if (with == 0) {
    const std::string note = WriteRunsOnly(options, results);
    if (summary) *summary = {eval::MonteCarloNees{}, false, note};
    return Outcome::Ok();
  }
  for (int i = 0; i < options.runs; ++i)
    if (!results[i].has_covariance)
      return Outcome::Failed(Status::Error(MonteCarloRunFile(options.out, i) + ": run " + std::to_string(i) +
                                           " has no covariance while other runs have one (no NEES can be averaged)"));
  Result<eval::MonteCarloNees> nees = eval::AggregateRunNees(runs, options.t0_s);
  if (!nees.ok()) return Outcome::Failed(nees.status());
  const std::string plot_note = WriteOutputs(options, nees.value(), results);
  if (summary) *summary = {std::move(nees).value(), true, plot_note};
  return Outcome::Ok();
}

Outcome RunMonteCarlo(const MonteCarloOptions& options, MonteCarloSummary* summary) {
  std::shared_ptr<const MonteCarloShared> shared;
  if (Outcome prepared = PrepareMonteCarlo(options, &shared); !prepared.ok()) return prepared;
  std::vector<int> todo;
  if (options.resume) {
    todo = MissingMonteCarloRuns(options);
    if (options.log)
      options.log(std::to_string(options.runs - static_cast<int>(todo.size())) + " of " + std::to_string(options.runs) +
                  " runs already have their result file");
  } else {
    for (int i = 0; i < options.runs; ++i) todo.push_back(i);
  }
  const auto run = [&](int i) { return RunMonteCarloRun(options, *shared, i); };
  if (Outcome ran = RunSpread(todo, options.jobs, options.progress, run); !ran.ok()) return ran;
  if (InterruptRequested()) return Outcome::Failed(InterruptedError());
  return AggregateMonteCarlo(options, summary);
}

}  // namespace roamlab::experiment
