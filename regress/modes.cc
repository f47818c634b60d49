#include "regress/modes.h"

#include <glob.h>

#include <algorithm>
#include <filesystem>
#include <sstream>
#include <utility>

#include "eval/evaluate.h"
#include "experiment/diagnose.h"
#include "experiment/montecarlo.h"
#include "experiment/odometry.h"
#include "experiment/steps.h"
#include "recording/recording.h"
#include "recording/truth.h"
#include "sim/scenario.h"
#include "sim/simulator.h"

namespace roamlab::regress {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// What `roamlab evaluate` writes (eval/evaluate.cc, eval/parameters.cc).
json MetricsSchema() {
  const json stats = {{"rmse", "number"}, {"mean", "number"}, {"median", "number"}, {"max", "number"}};
  return {
      {"ate_m", "number"},
      {"rpe_trans_m", "number"},
      {"rpe_rot_deg", "number"},
      {"nees_mean", "number"},
      {"association",
       {{"estimate_poses", "number"},
        {"reference_poses", "number"},
        {"matched", "number"},
        {"tolerance_s", "number"},
        {"max_time_difference_s", "number"}}},
      {"alignment", {{"q_ref_est_wxyz", "numbers"}, {"p_ref_est_m", "numbers"}}},
      {"ate",
       {{"poses", "number"}, {"rmse_m", "number"}, {"mean_m", "number"}, {"median_m", "number"}, {"max_m", "number"}}},
      {"rpe",
       {{"delta_poses", "number"}, {"delta_s", "number"}, {"pairs", "number"}, {"trans_m", stats}, {"rot_deg", stats}}},
      {"rpe_distance", {{"distance_m", "number"}, {"pairs", "number"}, {"trans_m", stats}, {"rot_deg", stats}}},
      {"nees",
       {{"poses", "number"},
        {"without_covariance", "number"},
        {"not_positive_definite", "number"},
        {"dof", "number"},
        {"band_single_run", "numbers"},
        {"t0_s", "number"},
        {"fraction_in_band", "number"}}},
      {"velocity",
       {{"fused",
         {{"linear_rmse", "number"}, {"angular_rmse", "number"}, {"rpe_rot_deg", "number"}, {"intervals", "number"}}},
        {"encoders_only",
         {{"linear_rmse", "number"}, {"angular_rmse", "number"}, {"rpe_rot_deg", "number"}, {"intervals", "number"}}},
        {"rpe_delta_poses", "number"}}},
      {"parameters",
       {{"<parameter>",
         {{"truth", "numbers"},
          {"estimate", "numbers"},
          {"std", "numbers"},
          {"error", "numbers"},
          {"error_over_std", "numbers"},
          {"angle_error_deg", "number"},
          {"component_error", "numbers"},
          {"relative_error", "relative"}}}}}};
}

json CountsSchema() {
  return {{"<stream>",
           {{"attached", "number"},
            {"rejected", "number"},
            {"too_late", "number"},
            {"outside", "number"},
            {"duplicates", "number"},
            {"gaps", "number"},
            {"frozen", "number"}}}};
}

// What `roamlab calibrate` writes (estimator/calibration_io.h).
json CalibrationSchema() {
  return {{"parameters", {{"<parameter>", {{"estimate", "numbers"}, {"std", "numbers"}}}}},
          {"solver",
           {{"iterations", "number"},
            {"initial_cost", "number"},
            {"final_cost", "number"},
            {"seconds", "timing"},
            {"stages", json::array({{{"iterations", "number"},
                                     {"initial_cost", "number"},
                                     {"final_cost", "number"},
                                     {"rejected", "number"},
                                     {"seconds", "timing"}}})}}},
          {"measurements", CountsSchema()}};
}

// What `roamlab track` writes to summary.json (estimator/tracking_io.h).
json SummarySchema() {
  return {{"poses", "number"},
          {"updates", "number"},
          {"mean_iterations", "number"},
          {"window", "number"},
          {"rejected_measurements", "number"},
          {"mean_update_s", "timing"},
          {"max_update_s", "timing"},
          {"p99_update_s", "timing"},
          {"seconds", "timing"},
          {"realtime_factor", "timing"},
          {"measurements", CountsSchema()}};
}

// What `roamlab montecarlo` writes (experiment/montecarlo.h, eval/nees.h).
json NeesSchema() {
  return {{"runs", "number"}, {"dof", "number"}, {"band", "numbers"},      {"alpha", "number"},
          {"t0_s", "number"}, {"t", "numbers"},  {"mean_nees", "numbers"}, {"fraction_in_band", "number"}};
}
json RunsSchema() {
  return {{"runs", json::array({{{"seed", "number"},
                                 {"ate_m", "number"},
                                 {"mean_nees", "number"},
                                 {"rpe_m", "number"},
                                 {"track_seconds", "timing"}}})}};
}

// A failed step's error as the command would print it: "roamlab COMMAND: message" (Outcome::step names an inner
// command).
Status Failed(const std::string& command, const experiment::Outcome& outcome) {
  return Status::Error("roamlab " + (outcome.step.empty() ? command : outcome.step) + ": " + outcome.status.message());
}

// The case's recording: the given directory, or the scenario simulated with the case's seed into DIR/recording.
Result<std::string> Recording(const CaseContext& context) {
  if (!context.c.recording.empty()) return context.c.recording;
  experiment::SimulateRequest request;
  request.scenario = context.c.scenario;
  request.out = context.dir + "/recording";
  request.seed = context.c.seed;
  request.faults = context.c.faults;
  const experiment::Outcome outcome = experiment::SimulateToDirectory(request);
  if (!outcome.ok()) return Failed("simulate", outcome);
  return request.out;
}

// Calibrates `recording` with `config` into DIR/calibration.
Status Calibrate(const CaseContext& context, const std::string& recording, const std::string& config) {
  experiment::CalibrateRequest request;
  request.recording = recording;
  request.config = config;
  request.out = context.dir + "/calibration";
  const experiment::Outcome outcome = experiment::CalibrateToDirectory(request);
  return outcome.ok() ? Status::Ok() : Failed("calibrate", outcome);
}

// The calibration.json tracking uses: the given file, one calibrated into DIR/calibration, or none ("").
Result<std::string> CalibrationFile(const CaseContext& context, const std::string& recording) {
  if (!context.c.calibration.empty()) return context.c.calibration;
  if (context.c.calibrate.empty()) return std::string();
  const Status st = Calibrate(context, recording, context.c.calibrate);
  if (!st.ok()) return st;
  return context.dir + "/calibration/calibration.json";
}

// Evaluates the estimate in `estimate` against the recording's truth into DIR/evaluation (no figures).
Status Evaluate(const CaseContext& context, const std::string& estimate, const std::string& recording) {
  eval::EvaluateOptions options;
  options.estimate_dir = estimate;
  options.recording_dir = recording;
  if (context.c.t0_s) options.nees_t0_s = *context.c.t0_s;
  const auto failed = [](const std::string& message) { return Status::Error("roamlab evaluate: " + message); };
  if (const std::string problem = options.Validate(); !problem.empty()) return failed(problem);
  const Result<eval::Evaluation> evaluation = eval::Evaluate(options);
  if (!evaluation.ok()) return failed(evaluation.status().message());
  const Result<eval::WrittenEvaluation> written =
      eval::WriteEvaluation(evaluation.value(), context.dir + "/evaluation", false);
  return written.ok() ? Status::Ok() : failed(written.status().message());
}

Status RunCalibrateCase(const CaseContext& context) {
  const Result<std::string> recording = Recording(context);
  if (!recording.ok()) return recording.status();
  const Status st = Calibrate(context, recording.value(), context.c.config);
  if (!st.ok()) return st;
  return Evaluate(context, context.dir + "/calibration", recording.value());
}

// Tracking runs without its per-update time budget (tracking.time_budget_s): where an update reaches it, the result
// would depend on the machine's load, and a regression value must not.
Status RunTrackCase(const CaseContext& context) {
  const Result<std::string> recording = Recording(context);
  if (!recording.ok()) return recording.status();
  const Result<std::string> calibration = CalibrationFile(context, recording.value());
  if (!calibration.ok()) return calibration.status();
  experiment::TrackRequest request;
  request.recording = recording.value();
  request.config = context.c.config;
  request.calibration = calibration.value();
  request.out = context.dir + "/tracking";
  request.no_time_budget = true;
  const experiment::Outcome outcome = experiment::TrackToDirectory(request);
  if (!outcome.ok()) return Failed("track", outcome);
  return Evaluate(context, request.out, recording.value());
}

Status RunMonteCarloCase(const CaseContext& context) {
  std::string calibration = context.c.calibration;
  if (!context.c.calibrate.empty()) {
    const Result<std::string> recording = Recording(context);
    if (!recording.ok()) return recording.status();
    const Result<std::string> file = CalibrationFile(context, recording.value());
    if (!file.ok()) return file.status();
    calibration = file.value();
  }
  experiment::MonteCarloOptions options;
  options.scenario = context.c.scenario;
  options.config = context.c.config;
  options.calibration = calibration;
  options.out = context.dir + "/montecarlo";
  options.runs = context.c.runs;
  options.jobs = context.jobs;
  options.seed_base = context.c.seed_base;
  options.no_time_budget = true;
  if (context.c.t0_s) options.t0_s = *context.c.t0_s;
  const experiment::Outcome outcome = experiment::RunMonteCarlo(options);
  return outcome.ok() ? Status::Ok() : Failed("montecarlo", outcome);
}

// What `roamlab odometry evaluate` writes (experiment/odometry.h).
json TableSchema() {
  return {{"rows", json::array({{{"model", "string"},
                                 {"mean", "string"},
                                 {"kernel", "string"},
                                 {"ate_m", "number"},
                                 {"rpe_mm", "number"},
                                 {"model_file", "string"}}})},
          {"recordings", json::array({{{"recording", "string"}, {"key_poses", "number"}}})},
          {"interval_s", "number"}};
}

// What `roamlab diagnose` writes to gap.json (apps/diagnose.h); effect parameters and stream names vary ("<any>").
json GapSchema() {
  const json effect = {{"name", "string"},
                       {"parameters", {{"<any>", "number"}}},
                       {"std", {{"<any>", "number"}}},
                       {"baseline_parameters", {{"<any>", "number"}}},
                       {"dof", "number"},
                       {"lr_statistic", "number"},
                       {"chi2_drop", "number"},
                       {"baseline_lr_statistic", "number"},
                       {"lr_pvalue", "number"},
                       {"delta_bic", "number"},
                       {"heldout_improvement", "number"},
                       {"decision", "string"}};
  const json fits = {
      {"<any>", {{"rms", "number"}, {"chi2_per_dof", "number"}, {"dof", "number"}, {"measurements", "number"}}}};
  const json component = {
      {"stream", "string"}, {"component", "number"}, {"chi2_per_dof", "number"}, {"expected_chi2_per_dof", "number"}};
  return {{"verdict", "string"},
          {"located", json::array({component})},
          {"effects", json::array({effect})},
          {"candidates", json::array({effect})},
          {"components", json::array({component})},
          {"fit", {{"before", fits}, {"after", fits}, {"heldout_start_s", "number"}, {"whole_run_nominal", fits}}},
          {"run", {{"fits", "number"}, {"seconds", "timing"}}}};
}

// The files a glob names, sorted; an error when it names none.
Result<std::vector<std::string>> Glob(const std::string& pattern) {
  glob_t g{};
  const int code = ::glob(pattern.c_str(), 0, nullptr, &g);
  std::vector<std::string> paths;
  if (code == 0)
    for (std::size_t i = 0; i < g.gl_pathc; ++i) paths.emplace_back(g.gl_pathv[i]);
  globfree(&g);
  if (paths.empty()) return Status::Error(pattern + " matches nothing");
  std::sort(paths.begin(), paths.end());
  return paths;
}

// The recordings of the odometry case's `train` or `test` entries, imported or simulated into DIR/recordings/.
Result<std::vector<std::string>> OdometryRecordings(const CaseContext& context, const std::vector<std::string>& globs,
                                                    const std::string& kind) {
  std::vector<std::string> recordings;
  for (const std::string& pattern : globs) {
    const Result<std::vector<std::string>> paths = Glob(pattern);
    if (!paths.ok()) return Status::Error(kind + ": " + paths.status().message());
    for (const std::string& path : paths.value()) {
      const std::string out = context.dir + "/recordings/" + kind + "_" + std::to_string(recordings.size()) + "_" +
                              fs::path(path).stem().string();
      if (fs::is_regular_file(fs::path(path) / "recording.yaml")) {
        recordings.push_back(path);
      } else if (fs::path(path).extension() == ".csv") {
        const experiment::Outcome outcome = experiment::ImportOptiOdomToDirectory(path, "", out);
        if (!outcome.ok()) return Failed("import", outcome);
        recordings.push_back(out);
      } else if (fs::path(path).extension() == ".yaml") {
        experiment::SimulateRequest request;
        request.scenario = path;
        request.out = out;
        request.seed = context.c.seed;
        const experiment::Outcome outcome = experiment::SimulateToDirectory(request);
        if (!outcome.ok()) return Failed("simulate", outcome);
        recordings.push_back(out);
      } else {
        return Status::Error(kind + ": " + path + " is not an OptiOdom run (.csv), a scenario (.yaml) or a recording");
      }
    }
  }
  return recordings;
}

// Learns each model on the training recordings and evaluates them all on the test recordings (table.json).
Status RunOdometryCase(const CaseContext& context) {
  const Result<std::vector<std::string>> train = OdometryRecordings(context, context.c.train, "train");
  if (!train.ok()) return train.status();
  const Result<std::vector<std::string>> test = OdometryRecordings(context, context.c.test, "test");
  if (!test.ok()) return test.status();
  experiment::OdometryEvaluateOptions evaluate;
  for (std::size_t i = 0; i < context.c.models.size(); ++i) {
    const Case::OdometryModel& m = context.c.models[i];
    experiment::OdometryLearnOptions options;
    options.recordings = train.value();
    options.model = m.model;
    if (!m.mean.empty()) options.mean = m.mean;
    if (!m.kernel.empty()) options.kernel = m.kernel;
    if (context.c.interval_s) options.interval_s = *context.c.interval_s;
    options.out = context.dir + "/models/" + std::to_string(i) + "_" + m.model + (m.mean.empty() ? "" : "_" + m.mean) +
                  (m.kernel.empty() ? "" : "_" + m.kernel) + ".json";
    std::error_code ec;
    fs::create_directories(context.dir + "/models", ec);
    const experiment::Outcome outcome = experiment::LearnOdometry(options);
    if (!outcome.ok()) return Failed("odometry", outcome);
    evaluate.models.push_back(options.out);
  }
  evaluate.recordings = test.value();
  evaluate.out = context.dir + "/odometry";
  evaluate.plots = false;
  const experiment::Outcome outcome = experiment::EvaluateOdometry(evaluate);
  return outcome.ok() ? Status::Ok() : Failed("odometry", outcome);
}

// Diagnoses the case's recording, or the scenario simulated with the case's hidden effects, against the scenario.
Status RunDiagnoseCase(const CaseContext& context) {
  std::string recording = context.c.recording;
  if (recording.empty()) {
    Result<sim::Scenario> scenario = sim::LoadScenario(context.c.scenario);
    if (!scenario.ok()) return scenario.status();
    scenario.value().effects.clear();
    for (const auto& [name, parameters] : context.c.effects) scenario.value().effects.push_back({name, parameters});
    sim::SimulateOptions options;
    options.seed = context.c.seed;
    const auto simulated = sim::Simulate(scenario.value(), options);
    if (!simulated.ok()) return Status::Error("simulate: " + simulated.status().message());
    recording = context.dir + "/recording";
    Status st = recording::WriteRecording(simulated.value().recording, recording);
    if (st.ok()) st = recording::WriteTruth(simulated.value().truth, recording);  // for people; diagnose never reads it
    if (!st.ok()) return st;
  }
  experiment::DiagnoseRequest request;
  request.recording = recording;
  request.scenario = context.c.scenario;
  request.config = context.c.config;
  request.out = context.dir + "/diagnosis";
  if (context.c.baseline_seed) request.baseline_seed = *context.c.baseline_seed;
  request.no_plots = true;
  const experiment::Outcome outcome = experiment::DiagnoseToDirectory(request);
  if (outcome.ok()) return Status::Ok();
  return Status::Error("roamlab diagnose: " + outcome.status.message());
}

const std::vector<ModeSpec>& Modes() {
  static const std::vector<ModeSpec> modes = {
      {"calibrate",
       {"scenario", "recording", "seed", "config", "faults"},
       {"scenario|recording", "config"},
       {{"calibration", "calibration/calibration.json", CalibrationSchema()},
        {"metrics", "evaluation/metrics.json", MetricsSchema()}},
       RunCalibrateCase},
      {"track",
       {"scenario", "recording", "seed", "config", "calibration", "calibrate", "t0_s", "faults"},
       {"scenario|recording", "config"},
       {{"summary", "tracking/summary.json", SummarySchema()}, {"metrics", "evaluation/metrics.json", MetricsSchema()}},
       RunTrackCase},
      {"montecarlo",
       {"scenario", "seed", "config", "calibration", "calibrate", "runs", "seed_base", "t0_s"},
       {"scenario", "config", "runs"},
       {{"nees", "montecarlo/nees.json", NeesSchema()}, {"runs", "montecarlo/runs.json", RunsSchema()}},
       RunMonteCarloCase},
      {"odometry",
       {"train", "test", "models", "interval_s", "seed"},
       {"train", "test", "models"},
       {{"table", "odometry/table.json", TableSchema()}},
       RunOdometryCase},
      {"diagnose",
       {"scenario", "recording", "seed", "effects", "config", "baseline_seed"},
       {"scenario"},
       {{"gap", "diagnosis/gap.json", GapSchema()}},
       RunDiagnoseCase},
  };
  return modes;
}

}  // namespace

const ModeSpec* FindMode(const std::string& name) {
  for (const ModeSpec& mode : Modes())
    if (mode.name == name) return &mode;
  return nullptr;
}

std::string AvailableModeNames() {
  std::string names;
  for (const ModeSpec& mode : Modes())
    if (mode.run) names += (names.empty() ? "" : ", ") + mode.name;
  return names;
}

}  // namespace roamlab::regress
