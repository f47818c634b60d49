// A regression run (regress/regress.h) end to end on a short synthetic drive: a baseline made with the right estimator
// configuration, the same values again (with another number of jobs), and a configuration with a wrong noise level
// caught by the baseline checks, named in results.json and junit.xml.
#include "regress/regress.h"

#include <cmath>
#include <set>

#include <filesystem>
#include <fstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "eval/evaluate.h"
#include "experiment/steps.h"
#include "recording/recording.h"
#include "recording/truth.h"
#include "regress/modes.h"
#include "tests/recording/temp_dir.h"
#include "tests/support/paths.h"
#include "tests/support/synthetic.h"

namespace roamlab::regress {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

// The exit code `roamlab regress` gives for a run: 2 on bad input, 1 when a check fails or a report cannot be
// written, 0 when every check passes.
int RunRegress(const RunOptions& options) {
  SuiteResult result;
  RunReports reports;
  const experiment::Outcome outcome = RunSuite(options, &result, &reports);
  if (!outcome.ok()) return outcome.bad_input ? 2 : 1;
  return result.Passed() ? 0 : 1;
}

std::string Source(const std::string& name) { return roamlab::testing::SourceDir() + "/configs/" + name; }

// The ATV tracking configuration with the synthetic drive's calibration (seed Table I, tests/support/synthetic.h)
// and a noise value replaced: tracking with known parameters (no calibration prior), whose consistency then depends
// on the noise levels. The synthetic drive is eq. 15's rigid vehicle: the MuJoCo ATV's measured physics (rows at the
// ground contact, cornering compliance, the odometer's coloured disturbance (held at zero) and the model residual in
// the odometer's and the IMU's noise) is replaced by none, and the noise by the generator's sensor noise.
std::string TrackingConfig(const std::string& from, const std::string& to) {
  std::string text = testing::ReadFile(Source("atv_tracking.yaml"));
  const std::pair<std::string, std::string> replacements[] = {
      {"calibration_prior: true", "calibration_prior: false"},
      {"gps.lever_arm: {value: [0, 0, 0]}", "gps.lever_arm: {value: [0.57, -0.46, 0.32]}"},
      {"imu.misalignment: {value: [1, 0, 0, 0]}", "imu.misalignment: {value: [0.938, 0.104, 0.313, 0.104]}"},
      {"magnetometer.A: {value: [1, 0, 0, 0, 1, 0, 0, 0, 1]}",
       "magnetometer.A: {value: [0.87, -0.02, -0.02, 0.0, 0.88, 0.0, -0.02, -0.04, 0.85]}"},
      {"magnetometer.b: {value: [0, 0, 0]}", "magnetometer.b: {value: [-0.008, -0.007, -0.040]}"},
      {"odometer.cornering_front: {value: 0.0208}", "odometer.cornering_front: {value: 0.0}"},
      {"odometer.cornering_rear: {value: 0.0208}", "odometer.cornering_rear: {value: 0.0}"},
      {"options: {contact_height_m: 0.28, pitch_lever_m: 0.625, front_slip_velocity: 1}",
       "options: {contact_height_m: 0, pitch_lever_m: 0}"},
      {"odometer.disturbance: {value: [0, 0, 0], free: true,", "odometer.disturbance: {value: [0, 0, 0], free: false,"},
      {"noise: {speed_mps: 0.033, steering_rad: 0.053, lateral_mps: 0.02, vertical_mps: 0.05}",
       "noise: {speed_mps: 0.033, steering_rad: 0.014, lateral_mps: 0.02, vertical_mps: 0.1}"},
      {"noise: {sigma_radps: 0.040}", "noise: {sigma_radps: 0.033}"},
      {"noise: {sigma_mps2: 0.084}", "noise: {sigma_mps2: 0.067}"},
      {from, to}};
  for (const auto& [a, b] : replacements) {
    const std::size_t at = text.find(a);
    EXPECT_NE(at, std::string::npos) << a;
    if (at != std::string::npos) text.replace(at, a.size(), b);
  }
  return text;
}

json ReadJson(const std::string& path) {
  std::ifstream in(path);
  return json::parse(in);
}

class RegressTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new testing::TempDir();
    testing::SyntheticOptions options;
    options.duration_s = 8.0;
    options.seed = 11;
    const testing::SyntheticRecording synthetic = testing::MakeAtvRecording(options);
    ASSERT_TRUE(recording::WriteRecording(synthetic.recording, dir_->File("rec")).ok());
    ASSERT_TRUE(recording::WriteTruth(synthetic.truth, dir_->File("rec")).ok());
    testing::WriteFile(dir_->File("good.yaml"), TrackingConfig("sigma_m: 0.33", "sigma_m: 0.33"));
    // Wrong noise levels: a GPS 10 times noisier than configured is trusted too little, an odometer 10 times less
    // noisy than it is trusted too much.
    testing::WriteFile(dir_->File("gps_x10.yaml"), TrackingConfig("sigma_m: 0.33", "sigma_m: 3.3"));
    testing::WriteFile(dir_->File("speed_div10.yaml"), TrackingConfig("speed_mps: 0.033", "speed_mps: 0.0033"));
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }

  // A suite with one tracking case on the synthetic recording, with baseline checks.
  static std::string Suite(const std::string& config) {
    const std::string path = dir_->File("suite_" + config);
    testing::WriteFile(path,
                       "suite: degraded\nbaseline: baseline\ncases:\n"
                       "  - name: synthetic_track\n"
                       "    mode: track\n"
                       "    recording: rec\n"
                       "    config: " +
                           config +
                           "\n"
                           "    checks:\n"
                           "      - {metric: metrics.ate_m, bound: \"<= 1.25 * baseline\"}\n"
                           "      - {metric: metrics.nees_mean, bound: \"<= 2 * baseline\"}\n"
                           "      - {metric: metrics.nees_mean, bound: \">= 0.5 * baseline\"}\n"
                           "      - {metric: metrics.nees.fraction_in_band, bound: \">= baseline - 0.1\"}\n"
                           "      - {metric: summary.poses, bound: \">= 100\"}\n"
                           "      - {metric: summary.measurements.odometer.rejected, bound: \"<= baseline + 20\"}\n");
    return path;
  }

  static int Run(const std::string& suite, const std::string& out, bool update, int jobs) {
    RunOptions args;
    args.suite = suite;
    args.out = dir_->File(out);
    args.update_baseline = update;
    args.jobs = jobs;
    return RunRegress(args);
  }

  static testing::TempDir* dir_;
};
testing::TempDir* RegressTest::dir_ = nullptr;

