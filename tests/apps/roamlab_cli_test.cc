// The command line end to end: calibrate and track on a synthetic recording, and one clear line with a non-zero
// exit on bad input.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/recording/temp_dir.h"
#include "tests/support/html_check.h"

#include "recording/recording.h"
#include "recording/trajectory.h"
#include "tests/support/paths.h"
#include "tests/support/synthetic.h"

namespace roamlab {
namespace {

namespace fs = std::filesystem;

using testing::CommandRun;

CommandRun Roamlab(const std::string& args, const fs::path& dir) {
  return testing::RunCommand(std::string(ROAMLAB_BINARY) + " " + args, dir.string());
}

class CliTest : public ::testing::Test {
 protected:
  testing::TempDir temp_;
  fs::path dir_{temp_.path()};
};

TEST_F(CliTest, CalibrateAndTrackWriteTheirOutputs) {
  roamlab::testing::SyntheticOptions options;
  options.duration_s = 5.0;
  ASSERT_TRUE(
      recording::WriteRecording(roamlab::testing::MakeAtvRecording(options).recording, (dir_ / "rec").string()).ok());
  const std::string config = roamlab::testing::SourceDir() + "/configs/atv_calibration.yaml";
  CommandRun r = Roamlab(
      "calibrate " + (dir_ / "rec").string() + " --config " + config + " --out " + (dir_ / "cal").string() + " --quiet",
      dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(dir_ / "cal" / "calibration.json");
  const nlohmann::json cal = nlohmann::json::parse(in);
  for (const char* name : {"gps.lever_arm", "imu.misalignment", "magnetometer.A", "odometer.kv_over_L"}) {
    ASSERT_TRUE(cal["parameters"].contains(name)) << name;
    EXPECT_TRUE(cal["parameters"][name].contains("estimate"));
    EXPECT_TRUE(cal["parameters"][name].contains("std"));
    EXPECT_TRUE(cal["parameters"][name].contains("observability"));
  }
  EXPECT_EQ(cal["parameters"]["imu.misalignment"]["estimate"].size(), 4u);
  EXPECT_EQ(cal["parameters"]["magnetometer.A"]["estimate"].size(), 9u);
  for (const char* key : {"iterations", "initial_cost", "final_cost", "termination", "seconds"})
    EXPECT_TRUE(cal["solver"].contains(key)) << key;
  EXPECT_TRUE(cal.contains("correlations"));
  // The joint information of the calibrated parameters, for tracking.calibration_prior: one row and column per
  // tangent dimension of the parameters listed (3 + 3 + 9 + 3 + 1 + 1 + 1 for the ATV configuration).
  ASSERT_TRUE(cal.contains("information"));
  EXPECT_EQ(cal["information"]["parameters"].size(), cal["parameters"].size());
  EXPECT_EQ(cal["information"]["matrix"].size(), 21u);

  const std::string track_config = roamlab::testing::SourceDir() + "/configs/atv_tracking.yaml";
  r = Roamlab("track " + (dir_ / "rec").string() + " --config " + track_config + " --calibration " +
                  (dir_ / "cal" / "calibration.json").string() + " --out " + (dir_ / "trk").string() + " --quiet",
              dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "trk" / "trajectory.tum"));
  EXPECT_TRUE(fs::exists(dir_ / "trk" / "covariance.csv"));
  std::ifstream sin(dir_ / "trk" / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(sin);
  for (const char* key : {"updates", "mean_update_s", "max_update_s", "rejected_measurements"})
    EXPECT_TRUE(summary.contains(key)) << key;

  // The tracking configuration tracks under the calibration's uncertainty: without a calibration, or with one that
  // lacks the information matrix, it refuses with one line.
  r = Roamlab("track " + (dir_ / "rec").string() + " --config " + track_config + " --out " + (dir_ / "t2").string(),
              dir_);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("calibration_prior needs --calibration"), std::string::npos) << r.err;
  nlohmann::json old = cal;
  old.erase("information");
  std::ofstream(dir_ / "old.json") << old.dump();
  r = Roamlab("track " + (dir_ / "rec").string() + " --config " + track_config + " --calibration " +
                  (dir_ / "old.json").string() + " --out " + (dir_ / "t3").string(),
              dir_);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("no 'information'"), std::string::npos) << r.err;
}

// montecarlo without --calibration, with tracking.calibrate (configs/atv_tracking.yaml): one offline calibration
// on the scenario's own noise seed, then the runs track under its prior. A 6 s drive keeps the test short.
TEST_F(CliTest, MonteCarloCalibratesOnceWhenTheConfigSaysHow) {
  std::ifstream in(roamlab::testing::SourceDir() + "/scenarios/atv_hills.yaml");
  std::string scenario((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string from = "duration_s: 30.0";
  ASSERT_NE(scenario.find(from), std::string::npos);
  scenario.replace(scenario.find(from), from.size(), "duration_s: 6.0");
  const std::string model = "../models/atv.xml";  // relative to the scenario's file: made absolute for the copy
  ASSERT_NE(scenario.find(model), std::string::npos);
  scenario.replace(scenario.find(model), model.size(), roamlab::testing::SourceDir() + "/models/atv.xml");
  const std::string short_scenario = (dir_ / "atv_short.yaml").string();
  std::ofstream(short_scenario) << scenario;
  const std::string config = roamlab::testing::SourceDir() + "/configs/atv_tracking.yaml";
  const CommandRun r = Roamlab("montecarlo " + short_scenario + " --config " + config + " --runs 2 --jobs 1 --t0 1" +
                                   " --out " + (dir_ / "mc").string(),
                               dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("calibrating once with"), std::string::npos) << r.err;
  std::ifstream cin(dir_ / "mc" / "calibration" / "calibration.json");
  const nlohmann::json cal = nlohmann::json::parse(cin);
  EXPECT_TRUE(cal.contains("information"));
  std::ifstream rin(dir_ / "mc" / "calibration" / "recording" / "recording.yaml");
  const std::string recording((std::istreambuf_iterator<char>(rin)), std::istreambuf_iterator<char>());
  EXPECT_NE(recording.find("seed: 1\n"), std::string::npos) << "calibrated on the scenario's own seed";
  std::ifstream nin(dir_ / "mc" / "nees.json");
  const nlohmann::json nees = nlohmann::json::parse(nin);
  EXPECT_EQ(nees["runs"], 2);
  EXPECT_GT(nees["mean_nees"].size(), 100u);
  // report.html: the headline, one row per run, the NEES figure embedded when gnuplot drew it.
  std::ifstream hin(dir_ / "mc" / "report.html");
  const std::string page((std::istreambuf_iterator<char>(hin)), std::istreambuf_iterator<char>());
  const testing::HtmlSummary html = testing::CheckHtml(page);
  ASSERT_EQ(html.error, "");
  EXPECT_NE(page.find("class=\"headline\">Average position NEES over 2 runs"), std::string::npos);
  ASSERT_EQ(html.table_headers.size(), 1u);
  EXPECT_EQ(html.table_headers[0].front(), "seed");
  EXPECT_EQ(html.image_sources.size(), std::filesystem::exists(dir_ / "mc" / "nees.png") ? 1u : 0u);
}

TEST_F(CliTest, BadInputGivesOneLineAndNonZeroExit) {
  const std::string config = roamlab::testing::SourceDir() + "/configs/atv_calibration.yaml";
  for (const std::string& args :
       {"calibrate /nonexistent/rec --config " + config + " --out " + (dir_ / "o").string(),
        "calibrate " + dir_.string() + " --config /nonexistent.yaml --out " + (dir_ / "o").string(),
        std::string("calibrate"), std::string("frobnicate")}) {
    const CommandRun r = Roamlab(args, dir_);
    EXPECT_NE(r.exit_code, 0) << args;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
  }
}

TEST_F(CliTest, EvaluateBadInputGivesOneLineAndExitCodeTwo) {
  fs::create_directories(dir_ / "est");
  fs::create_directories(dir_ / "rec");
  const std::string inputs = "evaluate --estimate " + (dir_ / "est").string() + " --recording " +
                             (dir_ / "rec").string() + " --out " + (dir_ / "out").string();
  const CommandRun missing = Roamlab(inputs + " --quiet", dir_);
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_EQ(missing.err.rfind("roamlab evaluate: ", 0), 0u) << missing.err;
  EXPECT_EQ(std::count(missing.err.begin(), missing.err.end(), '\n'), 1) << missing.err;
  EXPECT_FALSE(fs::exists(dir_ / "out" / "metrics.json"));
  const CommandRun align = Roamlab(inputs + " --align similarity", dir_);
  EXPECT_EQ(align.exit_code, 2);
  EXPECT_NE(align.err.find("unknown alignment 'similarity'"), std::string::npos) << align.err;
}

// A simulated recording and an estimate written from its truth with a known error.
class EvaluateCliTest : public CliTest {
 protected:
  void SetUp() override {
    roamlab::testing::SyntheticOptions options;
    options.duration_s = 5.0;
    const recording::Recording rec = roamlab::testing::MakeAtvRecording(options).recording;
    ASSERT_TRUE(recording::WriteRecording(rec, (dir_ / "rec").string()).ok());
    Trajectory estimate = *rec.ground_truth;
    for (std::size_t i = 0; i < estimate.size(); ++i) {
      const double t = SecondsBetween(estimate.front().t, estimate[i].t);
      estimate[i].p_world_body += Eigen::Vector3d(0.2 * std::sin(t), 0.1 * t, 0.3);
      estimate[i].q_world_body =
          estimate[i].q_world_body * Eigen::Quaterniond(Eigen::AngleAxisd(0.01 * t, Eigen::Vector3d::UnitY()));
    }
    fs::create_directories(dir_ / "est");
    ASSERT_TRUE(WriteTum(estimate, (dir_ / "est" / "trajectory.tum").string()).ok());
  }
  nlohmann::json Metrics(const std::string& out) const {
    std::ifstream in(dir_ / out / "metrics.json");
    return nlohmann::json::parse(in);
  }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
};

// The number: two plain files give the same ATE as the directory form on the same data.
TEST_F(EvaluateCliTest, PlainFilesGiveTheDirectoryFormsAte) {
  for (const std::string align : {"", " --align se3", " --align sim3"}) {
    CommandRun r = Roamlab("evaluate --estimate " + Path("est") + " --recording " + Path("rec") + " --out " +
                               Path("dir") + align + " --no-plots --quiet",
                           dir_);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    r = Roamlab("evaluate --reference " + Path("rec/ground_truth.tum") + " --estimate " + Path("est/trajectory.tum") +
                    " --out " + Path("files") + align + " --no-plots",
                dir_);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("ATE rotation"), std::string::npos) << r.out;
    nlohmann::json d = Metrics("dir"), f = Metrics("files");
    EXPECT_GT(d["ate_m"].get<double>(), 0.05) << align;  // an error that alignment does not remove
    for (const char* key : {"ate_m", "ate_rot_deg", "ate_axes", "rpe_trans_m", "rpe_rot_deg", "rpe_distance"})
      EXPECT_EQ(d[key], f[key]) << key << align;
    d["alignment"].erase("reason");  // why the default is what it is differs; the alignment itself does not
    f["alignment"].erase("reason");
    EXPECT_EQ(d["alignment"], f["alignment"]) << align;
    EXPECT_EQ(f["reference"]["kind"], "file");
  }
}

TEST_F(EvaluateCliTest, SeveralEstimatesGiveOneTable) {
  const CommandRun r =
      Roamlab("evaluate --reference " + Path("rec/ground_truth.tum") + " --estimate " + Path("est") + " --estimate " +
                  Path("est/trajectory.tum") + " --estimate " + Path("est") + " --out " + Path("cmp") + " --no-plots",
              dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json m = Metrics("cmp");
  ASSERT_EQ(m["table"].size(), 3u);
  EXPECT_EQ(m["table"][0]["name"], "est");
  EXPECT_EQ(m["table"][1]["name"], "trajectory.tum");
  EXPECT_EQ(m["table"][2]["name"], "est_2");  // a repeated name is made unique
  EXPECT_EQ(m["table"][0]["ate_m"], m["table"][1]["ate_m"]);
  EXPECT_NE(r.out.find("estimate"), std::string::npos);
  EXPECT_NE(r.out.find("est_2"), std::string::npos) << r.out;
}

TEST_F(EvaluateCliTest, BadPlainFilesGiveOneLineAndExitCodeTwo) {
  std::ofstream(dir_ / "short.tum") << "0 1 2 3 0 0 0\n";
  std::ofstream(dir_ / "late.tum") << "1000 1 2 3 0 0 0 1\n";
  const std::string reference = " --reference " + Path("rec/ground_truth.tum") + " --out " + Path("o");
  const std::pair<std::string, std::string> cases[] = {
      {"--estimate " + Path("none.tum") + reference, Path("none.tum") + ": missing"},
      {"--estimate " + Path("short.tum") + reference, Path("short.tum") + ":1: expected 8 fields"},
      {"--estimate " + Path("late.tum") + reference, Path("late.tum") + ": no pose within 0.01 s"},
      {"--estimate " + Path("est") + reference + " --reference-format csv", "--reference-format: unknown format"},
      {"--estimate " + Path("est") + " --out " + Path("o"), "no reference"}};
  for (const auto& [args, message] : cases) {
    const CommandRun r = Roamlab("evaluate " + args, dir_);
    EXPECT_EQ(r.exit_code, 2) << args;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
  }
}

TEST_F(CliTest, HelpDescribesEveryCommand) {
  for (const char* cmd : {"--help", "calibrate --help", "track --help"}) {
    const CommandRun r = Roamlab(cmd, dir_);
    EXPECT_EQ(r.exit_code, 0) << cmd;
  }
}

}  // namespace
}  // namespace roamlab
