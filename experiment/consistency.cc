#include "experiment/consistency.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <utility>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <nlohmann/json.hpp>

#include "common/atomic_file.h"
#include "common/interrupt.h"
#include "common/json.h"
#include "estimator/calibration.h"
#include "eval/parameters.h"
#include "eval/plots.h"
#include "experiment/terrain_redraw.h"
#include "recording/stream_health.h"
#include "sim/simulator.h"

namespace roamlab::experiment {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr char kCramerRaoMethod[] =
    "the std calibrate reports on the scenario simulated with every noise source off (the recording at the truth)";
constexpr char kCramerRaoOnRedrawnTerrain[] =
    ", on the scenario's own terrain (each redrawn terrain has a bound of its own; this one is a reference)";

// What every run shares.
struct Shared {
  sim::Scenario scenario;
  estimator::EstimatorConfig config;
  std::map<std::string, Eigen::VectorXd> cramer_rao_std;
  std::map<std::string, Eigen::VectorXd> noise_free_error;
};

// One calibrated parameter of one run against its truth.
struct RunParameter {
  std::string name;
  std::string manifold;
  std::vector<double> truth, estimate;
  eval::ParameterDraw draw;
};

// The joint covariance of the calibrated parameters: the inverse of the joint marginal information, rescaled so that
// its diagonal is the reported std squared (the correlations are the information's). NaN when the information is
// singular (a direction the recording does not observe).
Eigen::MatrixXd ReportedCovariance(const estimator::CalibrationResult& result) {
  const Eigen::MatrixXd& information = result.information;
  const Eigen::Index n = information.rows();
  if (n == 0 || !information.allFinite()) return Eigen::MatrixXd::Constant(n, n, kNaN);
  const Eigen::LLT<Eigen::MatrixXd> llt(information);
  if (llt.info() != Eigen::Success) return Eigen::MatrixXd::Constant(n, n, kNaN);
  const Eigen::MatrixXd covariance = llt.solve(Eigen::MatrixXd::Identity(n, n));
  Eigen::VectorXd reported(n);
  Eigen::Index offset = 0;
  for (const estimator::ParameterEstimate& p : result.parameters) {
    reported.segment(offset, p.std.size()) = p.std;
    offset += p.std.size();
  }
  if (offset != n) return Eigen::MatrixXd::Constant(n, n, kNaN);
  const Eigen::VectorXd scale = reported.array() / covariance.diagonal().array().sqrt();
  return scale.asDiagonal() * covariance * scale.asDiagonal();
}

// Every calibrated parameter compared with its true value; an error names a parameter without one.
Result<std::vector<RunParameter>> CompareWithTruth(const estimator::CalibrationResult& result,
                                                   const recording::Truth& truth) {
  const Eigen::MatrixXd covariance = ReportedCovariance(result);
  std::vector<RunParameter> out;
  Eigen::Index offset = 0;
  for (const estimator::ParameterEstimate& p : result.parameters) {
    const Eigen::Index d = p.std.size();
    const auto true_value = truth.calibration.find(p.name);
    if (true_value == truth.calibration.end())
      return Status::Error(p.name + ": the scenario's truth has no value for this free parameter");
    RunParameter r;
    r.name = p.name;
    r.manifold = p.manifold.Name();
    r.truth = true_value->second;
    r.estimate.assign(p.estimate.data(), p.estimate.data() + p.estimate.size());
    eval::ParameterEstimate estimate;
    estimate.kind = eval::ParameterKindFromManifold(r.manifold).value_or(eval::ParameterKind::kVector);
    estimate.estimate = r.estimate;
    estimate.std.assign(p.std.data(), p.std.data() + d);
    auto compared = eval::CompareParameter(p.name, r.truth, estimate);
    if (!compared.ok()) return compared.status();
    r.draw.error = Eigen::Map<const Eigen::VectorXd>(compared.value().error.data(), d);
    r.draw.std = p.std;
    r.draw.covariance = covariance.block(offset, offset, d, d);
    offset += d;
    out.push_back(std::move(r));
  }
  return out;
}

// Simulates the scenario (noise off when !noise), calibrates it; `truth` receives the simulation's truth and `stats`
// (optional) its statistics. An error says which step failed: "simulation: ..." or "calibration: ...".
Result<estimator::CalibrationResult> SimulateAndCalibrate(const sim::Scenario& scenario,
                                                          const estimator::EstimatorConfig& config, std::uint64_t seed,
                                                          bool noise, recording::Truth* truth,
                                                          sim::SimulationStats* stats = nullptr) {
  sim::SimulateOptions sim_options;
  sim_options.seed = seed;
  sim_options.noise = noise;
  auto simulation = sim::Simulate(scenario, sim_options);
  if (!simulation.ok()) return Status::Error("simulation: " + simulation.status().message());
  recording::DropDuplicateRows(&simulation.value().recording);  // as the reader does (a duplicates fault)
  auto calibrated = estimator::Calibrate(config, simulation.value().recording);
  if (!calibrated.ok()) return Status::Error("calibration: " + calibrated.status().message());
  *truth = std::move(simulation.value().truth);
  if (stats) *stats = simulation.value().stats;
  return calibrated;
}

// What the drive did, from the simulation (evaluation only: the calibration never sees it).
nlohmann::json DriveJson(const sim::SimulationStats& stats) {
  return {{"distance_m", stats.distance_m},
          {"path_height_range_m", stats.path_height_range_m},
          {"max_abs_roll_rad", stats.max_abs_roll_rad},
          {"max_abs_pitch_rad", stats.max_abs_pitch_rad},
          {"max_lateral_speed_mps", stats.max_lateral_speed_mps},
          {"max_wheel_slip_mps", stats.max_wheel_slip_mps}};
}

nlohmann::json MatrixJson(const Eigen::MatrixXd& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    const Eigen::VectorXd row = m.row(r).transpose();
    rows.push_back(NumberArray(row));
  }
  return rows;
}