TEST_F(RegressTest, BaselineCatchesWrongNoiseLevels) {
  // Baseline with the right configuration; every check then passes against it.
  ASSERT_EQ(Run(Suite("good.yaml"), "out_update", true, 1), 0);
  const json baseline = ReadJson(dir_->File("baseline/synthetic_track.json"));
  ASSERT_EQ(baseline["values"].size(), 5u) << baseline.dump();

  // The same suite again with two jobs: the same values, bit for bit.
  ASSERT_EQ(Run(Suite("good.yaml"), "out_again", false, 2), 0);
  const json again = ReadJson(dir_->File("out_again/results.json"));
  for (const json& check : again["cases"][0]["checks"])
    EXPECT_EQ(check["value"], baseline["values"][check["metric"].get<std::string>()]) << check.dump();

  // Each wrong noise level fails a consistency check against the baseline, and the reports name it.
  for (const std::string config : {"gps_x10.yaml", "speed_div10.yaml"}) {
    const std::string out = "out_" + config;
    EXPECT_EQ(Run(Suite(config), out, false, 2), 1) << config;
    const json results = ReadJson(dir_->File(out + "/results.json"));
    int failed = 0;
    for (const json& check : results["cases"][0]["checks"]) {
      if (check["result"] != "failed") continue;
      ++failed;
      EXPECT_TRUE(check["baseline"].is_number()) << check.dump();
      EXPECT_NE(check["message"].get<std::string>().find("violates bound"), std::string::npos);
    }
    EXPECT_GE(failed, 1) << config << ": " << results.dump(2);
    EXPECT_EQ(results["checks"]["failed"], failed);
    const std::string junit = testing::ReadFile(dir_->File(out + "/junit.xml"));
    EXPECT_NE(junit.find("<failure message=\"value "), std::string::npos) << junit;
    EXPECT_NE(junit.find("classname=\"synthetic_track\" name=\"metrics.nees"), std::string::npos) << junit;
  }
}

