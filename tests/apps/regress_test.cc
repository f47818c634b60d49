// `roamlab regress` end to end on a short synthetic drive: a baseline made with the right estimator configuration,
// the same values again (with another number of jobs), and a configuration with a wrong noise level caught by the
// baseline checks, named in results.json and junit.xml.
#include "apps/regress.h"

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "recording/recording.h"
#include "tests/recording/temp_dir.h"
#include "tests/support/synthetic.h"

namespace roamlab::apps {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

std::string Source(const std::string& name) { return std::string(ROAMLAB_SOURCE_DIR) + "/scenarios/" + name; }

// The ATV tracking configuration with the synthetic drive's calibration (seed Table I, tests/support/synthetic.h)
// and a noise value replaced: tracking with known parameters, whose consistency then depends on the noise levels.
std::string TrackingConfig(const std::string& from, const std::string& to) {
  std::string text = testing::ReadFile(Source("atv_tracking.yaml"));
  const std::pair<std::string, std::string> replacements[] = {
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
    ASSERT_TRUE(recording::WriteRecording(testing::MakeAtvRecording(options).recording, dir_->File("rec")).ok());
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

}  // namespace
}  // namespace roamlab::apps