// The head of run i's result file: its index, noise seed and, when the terrain is redrawn, its terrain seed.
nlohmann::json RunHead(const MonteCarloOptions& options, int i) {
  nlohmann::json j = {{"run", i}, {"seed", options.seed_base + static_cast<std::uint64_t>(i)}};
  if (options.terrain_seed_base) j["terrain_seed"] = RunTerrainSeed(*options.terrain_seed_base, i);
  return j;
}

// Run i: simulate with its seed (and its terrain), calibrate, compare with the truth, write its result file. With the
// terrain redrawn, a terrain the drive fails on is a result: its file says why ("failed").
Outcome RunOne(const MonteCarloOptions& options, const Shared& shared, int i) {
  const std::uint64_t seed = options.seed_base + static_cast<std::uint64_t>(i);
  nlohmann::json j = RunHead(options, i);
  const sim::Scenario scenario = options.terrain_seed_base
                                     ? WithTerrainSeed(shared.scenario, RunTerrainSeed(*options.terrain_seed_base, i))
                                     : shared.scenario;
  recording::Truth truth;
  sim::SimulationStats stats;
  auto calibrated = SimulateAndCalibrate(scenario, shared.config, seed, true, &truth, &stats);
  if (!calibrated.ok() && options.terrain_seed_base && !InterruptRequested()) {
    j["failed"] = calibrated.status().message();
    const Status written = WriteFileAtomic(ConsistencyRunFile(options.out, i), j.dump() + "\n");
    return written.ok() ? Outcome::Ok() : Outcome::Failed(written);
  }
  if (!calibrated.ok())
    return Outcome::Failed(Status::Error("run " + std::to_string(i) + ", seed " + std::to_string(seed) + ": " +
                                         calibrated.status().message()));
  auto compared = CompareWithTruth(calibrated.value(), truth);
  if (!compared.ok()) return Outcome::BadInput(compared.status());
  nlohmann::json parameters = nlohmann::json::object();
  for (const RunParameter& p : compared.value())
    parameters[p.name] = {{"manifold", p.manifold},
                          {"truth", NumberArray(p.truth)},
                          {"estimate", NumberArray(p.estimate)},
                          {"error", NumberArray(p.draw.error)},
                          {"std", NumberArray(p.draw.std)},
                          {"covariance", MatrixJson(p.draw.covariance)}};
  j["seconds"] = calibrated.value().seconds;
  j["drive"] = DriveJson(stats);
  j["parameters"] = parameters;
  const Status written = WriteFileAtomic(ConsistencyRunFile(options.out, i), j.dump() + "\n");
  return written.ok() ? Outcome::Ok() : Outcome::Failed(written);
}