TEST_F(RegressTest, MissingBaselineIsAnErrorNotAPass) {
  fs::remove_all(dir_->File("empty_baseline"));
  RunOptions args;
  args.suite = Suite("good.yaml");
  args.out = dir_->File("out_no_baseline");
  args.baseline = dir_->File("empty_baseline");
  args.filter = "synthetic_*";
  EXPECT_EQ(RunRegress(args), 1);
  const json results = ReadJson(dir_->File("out_no_baseline/results.json"));
  EXPECT_EQ(results["checks"]["errors"], 5);
  EXPECT_EQ(results["checks"]["passed"], 1);
  args.filter = "no_such_case";
  EXPECT_EQ(RunRegress(args), 2);
}

// One bound made impossible makes the run exit non-zero, and junit.xml names that check with
// its value and bound (and only that one fails).
TEST_F(RegressTest, ImpossibleBoundFailsAndJunitNamesTheCheck) {
  const std::string path = dir_->File("suite_impossible.yaml");
  testing::WriteFile(path,
                     "cases:\n  - name: synthetic_track\n    mode: track\n    recording: rec\n"
                     "    config: good.yaml\n    checks:\n"
                     "      - {metric: metrics.ate_m, bound: \"<= 100\"}\n"
                     "      - {metric: summary.poses, bound: \"<= 1\"}\n");
  EXPECT_EQ(Run(path, "out_impossible", false, 1), 1);
  const json results = ReadJson(dir_->File("out_impossible/results.json"));
  EXPECT_EQ(results["checks"]["failed"], 1);
  EXPECT_EQ(results["checks"]["passed"], 1);
  const double poses = results["cases"][0]["checks"][1]["value"].get<double>();
  EXPECT_GT(poses, 1.0);
  const std::string junit = testing::ReadFile(dir_->File("out_impossible/junit.xml"));
  char value[32];
  std::snprintf(value, sizeof value, "%.6g", poses);
  EXPECT_NE(junit.find("<testcase classname=\"synthetic_track\" name=\"summary.poses\">\n      <failure message=\""
                       "value " +
                       std::string(value) + " violates bound &apos;&lt;= 1&apos;\""),
            std::string::npos)
      << junit;
  EXPECT_EQ(junit.find("<failure", junit.find("<failure") + 1), std::string::npos) << junit;
}

// An open target is evaluated and reported but does not fail the run; one that holds is reported as met. A case whose
// data directory is absent is skipped (exit 0, every check a <skipped> testcase naming the directory).
TEST_F(RegressTest, OpenTargetsAndAbsentDataDoNotFailTheRun) {
  const std::string path = dir_->File("suite_open.yaml");
  testing::WriteFile(path,
                     "cases:\n  - name: synthetic_track\n    mode: track\n    recording: rec\n"
                     "    config: good.yaml\n    checks:\n"
                     "      - {metric: summary.poses, bound: \"<= 1\", open: \"speed target, not met yet\"}\n"
                     "      - {metric: summary.poses, bound: \">= 100\", open: \"speed target\"}\n"
                     "      - {metric: metrics.rpe_trans_m, bound: \"<= 2 * metrics.ate_m + 1\"}\n"
                     "  - name: real_data\n    mode: track\n    data: no_such_directory\n"
                     "    recording: no_such_directory/rec\n    config: good.yaml\n    checks:\n"
                     "      - {metric: metrics.ate_m, bound: \"<= 1\"}\n");
  EXPECT_EQ(Run(path, "out_open", false, 1), 0);
  const json results = ReadJson(dir_->File("out_open/results.json"));
  const json& checks = results["cases"][0]["checks"];
  EXPECT_EQ(checks[0]["result"], "open");
  EXPECT_NE(checks[0]["message"].get<std::string>().find("speed target, not met yet"), std::string::npos);
  EXPECT_EQ(checks[1]["result"], "open met");
  EXPECT_EQ(checks[2]["result"], "passed");
  EXPECT_TRUE(checks[2]["threshold"].is_number());
  EXPECT_EQ(results["cases"][1]["checks"][0]["result"], "skipped");
  EXPECT_NE(results["cases"][1]["skipped"].get<std::string>().find("no_such_directory"), std::string::npos);
  const std::string junit = testing::ReadFile(dir_->File("out_open/junit.xml"));
  EXPECT_NE(junit.find("<skipped message=\"open target not met (speed target, not met yet): value "), std::string::npos)
      << junit;
  EXPECT_NE(junit.find("violates bound &apos;&lt;= 1&apos;\"/>"), std::string::npos) << junit;
  EXPECT_NE(junit.find("<skipped message=\"case skipped: data directory "), std::string::npos) << junit;

  // Without the marker the same bound fails the run.
  testing::WriteFile(path,
                     "cases:\n  - name: synthetic_track\n    mode: track\n    recording: rec\n"
                     "    config: good.yaml\n    checks:\n      - {metric: summary.poses, bound: \"<= 1\"}\n");
  EXPECT_EQ(Run(path, "out_closed", false, 1), 1);
}

