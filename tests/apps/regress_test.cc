// `roamlab regress` end to end on a short synthetic drive: a baseline made with the right estimator configuration,
// the same values again (with another number of jobs), and a configuration with a wrong noise level caught by the
// baseline checks, named in results.json and junit.xml.
#include "apps/regress.h"

#include <set>

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "apps/evaluate.h"
#include "apps/regress_modes.h"
#include "recording/recording.h"
#include "recording/truth.h"
#include "tests/recording/temp_dir.h"
#include "tests/support/synthetic.h"

namespace roamlab::apps {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

std::string Source(const std::string& name) { return std::string(ROAMLAB_SOURCE_DIR) + "/scenarios/" + name; }

// The ATV tracking configuration with the synthetic drive's calibration (seed Table I, tests/support/synthetic.h)
// and a noise value replaced: tracking with known parameters (no calibration prior), whose consistency then depends
// on the noise levels.
std::string TrackingConfig(const std::string& from, const std::string& to) {
  std::string text = testing::ReadFile(Source("atv_tracking.yaml"));
  const std::pair<std::string, std::string> replacements[] = {
      {"calibration_prior: true", "calibration_prior: false"},
      {"gps.lever_arm: {value: [0, 0, 0]}", "gps.lever_arm: {value: [0.57, -0.46, 0.32]}"},
      {"imu.misalignment: {value: [1, 0, 0, 0]}", "imu.misalignment: {value: [0.938, 0.104, 0.313, 0.104]}"},
      {"magnetometer.A: {value: [1, 0, 0, 0, 1, 0, 0, 0, 1]}",
       "magnetometer.A: {value: [0.87, -0.02, -0.02, 0.0, 0.88, 0.0, -0.02, -0.04, 0.85]}"},
      {"magnetometer.b: {value: [0, 0, 0]}", "magnetometer.b: {value: [-0.008, -0.007, -0.040]}"},
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
    testing::WriteFile(path, "suite: degraded\nbaseline: baseline\ncases:\n"
                             "  - name: synthetic_track\n"
                             "    mode: track\n"
                             "    recording: rec\n"
                             "    config: " + config + "\n"
                             "    checks:\n"
                             "      - {metric: metrics.ate_m, bound: \"<= 1.25 * baseline\"}\n"
                             "      - {metric: metrics.nees_mean, bound: \"<= 2 * baseline\"}\n"
                             "      - {metric: metrics.nees_mean, bound: \">= 0.5 * baseline\"}\n"
                             "      - {metric: metrics.nees.fraction_in_band, bound: \">= baseline - 0.1\"}\n"
                             "      - {metric: summary.poses, bound: \">= 100\"}\n");
    return path;
  }

  static int Run(const std::string& suite, const std::string& out, bool update, int jobs) {
    RegressArgs args;
    args.suite = suite;
    args.out = dir_->File(out);
    args.update_baseline = update;
    args.jobs = jobs;
    args.quiet = true;
    return RunRegress(args);
  }

  static testing::TempDir* dir_;
};
testing::TempDir* RegressTest::dir_ = nullptr;

TEST_F(RegressTest, BaselineCatchesWrongNoiseLevels) {
  // Baseline with the right configuration; every check then passes against it.
  ASSERT_EQ(Run(Suite("good.yaml"), "out_update", true, 1), 0);
  const json baseline = ReadJson(dir_->File("baseline/synthetic_track.json"));
  ASSERT_EQ(baseline["values"].size(), 4u) << baseline.dump();

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
  RegressArgs args;
  args.suite = Suite("good.yaml");
  args.out = dir_->File("out_no_baseline");
  args.baseline = dir_->File("empty_baseline");
  args.quiet = true;
  args.filter = "synthetic_*";
  EXPECT_EQ(RunRegress(args), 1);
  const json results = ReadJson(dir_->File("out_no_baseline/results.json"));
  EXPECT_EQ(results["checks"]["errors"], 4);
  EXPECT_EQ(results["checks"]["passed"], 1);
  args.filter = "no_such_case";
  EXPECT_EQ(RunRegress(args), 2);
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
  for (const regress::ModeOutput& o : regress::FindMode(mode)->outputs)
    if (o.name == name) return o.schema;
  ADD_FAILURE() << mode << " has no output " << name;
  return json::object();
}

// The schemas that metric paths are validated against are what the commands write: every key is there, except
// those the commands write only in some cases (a NEES without covariance, rotation errors of vectors).
TEST_F(RegressTest, OutputSchemasMatchWhatTheCommandsWrite) {
  CalibrateArgs calibrate;
  calibrate.recording = dir_->File("rec");
  calibrate.config = Source("atv_calibration.yaml");
  calibrate.out = dir_->File("schema_cal");
  calibrate.quiet = true;
  ASSERT_EQ(RunCalibrate(calibrate), 0);
  EvaluateArgs evaluate;
  evaluate.estimate = calibrate.out;
  evaluate.recording = calibrate.recording;
  evaluate.out = dir_->File("schema_eval");
  evaluate.no_plots = true;
  evaluate.quiet = true;
  ASSERT_EQ(RunEvaluate(evaluate), 0);

  std::set<std::string> missing;
  MissingKeys(Output("calibrate", "calibration"), ReadJson(calibrate.out + "/calibration.json"), "calibration",
              &missing);
  EXPECT_TRUE(missing.empty()) << *missing.begin();
  missing.clear();
  const json metrics = ReadJson(evaluate.out + "/metrics.json");
  MissingKeys(Output("calibrate", "metrics"), metrics, "metrics", &missing);
  for (const std::string& key : missing) {
    const bool no_covariance = key == "metrics.nees" || key == "metrics.nees_mean";
    const std::string name = key.substr(key.find('.', 8) + 1, key.rfind('.') - key.find('.', 8) - 1);
    const bool vector_parameter = key.rfind("metrics.parameters.", 0) == 0 &&
                                  metrics["parameters"][name]["manifold"] != "S3" &&
                                  (key.find(".angle_error_deg") != std::string::npos ||
                                   key.find(".component_error") != std::string::npos);
    EXPECT_TRUE(no_covariance || vector_parameter) << key;
  }
  EXPECT_TRUE(metrics["parameters"].contains("imu.misalignment"));

  // Tracking (the outcome of the checks does not matter here: their baseline may be absent).
  Run(Suite("good.yaml"), "out_schema", false, 1);
  const std::string track = dir_->File("out_schema/cases/synthetic_track");
  ASSERT_TRUE(fs::exists(track + "/tracking/summary.json"));
  missing.clear();
  MissingKeys(Output("track", "summary"), ReadJson(track + "/tracking/summary.json"), "summary", &missing);
  MissingKeys(Output("track", "metrics"), ReadJson(track + "/evaluation/metrics.json"), "metrics", &missing);
  EXPECT_EQ(missing, std::set<std::string>{"metrics.parameters"});
}

}  // namespace
}  // namespace roamlab::apps
