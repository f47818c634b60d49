// montecarlo's per-run result files on the local backend: --resume runs only the runs whose file is missing and the
// summary comes out byte-identical; a damaged result file is reported with one line naming it; `batch status`.
#include <algorithm>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/apps/batch_fixture.h"
#include "tests/recording/temp_dir.h"
#include "tests/support/paths.h"

namespace roamlab {
namespace {

namespace fs = std::filesystem;
using testing::ReadJson;
using testing::Roamlab;
using testing::SlurpFile;

class BatchLocalTest : public ::testing::Test {
 protected:
  // One 4-run Monte-Carlo of a 4 s drive for the whole suite (its shared calibration included).
  static void SetUpTestSuite() {
    temp_ = new testing::TempDir;
    const fs::path dir = temp_->path();
    const std::string scenario = testing::WriteShortAtvScenario(dir, "4.0");
    ASSERT_FALSE(scenario.empty());
    montecarlo_ = scenario + " --config " + roamlab::testing::SourceDir() +
                  "/configs/atv_tracking.yaml --runs 4 --jobs 2 --t0 1 --no-time-budget --quiet";
    const testing::CommandRun r = Roamlab("montecarlo " + montecarlo_ + " --out ref", dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  static void TearDownTestSuite() { delete temp_; }
  void SetUp() override {
    if (HasFatalFailure() || !fs::exists(dir_ / "ref" / "nees.json")) GTEST_FAIL() << "the reference run failed";
  }

  // A copy of the reference output as OUT, for a test to damage.
  fs::path CopyReference(const std::string& name) {
    const fs::path out = dir_ / name;
    fs::copy(dir_ / "ref", out, fs::copy_options::recursive);
    return out;
  }

  static testing::TempDir* temp_;
  static std::string montecarlo_;
  fs::path dir_{temp_->path()};
};
testing::TempDir* BatchLocalTest::temp_ = nullptr;
std::string BatchLocalTest::montecarlo_;

TEST_F(BatchLocalTest, EachRunWritesItsOwnResultFile) {
  for (int i = 0; i < 4; ++i) {
    const nlohmann::json run = ReadJson(dir_ / "ref" / "runs" / ("00000" + std::to_string(i) + ".json"));
    ASSERT_TRUE(run.is_object()) << i;
    EXPECT_EQ(run["run"], i);
    EXPECT_EQ(run["seed"], 1000 + i);
    EXPECT_EQ(run["t_ns"].size(), run["nees"].size());
    EXPECT_GT(run["t_ns"].size(), 100u);
  }
  // Nothing left under a temporary name.
  for (const auto& entry : fs::directory_iterator(dir_ / "ref" / "runs"))
    EXPECT_EQ(entry.path().extension(), ".json") << entry.path();
}

TEST_F(BatchLocalTest, ResumeRunsOnlyTheMissingRunsAndWritesTheSameBytes) {
  const fs::path out = CopyReference("resumed");
  fs::remove(out / "runs" / "000001.json");
  fs::remove(out / "runs" / "000003.json");
  for (const char* summary : {"nees.json", "runs.json", "nees.png", "report.html"}) fs::remove(out / summary);
  const std::string kept = SlurpFile(out / "runs" / "000000.json");
  const testing::CommandRun r = Roamlab("montecarlo " + montecarlo_ + " --out resumed --resume", dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(SlurpFile(out / "nees.json"), SlurpFile(dir_ / "ref" / "nees.json"));
  EXPECT_EQ(testing::RunsWithoutTimes(out / "runs.json"), testing::RunsWithoutTimes(dir_ / "ref" / "runs.json"));
  // Run 0 was not run again: its file, tracking time included, is the one the first call wrote.
  EXPECT_EQ(SlurpFile(out / "runs" / "000000.json"), kept);
  EXPECT_TRUE(fs::exists(out / "runs" / "000003.json"));
  const testing::CommandRun status = Roamlab("batch status resumed", dir_);
  EXPECT_EQ(status.exit_code, 0) << status.err;
  EXPECT_NE(status.out.find("4 runs: 4 done, 0 pending or running, 0 failed; state done"), std::string::npos)
      << status.out;
}

TEST_F(BatchLocalTest, MissingRunsAreReportedByStatus) {
  const fs::path out = CopyReference("partial");
  fs::remove(out / "runs" / "000002.json");
  const testing::CommandRun status = Roamlab("batch status partial", dir_);
  EXPECT_EQ(status.exit_code, 1);
  EXPECT_NE(status.out.find("3 done, 0 pending or running, 1 failed"), std::string::npos) << status.out;
  EXPECT_NE(status.out.find("failed: run 2 (seed 1002)"), std::string::npos) << status.out;
}

TEST_F(BatchLocalTest, DamagedResultFileIsNamed) {
  const fs::path out = CopyReference("damaged");
  testing::WriteFile((out / "runs" / "000002.json").string(), "{\"run\": 2, \"seed\": \"x\"");
  const testing::CommandRun r = Roamlab("montecarlo " + montecarlo_ + " --out damaged --resume", dir_);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("damaged/runs/000002.json: not the result file of run 2"), std::string::npos) << r.err;
}

TEST_F(BatchLocalTest, StatusOfADirectoryWithoutABatchIsBadInput) {
  const testing::CommandRun r = Roamlab("batch status nothing_here", dir_);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("nothing_here/batch/batch.json"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace roamlab