// An external estimator under test (a `command:` instead of `config:`): the dead reckoning of examples/ on its
// scenario is scored as roamlab's own estimates are, and its ATE is the one `evaluate` computes from its files; a
// command that fails, writes a malformed trajectory or exceeds its time makes its case an error that results.json and
// junit.xml name, while the other cases still run.
TEST_F(RegressTest, ExternalCommandCasesAreScoredAndTheirFailuresNamed) {
  const std::string source = roamlab::testing::SourceDir();
  const std::string scenario = source + "/examples/dead_reckoning/indoor_diffdrive_mocap.yaml";
  const std::string script = source + "/examples/dead_reckoning/dead_reckoning.sh";
  testing::WriteFile(dir_->File("bad_line.tum"), "0.0 0 0 0 0 0 0 1\n0.01 0 0 0 0 0 0\n");
  const std::string path = dir_->File("suite_external.yaml");
  const auto track_case = [&](const std::string& name, const std::string& command, const std::string& extra) {
    return "  - name: " + name + "\n    mode: track\n    scenario: " + scenario + "\n    seed: 1\n    command: \"" +
           command + "\"\n" + extra + "    checks:\n      - {metric: metrics.ate_m, bound: \"<= 0.05\"}\n";
  };
  testing::WriteFile(path, "cases:\n" + track_case("dead_reckoning", "sh " + script + " {recording} {out}", "") +
                               track_case("exits_3", "echo no encoders >&2; exit 3", "") +
                               track_case("malformed", "cp bad_line.tum {out}/trajectory.tum", "") +
                               track_case("too_slow", "sleep 20; : {out}", "    timeout_s: 0.5\n"));
  EXPECT_EQ(Run(path, "out_external", false, 2), 1);
  const json results = ReadJson(dir_->File("out_external/results.json"));
  ASSERT_EQ(results["cases"].size(), 4u) << results.dump(2);
  const json& good = results["cases"][0];
  EXPECT_EQ(good["checks"][0]["result"], "passed") << good.dump(2);
  const double ate = good["checks"][0]["value"].get<double>();
  EXPECT_GT(ate, 0.001);  // dead reckoning drifts: not the truth scored against itself

  // The same ATE from `evaluate` on the files the command wrote and the recording the case simulated.
  eval::EvaluateOptions evaluate;
  evaluate.estimate_dir = dir_->File("out_external/cases/dead_reckoning/estimate");
  evaluate.recording_dir = dir_->File("out_external/cases/dead_reckoning/recording");
  const auto evaluation = eval::Evaluate(evaluate);
  ASSERT_TRUE(evaluation.ok()) << evaluation.status().message();
  EXPECT_EQ(evaluation.value().metrics["ate_m"].get<double>(), ate);
  EXPECT_TRUE(evaluation.value().metrics.contains("nees"));
  EXPECT_FALSE(fs::exists(dir_->File("out_external/cases/dead_reckoning/input/ground_truth.tum")));

  const auto error = [&](int k) { return results["cases"][k]["error"].get<std::string>(); };
  EXPECT_THAT(error(1), ::testing::HasSubstr("estimator command 'echo no encoders >&2; exit 3': exited with status 3"));
  EXPECT_THAT(error(1), ::testing::HasSubstr("estimator.log: no encoders"));
  EXPECT_THAT(error(2), ::testing::HasSubstr("estimate/trajectory.tum:2"));
  EXPECT_THAT(error(3), ::testing::HasSubstr("killed after the time-out of 0.5 s"));
  const std::string junit = testing::ReadFile(dir_->File("out_external/junit.xml"));
  for (const char* name : {"exits_3", "malformed", "too_slow"})
    EXPECT_NE(junit.find("<testcase classname=\"" + std::string(name) + "\" name=\"metrics.ate_m\">\n      <error"),
              std::string::npos)
        << name << "\n"
        << junit;
}

