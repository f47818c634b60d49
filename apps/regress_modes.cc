#include "apps/regress_modes.h"

#include <sstream>

#include "apps/commands.h"
#include "apps/evaluate.h"
#include "apps/montecarlo.h"
#include "apps/simulate.h"

namespace roamlab::apps::regress {
namespace {

using nlohmann::json;

// What `roamlab evaluate` writes (apps/evaluate.cc, eval/evaluate.cc, eval/parameters.cc).
json MetricsSchema() {
  const json stats = {{"rmse", "number"}, {"mean", "number"}, {"median", "number"}, {"max", "number"}};
  return {{"ate_m", "number"},
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
           {{"poses", "number"}, {"rmse_m", "number"}, {"mean_m", "number"}, {"median_m", "number"},
            {"max_m", "number"}}},
          {"rpe",
           {{"delta_poses", "number"}, {"delta_s", "number"}, {"pairs", "number"}, {"trans_m", stats},
            {"rot_deg", stats}}},
          {"rpe_distance",
           {{"distance_m", "number"}, {"pairs", "number"}, {"trans_m", stats}, {"rot_deg", stats}}},
          {"nees",
           {{"poses", "number"},
            {"without_covariance", "number"},
            {"not_positive_definite", "number"},
            {"dof", "number"},
            {"band_single_run", "numbers"},
            {"t0_s", "number"},
            {"fraction_in_band", "number"}}},
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
  return {{"<stream>", {{"attached", "number"}, {"rejected", "number"}, {"too_late", "number"},
                        {"outside", "number"}}}};
}

// What `roamlab calibrate` writes (apps/commands.cc).
json CalibrationSchema() {
  return {{"parameters", {{"<parameter>", {{"estimate", "numbers"}, {"std", "numbers"}}}}},
          {"solver",
           {{"iterations", "number"},
            {"initial_cost", "number"},
            {"final_cost", "number"},
            {"seconds", "timing"},
            {"stages",
             json::array({{{"iterations", "number"},
                           {"initial_cost", "number"},
                           {"final_cost", "number"},
                           {"rejected", "number"},
                           {"seconds", "timing"}}})}}},
          {"measurements", CountsSchema()}};
}

// What `roamlab track` writes to summary.json (apps/commands.cc).
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

// What `roamlab montecarlo` writes (apps/montecarlo.cc, eval/nees.cc).
json NeesSchema() {
  return {{"runs", "number"}, {"dof", "number"},       {"band", "numbers"},     {"alpha", "number"},
          {"t0_s", "number"}, {"t", "numbers"},        {"mean_nees", "numbers"}, {"fraction_in_band", "number"}};
}
json RunsSchema() {
  return {{"runs", json::array({{{"seed", "number"}, {"ate_m", "number"}, {"mean_nees", "number"},
                                  {"track_seconds", "timing"}}})}};
}

// Calls a command with its one-line error captured: the error of a failed command becomes the case's error.
template <typename Args>
Status Call(int (*command)(const Args&), Args args, const std::string& what) {
  std::ostringstream err;
  args.quiet = true;
  args.err = &err;
  const int code = command(args);
  if (code == 0) return Status::Ok();
  std::string message = err.str();
  while (!message.empty() && message.back() == '\n') message.pop_back();
  if (message.empty()) message = what + " failed with exit code " + std::to_string(code);
  return Status::Error(message);
}

// The case's recording: the given directory, or the scenario simulated with the case's seed into DIR/recording.
Result<std::string> Recording(const CaseContext& context) {
  if (!context.c.recording.empty()) return context.c.recording;
  SimulateArgs args;
  args.scenario = context.c.scenario;
  args.out = context.dir + "/recording";
  args.seed = context.c.seed;
  const Status st = Call(RunSimulate, args, "simulate");
  if (!st.ok()) return st;
  return args.out;
}

// The calibration.json tracking uses: the given file, one calibrated into DIR/calibration, or none ("").
Result<std::string> CalibrationFile(const CaseContext& context, const std::string& recording) {
  if (!context.c.calibration.empty()) return context.c.calibration;
  if (context.c.calibrate.empty()) return std::string();
  CalibrateArgs args;
  args.recording = recording;
  args.config = context.c.calibrate;
  args.out = context.dir + "/calibration";
  const Status st = Call(RunCalibrate, args, "calibrate");
  if (!st.ok()) return st;
  return args.out + "/calibration.json";
}

Status Evaluate(const CaseContext& context, const std::string& estimate, const std::string& recording) {
  EvaluateArgs args;
  args.estimate = estimate;
  args.recording = recording;
  args.out = context.dir + "/evaluation";
  if (context.c.t0_s) args.nees_t0_s = *context.c.t0_s;
  args.no_plots = true;
  return Call(RunEvaluate, args, "evaluate");
}

Status RunCalibrateCase(const CaseContext& context) {
  const Result<std::string> recording = Recording(context);
  if (!recording.ok()) return recording.status();
  CalibrateArgs args;
  args.recording = recording.value();
  args.config = context.c.config;
  args.out = context.dir + "/calibration";
  const Status st = Call(RunCalibrate, args, "calibrate");
  if (!st.ok()) return st;
  return Evaluate(context, args.out, recording.value());
}

// Tracking runs without its per-update time budget (tracking.time_budget_s): where an update reaches it, the result
// would depend on the machine's load, and a regression value must not.
Status RunTrackCase(const CaseContext& context) {
  const Result<std::string> recording = Recording(context);
  if (!recording.ok()) return recording.status();
  const Result<std::string> calibration = CalibrationFile(context, recording.value());
  if (!calibration.ok()) return calibration.status();
  TrackArgs args;
  args.recording = recording.value();
  args.config = context.c.config;
  args.calibration = calibration.value();
  args.out = context.dir + "/tracking";
  args.no_time_budget = true;
  const Status st = Call(RunTrack, args, "track");
  if (!st.ok()) return st;
  return Evaluate(context, args.out, recording.value());
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
  MonteCarloArgs args;
  args.scenario = context.c.scenario;
  args.config = context.c.config;
  args.calibration = calibration;
  args.out = context.dir + "/montecarlo";
  args.runs = context.c.runs;
  args.jobs = context.jobs;
  args.seed_base = context.c.seed_base;
  args.no_time_budget = true;
  if (context.c.t0_s) args.t0_s = *context.c.t0_s;
  return Call(RunMonteCarlo, args, "montecarlo");
}

const std::vector<ModeSpec>& Modes() {
  static const std::vector<ModeSpec> modes = {
      {"calibrate",
       {"scenario", "recording", "seed", "config"},
       {"scenario|recording", "config"},
       {{"calibration", "calibration/calibration.json", CalibrationSchema()},
        {"metrics", "evaluation/metrics.json", MetricsSchema()}},
       RunCalibrateCase},
      {"track",
       {"scenario", "recording", "seed", "config", "calibration", "calibrate", "t0_s"},
       {"scenario|recording", "config"},
       {{"summary", "tracking/summary.json", SummarySchema()},
        {"metrics", "evaluation/metrics.json", MetricsSchema()}},
       RunTrackCase},
      {"montecarlo",
       {"scenario", "seed", "config", "calibration", "calibrate", "runs", "seed_base", "t0_s"},
       {"scenario", "config", "runs"},
       {{"nees", "montecarlo/nees.json", NeesSchema()}, {"runs", "montecarlo/runs.json", RunsSchema()}},
       RunMonteCarloCase},
      // Issues in progress (model-free odometry, reality-gap diagnosis): known names, not available yet.
      {"odometry", {}, {}, {}, nullptr},
      {"diagnose", {}, {}, {}, nullptr},
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

}  // namespace roamlab::apps::regress
