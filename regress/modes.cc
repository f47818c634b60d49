#include "regress/modes.h"

#include <glob.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <sstream>
#include <utility>

#include "eval/evaluate.h"
#include "experiment/diagnose.h"
#include "experiment/external.h"
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

// The case's external estimator (Case::command), run in the suite file's directory.
experiment::ExternalCommand Command(const CaseContext& context) {
  experiment::ExternalCommand command;
  command.command = context.c.command;
  command.working_dir = context.c.command_dir;
  if (context.c.timeout_s) command.timeout_s = *context.c.timeout_s;
  return command;
}

// An external estimator on the recording stripped of its truth (DIR/input): its output in DIR/estimate, checked
// against the protocol, then evaluated like roamlab's own.
Status RunExternalTrackCase(const CaseContext& context, const std::string& recording) {
  const std::string input = context.dir + "/input", estimate = context.dir + "/estimate";
  Status st = experiment::MakeEstimatorInput(recording, input);
  const experiment::ExternalCommand command = Command(context);
  if (st.ok()) st = experiment::RunExternalCommand(command, input, estimate, context.dir + "/estimator.log");
  if (!st.ok()) return st;
  const Result<experiment::ExternalEstimate> read = experiment::ReadExternalEstimate(estimate);
  if (!read.ok()) return Status::Error("estimator command '" + command.command + "': " + read.status().message());
  return Evaluate(context, estimate, recording);
}

// Tracking runs without its per-update time budget (tracking.time_budget_s): where an update reaches it, the result
// would depend on the machine's load, and a regression value must not.
Status RunTrackCase(const CaseContext& context) {
  const Result<std::string> recording = Recording(context);
  if (!recording.ok()) return recording.status();
  if (!context.c.command.empty()) return RunExternalTrackCase(context, recording.value());
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
  if (!context.c.command.empty()) options.command = Command(context);
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

}  // namespace

ModeRunner FindModeRunner(const std::string& name) {
  static const std::map<std::string, ModeRunner> runners = {{"calibrate", RunCalibrateCase},
                                                            {"track", RunTrackCase},
                                                            {"montecarlo", RunMonteCarloCase},
                                                            {"odometry", RunOdometryCase},
                                                            {"diagnose", RunDiagnoseCase}};
  const auto it = runners.find(name);
  return it == runners.end() ? nullptr : it->second;
}

}  // namespace roamlab::regress