// montecarlo with a command: every run's recording goes to the command, and the runs' ATE and NEES are scored.
TEST_F(RegressTest, ExternalMonteCarloCase) {
  const std::string source = roamlab::testing::SourceDir();
  const std::string path = dir_->File("suite_external_mc.yaml");
  testing::WriteFile(path, "cases:\n  - name: dead_reckoning_mc\n    mode: montecarlo\n    scenario: " + source +
                               "/examples/dead_reckoning/indoor_diffdrive_mocap.yaml\n    command: \"sh " + source +
                               "/examples/dead_reckoning/dead_reckoning.sh\"\n    runs: 2\n    checks:\n"
                               "      - {metric: runs.runs.ate_m.max, bound: \"<= 0.05\"}\n"
                               "      - {metric: nees.fraction_in_band, bound: \">= 0\"}\n");
  EXPECT_EQ(Run(path, "out_external_mc", false, 2), 0);
  const std::string runs = dir_->File("out_external_mc/cases/dead_reckoning_mc/montecarlo/runs");
  EXPECT_TRUE(fs::exists(runs + "/000001/estimate/covariance.csv"));
  EXPECT_FALSE(fs::exists(runs + "/000001/recording"));  // removed once the run succeeded
}

// A model-free odometry case on synthetic OptiOdom files (a differential drive whose wheel radii and track differ
// from its metadata): import, learn, evaluate, and checks on selected rows of table.json.
TEST_F(RegressTest, OdometryCaseLearnsAndEvaluatesFromOptiOdomFiles) {
  const fs::path data = dir_->File("optiodom");
  fs::create_directories(data / "train");
  fs::create_directories(data / "test");
  for (const char* set : {"train/syn", "test/syn"})
    std::ofstream(data / (std::string(set) + "_metadata.csv"))
        << "type,diff,,\nngear,43.7,,\nencRes,64,,\nLi,0.2,,\nDi,0.084,0.084,\nN,2,,\n";
  // Runs at 20 Hz: true radii 0.0415 m (right) and 0.0425 m (left), track 0.205 m; pattern 0 mixes lines, turns in
  // place and arcs, pattern 1 drives a circle. Ticks quantized with the fraction carried over.
  const auto write_run = [](const fs::path& path, int pattern, double duration_s) {
    const double ticks_per_rad = 43.7 * 64.0 / (2.0 * 3.14159265358979323846), dt = 0.05;
    double x = 0.0, y = 0.0, th = 0.0, carry_r = 0.0, carry_l = 0.0;
    std::ofstream out(path);
    out.precision(17);
    for (int k = 0; k * dt <= duration_s; ++k) {
      const int phase = static_cast<int>(k * dt / 2.0) % 4;
      const double wheel_r[] = {5.0, 3.0, 6.0, 2.0}, wheel_l[] = {5.0, -3.0, 3.0, 5.0};
      const double wr = k == 0 ? 0.0 : pattern == 0 ? wheel_r[phase] : 6.0;
      const double wl = k == 0 ? 0.0 : pattern == 0 ? wheel_l[phase] : 4.0;
      const double exact_r = wr * dt * ticks_per_rad + carry_r, exact_l = wl * dt * ticks_per_rad + carry_l;
      carry_r = exact_r - std::round(exact_r);
      carry_l = exact_l - std::round(exact_l);
      const double v = 0.5 * (0.0415 * wr + 0.0425 * wl), w = (0.0415 * wr - 0.0425 * wl) / 0.205;
      const double mid = th + 0.5 * w * dt;  // midpoint integration: fine at 20 Hz for a test
      x += v * dt * std::cos(mid);
      y += v * dt * std::sin(mid);
      th += w * dt;
      out << k * dt << "," << x << "," << y << "," << th << "," << std::round(exact_r) << "," << std::round(exact_l)
          << "\n";
    }
  };
  write_run(data / "train/syn_run-01.csv", 0, 60.0);
  write_run(data / "test/syn_run-01.csv", 1, 30.0);
  const std::string path = dir_->File("suite_odometry.yaml");
  testing::WriteFile(path,
                     "cases:\n  - name: odometry\n    mode: odometry\n    data: optiodom\n"
                     "    train: [\"train/*_run-??.csv\"]\n    test: [\"test/*_run-??.csv\"]\n"
                     "    interval_s: 0.25\n"
                     "    models: [{model: linear}, {model: parametric}]\n    checks:\n"
                     "      - {metric: \"table.rows[model=linear].ate_m\", bound: \"<= 0.2 * "
                     "table.rows[model=nominal].ate_m\"}\n"
                     "      - {metric: \"table.rows[model=parametric].ate_m\", bound: \"<= 0.2 * "
                     "table.rows[model=nominal].ate_m\"}\n"
                     "      - {metric: \"table.rows[model=nominal].ate_m\", bound: \">= 0.1\"}\n"
                     "      - {metric: \"table.rows[model=linear].model_file\", equals: nothing}\n"
                     "      - {metric: table.recordings.key_poses.min, bound: \">= 100\"}\n");
  EXPECT_EQ(Run(path, "out_odometry", false, 1), 1);  // the text check cannot hold
  const json results = ReadJson(dir_->File("out_odometry/results.json"));
  ASSERT_FALSE(results["cases"][0].contains("error")) << results.dump(2);
  const json& checks = results["cases"][0]["checks"];
  for (int i : {0, 1, 2, 4}) EXPECT_EQ(checks[i]["result"], "passed") << checks[i].dump();
  EXPECT_EQ(checks[3]["result"], "failed");
  EXPECT_NE(checks[3]["message"].get<std::string>().find("is not 'nothing'"), std::string::npos);
  EXPECT_LT(checks[0]["value"].get<double>(), checks[0]["threshold"].get<double>());
}

