// `roamlab montecarlo --command`: an external estimator under test (examples/dead_reckoning) over noise realizations.
// Each run's ATE in runs.json is the dead reckoning's own, as `simulate --seed`, the script and `evaluate` give it
// step by step; the NEES is averaged from its covariances; a failing command fails the call naming the run and the
// command.
#include <cmath>
#include <filesystem>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/apps/batch_fixture.h"

namespace roamlab {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using testing::ReadJson;
using testing::Roamlab;

std::string Example(const std::string& name) { return testing::SourceDir() + "/examples/dead_reckoning/" + name; }

TEST(ExternalCliTest, MonteCarloScoresTheDeadReckoningAsEvaluateDoes) {
  testing::TempDir dir;
  const std::string scenario = Example("indoor_diffdrive_mocap.yaml");
  const testing::CommandRun mc = Roamlab("montecarlo " + scenario + " --command 'sh " + Example("dead_reckoning.sh") +
                                             " {recording} {out}' --runs 3 --jobs 2 --seed-base 1000 --out mc --quiet",
                                         dir.path());
  ASSERT_EQ(mc.exit_code, 0) << mc.err;
  const nlohmann::json nees = ReadJson(fs::path(dir.path()) / "mc/nees.json");
  EXPECT_EQ(nees["runs"], 3);
  EXPECT_GT(nees["mean_nees"].size(), 1000u);
  const nlohmann::json runs = ReadJson(fs::path(dir.path()) / "mc/runs.json");
  ASSERT_EQ(runs["runs"].size(), 3u);

  for (int i = 0; i < 3; ++i) {
    const std::string seed = std::to_string(1000 + i), rec = "rec" + seed, est = "est" + seed;
    ASSERT_EQ(Roamlab("simulate " + scenario + " --seed " + seed + " --out " + rec + " --quiet", dir.path()).exit_code,
              0);
    ASSERT_EQ(testing::RunCommand("sh " + Example("dead_reckoning.sh") + " " + dir.File(rec) + " " + dir.File(est),
                                  dir.path())
                  .exit_code,
              0);
    const testing::CommandRun evaluated =
        Roamlab("evaluate --estimate " + est + " --recording " + rec + " --out eval" + seed + " --no-plots --quiet",
                dir.path());
    ASSERT_EQ(evaluated.exit_code, 0) << evaluated.err;
    const nlohmann::json metrics = ReadJson(fs::path(dir.path()) / ("eval" + seed) / "metrics.json");
    EXPECT_EQ(metrics["alignment"]["kind"], "none");  // the mocap stream fixes the world frame
    const double ate = runs["runs"][i]["ate_m"].get<double>();
    EXPECT_NEAR(ate, metrics["ate_m"].get<double>(), 1e-12 * ate) << "run " << i;
    EXPECT_NEAR(runs["runs"][i]["mean_nees"].get<double>(), metrics["nees_mean"].get<double>(), 1e-9) << "run " << i;
    EXPECT_GT(ate, 0.001) << "run " << i;  // dead reckoning drifts
  }
}

TEST(ExternalCliTest, AFailingCommandFailsTheCallNamingRunAndCommand) {
  testing::TempDir dir;
  const testing::CommandRun mc = Roamlab("montecarlo " + Example("indoor_diffdrive_mocap.yaml") +
                                             " --command 'echo broken >&2; exit 4' --runs 2 --jobs 1 --out mc --quiet",
                                         dir.path());
  EXPECT_EQ(mc.exit_code, 1);
  EXPECT_THAT(mc.err, HasSubstr("2 of 2 runs failed; first: run 0, seed 1000: estimator command 'echo broken >&2; "
                                "exit 4': exited with status 4"));
  EXPECT_THAT(mc.err, HasSubstr("mc/runs/000000/estimator.log: broken"));
  EXPECT_FALSE(fs::exists(fs::path(dir.path()) / "mc/nees.json"));
}

TEST(ExternalCliTest, WithoutCovarianceRunsAreScoredWithoutNees) {
  testing::TempDir dir;
  const std::string command = "sh " + Example("dead_reckoning.sh") + " {recording} {out} && rm {out}/covariance.csv";
  const testing::CommandRun mc =
      Roamlab("montecarlo " + Example("indoor_diffdrive_mocap.yaml") + " --command '" + command + "' --runs 2 --out mc",
              dir.path());
  ASSERT_EQ(mc.exit_code, 0) << mc.err;
  EXPECT_THAT(mc.out, HasSubstr("no NEES: the estimator wrote no covariance.csv"));
  EXPECT_FALSE(fs::exists(fs::path(dir.path()) / "mc/nees.json"));
  const nlohmann::json runs = ReadJson(fs::path(dir.path()) / "mc/runs.json");
  EXPECT_GT(runs["runs"][1]["ate_m"].get<double>(), 0.001);
  EXPECT_TRUE(runs["runs"][1]["mean_nees"].is_null());
}

TEST(ExternalCliTest, ConfigAndCommandTogetherAreBadInput) {
  testing::TempDir dir;
  const std::string scenario = Example("indoor_diffdrive_mocap.yaml");
  const testing::CommandRun both = Roamlab("montecarlo " + scenario + " --config " + testing::SourceDir() +
                                               "/configs/atv_tracking.yaml --command true --out mc",
                                           dir.path());
  EXPECT_EQ(both.exit_code, 2);
  EXPECT_THAT(both.err, HasSubstr("either as --config (roamlab's) or as --command"));
  const testing::CommandRun neither = Roamlab("montecarlo " + scenario + " --out mc", dir.path());
  EXPECT_EQ(neither.exit_code, 2);
  const testing::CommandRun timeout =
      Roamlab("montecarlo " + scenario + " --command true --timeout -1 --out mc", dir.path());
  EXPECT_EQ(timeout.exit_code, 2);
  EXPECT_THAT(timeout.err, HasSubstr("timeout_s must be positive"));
}

}  // namespace
}  // namespace roamlab