// A number array of a run file (null read as NaN); false when malformed or not of size n.
bool ReadVector(const nlohmann::json& j, Eigen::Index n, Eigen::VectorXd* out) {
  if (!j.is_array() || static_cast<Eigen::Index>(j.size()) != n) return false;
  out->resize(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const nlohmann::json& v = j[static_cast<std::size_t>(k)];
    if (!v.is_null() && !v.is_number()) return false;
    (*out)[k] = v.is_null() ? kNaN : v.get<double>();
  }
  return true;
}

// Parameter `name`'s draw in a run file; false when malformed.
bool ReadDraw(const nlohmann::json& run, const std::string& name, eval::ParameterDraw* draw) {
  const auto parameters = run.find("parameters");
  if (parameters == run.end() || !parameters->is_object() || !parameters->contains(name)) return false;
  const nlohmann::json& p = (*parameters)[name];
  if (!p.is_object() || !p.contains("error") || !p["error"].is_array()) return false;
  const Eigen::Index d = static_cast<Eigen::Index>(p["error"].size());
  if (d == 0 || !ReadVector(p["error"], d, &draw->error) || !p.contains("std") || !ReadVector(p["std"], d, &draw->std))
    return false;
  if (!p.contains("covariance") || !p["covariance"].is_array() || static_cast<Eigen::Index>(p["covariance"].size()) != d)
    return false;
  draw->covariance.resize(d, d);
  for (Eigen::Index r = 0; r < d; ++r) {
    Eigen::VectorXd row;
    if (!ReadVector(p["covariance"][static_cast<std::size_t>(r)], d, &row)) return false;
    draw->covariance.row(r) = row.transpose();
  }
  return true;
}

// What the run files hold: the draws of the calibrated runs per parameter (in the order of `names`), which runs those
// are, and the runs that failed.
struct RunFiles {
  std::vector<std::vector<eval::ParameterDraw>> draws;
  std::vector<int> calibrated;
  std::vector<FailedRun> failed;
};

// Whether `run` is the file of run i of this call: its noise seed and, when the terrain is redrawn, its terrain seed.
bool IsRunOf(const nlohmann::json& run, const MonteCarloOptions& options, int i) {
  if (!run.is_object()) return false;
  const nlohmann::json head = RunHead(options, i);
  for (const char* key : {"seed", "terrain_seed"}) {
    if (head.contains(key) != run.contains(key)) return false;
    if (head.contains(key) && !(run[key].is_number_unsigned() && run[key] == head[key])) return false;
  }
  return true;
}

// Every run's file; an error names the file that is missing or malformed.
Result<RunFiles> ReadRuns(const MonteCarloOptions& options, const std::vector<std::string>& names) {
  RunFiles out;
  out.draws.resize(names.size());
  for (int i = 0; i < options.runs; ++i) {
    const std::string path = ConsistencyRunFile(options.out, i);
    Result<std::string> text = ReadWholeFile(path);
    if (!text.ok()) return Status::Error(path + ": missing: run " + std::to_string(i) + " has no result");
    const nlohmann::json run = nlohmann::json::parse(text.value(), nullptr, false);
    const std::string other =
        path + ": not the result of run " + std::to_string(i) + " (seed " + std::to_string(options.seed_base + i) + ")";
    const std::string again = " (malformed or of another call; delete it to run it again)";
    if (!IsRunOf(run, options, i)) return Status::Error(other + again);
    if (run.contains("failed")) {
      if (!run["failed"].is_string() || !options.terrain_seed_base) return Status::Error(other + again);
      out.failed.push_back({i, run["seed"].get<std::uint64_t>(), run["terrain_seed"].get<std::uint64_t>(),
                            run["failed"].get<std::string>()});
      continue;
    }
    std::vector<eval::ParameterDraw> draws(names.size());
    for (std::size_t k = 0; k < names.size(); ++k)
      if (!ReadDraw(run, names[k], &draws[k])) return Status::Error(other + " with " + names[k] + again);
    for (std::size_t k = 0; k < names.size(); ++k) out.draws[k].push_back(std::move(draws[k]));
    out.calibrated.push_back(i);
  }
  return out;
}