// Keys of a mode output's schema that the output lacks (dotted); placeholders stand for every key the output has.
void MissingKeys(const json& schema, const json& actual, const std::string& prefix, std::set<std::string>* missing) {
  if (schema.is_array()) {
    for (const json& row : actual) MissingKeys(schema[0], row, prefix + "[]", missing);
    return;
  }
  if (!schema.is_object()) return;
  for (const auto& [key, sub] : schema.items()) {
    if (key == "<parameter>" || key == "<stream>") {
      for (const auto& [name, value] : actual.items()) MissingKeys(sub, value, prefix + "." + name, missing);
    } else if (sub == "relative") {
      continue;  // derived from error and truth
    } else if (!actual.contains(key)) {
      missing->insert(prefix + "." + key);
    } else {
      MissingKeys(sub, actual[key], prefix + "." + key, missing);
    }
  }
}

json Output(const std::string& mode, const std::string& name) {
  for (const ModeOutput& o : FindMode(mode)->outputs)
    if (o.name == name) return o.schema;
  ADD_FAILURE() << mode << " has no output " << name;
  return json::object();
}

// The schemas that metric paths are validated against are what the commands write: every key is there, except
// those the commands write only in some cases (a NEES without covariance, rotation errors of vectors).
TEST_F(RegressTest, OutputSchemasMatchWhatTheCommandsWrite) {
  experiment::CalibrateRequest calibrate;
  calibrate.recording = dir_->File("rec");
  calibrate.config = Source("atv_calibration.yaml");
  calibrate.out = dir_->File("schema_cal");
  ASSERT_TRUE(experiment::CalibrateToDirectory(calibrate).ok());
  eval::EvaluateOptions evaluate;
  evaluate.estimate_dir = calibrate.out;
  evaluate.recording_dir = calibrate.recording;
  const Result<eval::Evaluation> evaluation = eval::Evaluate(evaluate);
  ASSERT_TRUE(evaluation.ok());
  const std::string evaluation_dir = dir_->File("schema_eval");
  ASSERT_TRUE(eval::WriteEvaluation(evaluation.value(), evaluation_dir, false).ok());

  std::set<std::string> missing;
  MissingKeys(Output("calibrate", "calibration"), ReadJson(calibrate.out + "/calibration.json"), "calibration",
              &missing);
  EXPECT_TRUE(missing.empty()) << *missing.begin();
  missing.clear();
  const json metrics = ReadJson(evaluation_dir + "/metrics.json");
  MissingKeys(Output("calibrate", "metrics"), metrics, "metrics", &missing);
  for (const std::string& key : missing) {
    const bool no_covariance = key == "metrics.nees" || key == "metrics.nees_mean";
    const bool not_wheeled = key == "metrics.velocity";  // written for wheel_encoders streams only
    const std::string name = key.substr(key.find('.', 8) + 1, key.rfind('.') - key.find('.', 8) - 1);
    const bool vector_parameter =
        key.rfind("metrics.parameters.", 0) == 0 && metrics["parameters"][name]["manifold"] != "S3" &&
        (key.find(".angle_error_deg") != std::string::npos || key.find(".component_error") != std::string::npos);
    EXPECT_TRUE(no_covariance || not_wheeled || vector_parameter) << key;
  }
  EXPECT_TRUE(metrics["parameters"].contains("imu.misalignment"));

  // Tracking (the outcome of the checks does not matter here: their baseline may be absent).
  Run(Suite("good.yaml"), "out_schema", false, 1);
  const std::string track = dir_->File("out_schema/cases/synthetic_track");
  ASSERT_TRUE(fs::exists(track + "/tracking/summary.json"));
  missing.clear();
  MissingKeys(Output("track", "summary"), ReadJson(track + "/tracking/summary.json"), "summary", &missing);
  MissingKeys(Output("track", "metrics"), ReadJson(track + "/evaluation/metrics.json"), "metrics", &missing);
  EXPECT_EQ(missing, (std::set<std::string>{"metrics.parameters", "metrics.velocity"}));
}

// --resume takes a finished case from its record only while the record matches the case: a changed bound runs it
// again. Without --resume every case runs.
TEST_F(RegressTest, ResumeReadsMatchingRecordsOnly) {
  const std::string path = dir_->File("suite_resume.yaml");
  const auto suite = [&](const std::string& bound) {
    testing::WriteFile(path,
                       "cases:\n  - name: synthetic_track\n    mode: track\n    recording: rec\n"
                       "    config: good.yaml\n    checks:\n      - {metric: summary.poses, bound: \"" +
                           bound + "\"}\n");
  };
  const auto run = [&](bool resume, std::string* lines) {
    RunOptions args;
    args.suite = path;
    args.out = dir_->File("out_resume");
    args.jobs = 1;
    args.resume = resume;
    args.progress = [lines](const std::string& line) { *lines += line + "\n"; };
    return RunRegress(args);
  };
  suite(">= 100");
  std::string lines;
  ASSERT_EQ(run(false, &lines), 0);
  EXPECT_NE(lines.find("synthetic_track (track): ran"), std::string::npos) << lines;
  const std::string first = testing::ReadFile(dir_->File("out_resume/results.json"));
  ASSERT_TRUE(fs::exists(dir_->File("out_resume/cases/synthetic_track/case_result.json")));

  lines.clear();
  ASSERT_EQ(run(true, &lines), 0);
  EXPECT_NE(lines.find("synthetic_track (track): resumed"), std::string::npos) << lines;
  EXPECT_EQ(testing::ReadFile(dir_->File("out_resume/results.json")), first);

  suite(">= 101");
  lines.clear();
  ASSERT_EQ(run(true, &lines), 0);
  EXPECT_NE(lines.find("synthetic_track (track): ran"), std::string::npos) << lines;
  lines.clear();
  ASSERT_EQ(run(false, &lines), 0);
  EXPECT_NE(lines.find("synthetic_track (track): ran"), std::string::npos) << lines;
}

}  // namespace
}  // namespace roamlab::regress