// The normalized errors error / std of every run and the coverage per component, for the figure.
std::vector<eval::NormalizedErrors> PlotData(const std::vector<eval::BlockConsistency>& blocks,
                                             const std::vector<std::vector<eval::ParameterDraw>>& draws) {
  std::vector<eval::NormalizedErrors> out;
  for (std::size_t b = 0; b < blocks.size(); ++b)
    for (int i = 0; i < blocks[b].dimension; ++i) {
      eval::NormalizedErrors c;
      c.label = blocks[b].name + "[" + std::to_string(i) + "]";
      for (const eval::ParameterDraw& d : draws[b]) c.error_over_std.push_back(d.error[i] / d.std[i]);
      for (int k = 0; k < 3; ++k) c.coverage[k] = blocks[b].components[i].coverage[k].fraction;
      out.push_back(std::move(c));
    }
  return out;
}

// OUT/consistency.json and OUT/consistency.png; returns the plot note.
std::string WriteOutputs(const MonteCarloOptions& options, const std::vector<eval::BlockConsistency>& blocks,
                         const RunFiles& runs, Status* written) {
  nlohmann::json failed = nlohmann::json::array();
  for (const FailedRun& f : runs.failed)
    failed.push_back({{"run", f.run}, {"seed", f.seed}, {"terrain_seed", f.terrain_seed}, {"reason", f.reason}});
  nlohmann::json j = {{"scenario", options.scenario},
                      {"config", options.config},
                      {"runs", options.runs},
                      {"seed_base", options.seed_base},
                      {"terrain_seed_base", nullptr},
                      {"cramer_rao", kCramerRaoMethod},
                      {"calibrated_runs", runs.calibrated},
                      {"failed_runs", failed},
                      {"parameters", eval::ConsistencyJson(blocks)}};
  if (options.terrain_seed_base) {
    j["terrain_seed_base"] = *options.terrain_seed_base;
    j["cramer_rao"] = std::string(kCramerRaoMethod) + kCramerRaoOnRedrawnTerrain;
  }
  *written = WriteFileAtomic(options.out + "/consistency.json", j.dump(2) + "\n");
  if (!written->ok()) return "";
  if (!eval::GnuplotAvailable()) return " (gnuplot not found: no consistency.png)";
  auto plot = eval::WriteConsistencyPlot(options.out,
                                         "Calibration errors over " + std::to_string(runs.calibrated.size()) + " runs",
                                         PlotData(blocks, runs.draws));
  const Status drawn = plot.ok() ? eval::RunGnuplot(options.out, plot.value().script) : plot.status();
  return drawn.ok() ? "" : " (plot failed: " + drawn.message() + ")";
}

// Reads the scenario and configuration and computes the Cramer-Rao std.
Outcome Prepare(const MonteCarloOptions& options, Shared* shared) {
  if (const std::string problem = options.Validate(); !problem.empty())
    return Outcome::BadInput(Status::Error(problem));
  auto scenario = sim::LoadScenario(options.scenario);
  if (!scenario.ok()) return Outcome::BadInput(scenario.status());
  shared->scenario = std::move(scenario).value();
  if (options.terrain_seed_base)
    if (const std::string problem = TerrainRedrawProblem(shared->scenario); !problem.empty())
      return Outcome::BadInput(Status::Error(options.scenario + ": " + problem + " (--redraw-terrain)"));
  auto config = estimator::LoadEstimatorConfig(options.config);
  if (!config.ok()) return Outcome::BadInput(config.status());
  shared->config = std::move(config).value();
  // Only the calibration reads the runs' recordings: the laser and camera it does not read are not simulated.
  shared->scenario.DropUnreadCostlySensors(estimator::StreamsRead(shared->config));
  const auto& parameters = shared->config.parameters;
  if (std::none_of(parameters.begin(), parameters.end(), [](const auto& p) { return p.second.free; }))
    return Outcome::BadInput(Status::Error(options.config + ": no free parameter to calibrate"));
  if (const Status dir = MakeOutputDirectory(options.out + "/calibrations"); !dir.ok()) return Outcome::BadInput(dir);
  if (options.log) options.log("Cramer-Rao std: calibrating the scenario simulated without noise");
  auto noise_free = CalibrateWithoutNoise(shared->scenario, shared->config);
  if (!noise_free.ok()) return Outcome::Failed(Status::Error("noise-free calibration: " + noise_free.status().message()));
  auto crb = CramerRaoStd(noise_free.value());
  if (!crb.ok()) return Outcome::Failed(Status::Error("Cramer-Rao std: " + crb.status().message()));
  shared->cramer_rao_std = std::move(crb).value();
  shared->noise_free_error = std::move(noise_free.value().error);
  return Outcome::Ok();
}

// The statistics of every parameter from the run files, and the summary files.
Outcome Aggregate(const MonteCarloOptions& options, const Shared& shared, ConsistencySummary* summary) {
  std::vector<std::string> names;
  for (const auto& [name, std] : shared.cramer_rao_std) names.push_back(name);
  auto runs = ReadRuns(options, names);
  if (!runs.ok()) return Outcome::Failed(runs.status());
  const std::vector<std::vector<eval::ParameterDraw>>& draws = runs.value().draws;
  if (runs.value().calibrated.empty()) {
    const FailedRun& first = runs.value().failed.front();
    return Outcome::Failed(Status::Error("every run failed, the first: run " + std::to_string(first.run) +
                                         " (terrain seed " + std::to_string(first.terrain_seed) +
                                         "): " + first.reason));
  }
  std::vector<eval::BlockConsistency> blocks;
  for (std::size_t k = 0; k < names.size(); ++k) {
    const Eigen::VectorXd& crb = shared.cramer_rao_std.at(names[k]);
    if (crb.size() != draws[k].front().error.size())
      return Outcome::Failed(Status::Error(names[k] + ": the Cramer-Rao std has another size than the runs' errors"));
    blocks.push_back(eval::BlockStatistics(names[k], draws[k], crb));
    const Eigen::VectorXd& noise_free = shared.noise_free_error.at(names[k]);
    for (Eigen::Index i = 0; i < noise_free.size(); ++i) blocks.back().components[i].noise_free_error = noise_free[i];
  }
  Status written = Status::Ok();
  const std::string note = WriteOutputs(options, blocks, runs.value(), &written);
  if (!written.ok()) return Outcome::Failed(written);
  if (summary) *summary = {std::move(blocks), std::move(runs.value().failed), note};
  return Outcome::Ok();
}

}  // namespace

Result<NoiseFreeCalibration> CalibrateWithoutNoise(const sim::Scenario& scenario,
                                                   const estimator::EstimatorConfig& config) {
  recording::Truth truth;
  auto calibrated = SimulateAndCalibrate(scenario, config, scenario.seed, false, &truth);
  if (!calibrated.ok()) return calibrated.status();
  auto compared = CompareWithTruth(calibrated.value(), truth);
  if (!compared.ok()) return compared.status();
  NoiseFreeCalibration out;
  for (const RunParameter& p : compared.value()) {
    out.std[p.name] = p.draw.std;
    out.error[p.name] = p.draw.error;
  }
  return out;
}

Result<std::map<std::string, Eigen::VectorXd>> CramerRaoStd(const NoiseFreeCalibration& noise_free) {
  return noise_free.std;
}

std::string ConsistencyRunFile(const std::string& out, int i) {
  char name[40];
  std::snprintf(name, sizeof name, "/calibrations/%06d.json", i);
  return out + name;
}

Outcome RunCalibrationConsistency(const MonteCarloOptions& options, ConsistencySummary* summary) {
  Shared shared;
  if (Outcome prepared = Prepare(options, &shared); !prepared.ok()) return prepared;
  std::vector<int> todo;
  for (int i = 0; i < options.runs; ++i)
    if (!options.resume || !std::filesystem::exists(ConsistencyRunFile(options.out, i))) todo.push_back(i);
  if (options.resume && options.log)
    options.log(std::to_string(options.runs - static_cast<int>(todo.size())) + " of " + std::to_string(options.runs) +
                " runs already have their result file");
  const auto run = [&](int i) { return RunOne(options, shared, i); };
  if (Outcome ran = RunSpread(todo, options.jobs, options.progress, run); !ran.ok()) return ran;
  if (InterruptRequested()) return Outcome::Failed(InterruptedError());
  return Aggregate(options, shared, summary);
}

}  // namespace roamlab::experiment
