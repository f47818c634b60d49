// The Slurm backend on a running cluster (scripts/local-slurm.sh start, SLURM_CONF exported; ctest label "slurm"):
// an 8-run ATV Monte-Carlo (a 4 s drive) through Slurm gives the local backend's nees.json byte for byte; a task killed
// midway is submitted again by the aggregation job; --resume after a cancelled array submits only the missing runs and
// ends with the same bytes; a sweep through Slurm gives the local table; a small gap benchmark through Slurm (the
// calibration cases' array, then the scored cases') gives the local score.json, also after --resume.
#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

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
using testing::RunCommand;
using testing::SlurpFile;

// The drive [s] of the gap benchmark's cases: long enough for the diagnosis's held-out part, short enough for the
// suite's time.
constexpr char kGapDuration[] = "10";

class SlurmTest : public ::testing::Test {
 protected:
  // The cluster answers, and the local backend's 8-run Monte-Carlo of a 4 s drive is the reference.
  static void SetUpTestSuite() {
    temp_ = new testing::TempDir;
    const fs::path dir = temp_->path();
    const testing::CommandRun sinfo = RunCommand("sinfo -h -o %t", dir.string());
    ASSERT_EQ(sinfo.exit_code, 0) << "no Slurm cluster answers (start one with `bash scripts/local-slurm.sh start` "
                                     "and export SLURM_CONF, or leave these tests out with ctest -LE slurm): "
                                  << sinfo.err;
    const std::string scenario = testing::WriteShortAtvScenario(dir, "4.0");
    ASSERT_FALSE(scenario.empty());
    montecarlo_ = scenario + " --config " + roamlab::testing::SourceDir() +
                  "/configs/atv_tracking.yaml --runs 8 --t0 1 --no-time-budget --quiet";
    const testing::CommandRun r = Roamlab("montecarlo " + montecarlo_ + " --jobs 2 --out local", dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  static void TearDownTestSuite() { delete temp_; }
  void SetUp() override {
    if (!fs::exists(dir_ / "local" / "nees.json")) GTEST_FAIL() << "no cluster or the local reference run failed";
  }

  // OUT with the reference's shared calibration, so that `--resume` runs every run without calibrating again.
  fs::path WithCalibration(const std::string& name) {
    const fs::path out = dir_ / name;
    fs::create_directories(out);
    fs::copy(dir_ / "local" / "calibration", out / "calibration", fs::copy_options::recursive);
    return out;
  }
  std::string Slurm(const std::string& out, const std::string& more) {
    return "montecarlo " + montecarlo_ + " --out " + out + " --backend slurm " + more;
  }
  // Polls `squeue` until the array task is running (at most a minute).
  bool WaitUntilRunning(const std::string& task) {
    for (int k = 0; k < 600; ++k) {
      if (RunCommand("squeue -h -j " + task + " -o %T", dir_.string()).out.find("RUNNING") != std::string::npos)
        return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return false;
  }
  // Polls OUT/batch/batch.json until its state is no longer "submitted" (at most three minutes); its content.
  nlohmann::json WaitForEnd(const fs::path& out) {
    nlohmann::json batch;
    for (int k = 0; k < 1800; ++k) {
      batch = ReadJson(out / "batch" / "batch.json");
      if (batch.is_object() && batch["state"] != "submitted") break;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return batch;
  }
  void ExpectSameSummary(const fs::path& out) {
    EXPECT_EQ(SlurpFile(out / "nees.json"), SlurpFile(dir_ / "local" / "nees.json"));
    EXPECT_EQ(testing::RunsWithoutTimes(out / "runs.json"), testing::RunsWithoutTimes(dir_ / "local" / "runs.json"));
  }

  static testing::TempDir* temp_;
  static std::string montecarlo_;
  fs::path dir_{temp_->path()};
};
testing::TempDir* SlurmTest::temp_ = nullptr;
std::string SlurmTest::montecarlo_;

TEST_F(SlurmTest, ArrayGivesTheLocalBytes) {
  const testing::CommandRun r = Roamlab(Slurm("slurm", "--wait --array-parallelism 2"), dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("submitted 8 runs as array job"), std::string::npos) << r.err;
  ExpectSameSummary(dir_ / "slurm");
  if (fs::exists(dir_ / "local" / "nees.png")) {
    EXPECT_EQ(SlurpFile(dir_ / "slurm" / "nees.png"), SlurpFile(dir_ / "local" / "nees.png"));
  }
  const nlohmann::json batch = ReadJson(dir_ / "slurm" / "batch" / "batch.json");
  EXPECT_EQ(batch["state"], "done");
  EXPECT_EQ(batch["submissions"].size(), 1u) << "one sbatch array, no retry";
  EXPECT_EQ(batch["submissions"][0]["blocks"].size(), 8u);
  const testing::CommandRun status = Roamlab("batch status slurm", dir_);
  EXPECT_EQ(status.exit_code, 0);
  EXPECT_NE(status.out.find("8 runs: 8 done, 0 pending or running, 0 failed; state done"), std::string::npos)
      << status.out;
}

TEST_F(SlurmTest, KilledTaskIsSubmittedAgain) {
  WithCalibration("killed");
  const testing::CommandRun r = Roamlab(Slurm("killed", "--resume --runs-per-task 4"), dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string job = ReadJson(dir_ / "killed" / "batch" / "batch.json")["submissions"][0]["array_job"];
  ASSERT_TRUE(WaitUntilRunning(job + "_0"));
  // Task 0 runs runs 0-3 (a few seconds); killed within its first second, it leaves them without a result.
  ASSERT_EQ(RunCommand("scancel --signal=KILL --full " + job + "_0", dir_.string()).exit_code, 0);
  // The aggregation job finds runs 0-3 missing and submits their block again.
  const nlohmann::json batch = WaitForEnd(dir_ / "killed");
  ASSERT_EQ(batch["state"], "done") << batch.dump();
  ASSERT_EQ(batch["submissions"].size(), 2u);
  EXPECT_EQ(batch["submissions"][1]["blocks"], nlohmann::json::array({0}));
  ExpectSameSummary(dir_ / "killed");
}

TEST_F(SlurmTest, ResumeAfterCancelSubmitsOnlyTheMissingRuns) {
  const fs::path out = WithCalibration("cancelled");
  const testing::CommandRun r = Roamlab(Slurm("cancelled", "--resume --array-parallelism 1"), dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json first = ReadJson(out / "batch" / "batch.json")["submissions"][0];
  const std::string array = first["array_job"], aggregate = first["aggregate_job"];
  // One task at a time: cancel the array and its aggregation job once two runs have their result.
  for (int k = 0; k < 600 && !fs::exists(out / "runs" / "000001.json"); ++k)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  ASSERT_EQ(RunCommand("scancel " + array + " " + aggregate, dir_.string()).exit_code, 0);
  std::this_thread::sleep_for(std::chrono::seconds(1));
  int done = 0;
  for (int i = 0; i < 8; ++i) done += fs::exists(out / "runs" / ("00000" + std::to_string(i) + ".json"));
  ASSERT_GE(done, 2);
  ASSERT_LT(done, 8) << "the array finished before it was cancelled";
  EXPECT_FALSE(fs::exists(out / "nees.json"));
  const std::string run0 = SlurpFile(out / "runs" / "000000.json");

  const testing::CommandRun resumed = Roamlab(Slurm("cancelled", "--resume --wait"), dir_);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_NE(resumed.err.find("submitted " + std::to_string(8 - done) + " runs"), std::string::npos) << resumed.err;
  EXPECT_EQ(SlurpFile(out / "runs" / "000000.json"), run0) << "run 0 was run again";
  ExpectSameSummary(out);
}

TEST_F(SlurmTest, SweepGivesTheLocalTable) {
  const std::string scenario = testing::WriteShortAtvScenario(dir_, "4.0");
  ASSERT_FALSE(scenario.empty());
  std::ofstream(dir_ / "sweep.yaml") << "scenario: " << scenario << "\nconfig: " << roamlab::testing::SourceDir()
                                     << "/configs/atv_tracking.yaml\nseeds: 2\nt0_s: 1\nno_time_budget: true\n"
                                     << "grid:\n  config.tracking.window: [20, 40]\n";
  const testing::CommandRun local = Roamlab("sweep sweep.yaml --out sweep_local --jobs 2 --quiet", dir_);
  ASSERT_EQ(local.exit_code, 0) << local.err;
  const testing::CommandRun slurm =
      Roamlab("sweep sweep.yaml --out sweep_slurm --backend slurm --runs-per-task 2 --wait --quiet", dir_);
  ASSERT_EQ(slurm.exit_code, 0) << slurm.err;
  for (const char* point : {"000", "001"}) {
    const fs::path nees = fs::path("points") / point / "nees.json";
    EXPECT_EQ(SlurpFile(dir_ / "sweep_slurm" / nees), SlurpFile(dir_ / "sweep_local" / nees)) << point;
  }
  // The table but for the tracking times.
  nlohmann::json a = ReadJson(dir_ / "sweep_local" / "sweep.json"), b = ReadJson(dir_ / "sweep_slurm" / "sweep.json");
  ASSERT_EQ(a["points"].size(), 2u);
  for (nlohmann::json* sweep : {&a, &b})
    for (nlohmann::json& point : (*sweep)["points"]) point.erase("track_seconds");
  EXPECT_EQ(a, b);
}

// Two calibration and two scored cases of short drives, two cases a task: one array for the calibration cases, then
// one for the scored cases (their thresholds are chosen on the calibration cases), submitted by the first aggregation
// job; score.json is the local backend's byte for byte. Then a scored case's result is removed and --resume runs only
// its task, leaves the other cases' files untouched and writes the same score.json again.
TEST_F(SlurmTest, GapBenchmarkGivesTheLocalScore) {
  const std::string scenarios = roamlab::testing::SourceDir() + "/scenarios/";
  // --other-drive 0: no case replays its drive (the batch's mechanics do not depend on it; replays are slow).
  const std::string benchmark = "gap-benchmark --cases 2 --calibration-cases 2 --seed 3 --other-drive 0 --duration " +
                                std::string(kGapDuration) + " --quiet --atv " + scenarios + "atv_hills_sines.yaml" +
                                " --diffdrive " + scenarios + "indoor_diffdrive_gap.yaml --mecanum " + scenarios +
                                "indoor_mecanum_gap.yaml";
  const testing::CommandRun local = Roamlab(benchmark + " --jobs 2 --out gap_local", dir_);
  ASSERT_EQ(local.exit_code, 0) << local.err;
  const testing::CommandRun slurm =
      Roamlab(benchmark + " --out gap_slurm --backend slurm --runs-per-task 2 --wait", dir_);
  ASSERT_EQ(slurm.exit_code, 0) << slurm.err;
  const fs::path out = dir_ / "gap_slurm";
  const std::string score = SlurpFile(dir_ / "gap_local" / "score.json");
  ASSERT_FALSE(score.empty());
  EXPECT_EQ(SlurpFile(out / "score.json"), score);
  const nlohmann::json submissions = ReadJson(out / "batch" / "batch.json")["submissions"];
  ASSERT_EQ(submissions.size(), 2u) << submissions.dump();
  EXPECT_EQ(submissions[0]["blocks"], nlohmann::json::array({0}));
  EXPECT_EQ(submissions[0]["ready"], 2);
  EXPECT_EQ(submissions[1]["blocks"], nlohmann::json::array({1}));
  EXPECT_EQ(submissions[1]["ready"], 4);

  const std::string calibration0 = SlurpFile(out / "calibration" / "000" / "case.json");
  fs::remove(out / "cases" / "001" / "case.json");
  fs::remove(out / "score.json");
  const testing::CommandRun resumed =
      Roamlab(benchmark + " --out gap_slurm --backend slurm --runs-per-task 2 --resume --wait", dir_);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_NE(resumed.err.find("submitted 1 runs as array job"), std::string::npos) << resumed.err;
  EXPECT_EQ(SlurpFile(out / "calibration" / "000" / "case.json"), calibration0) << "calibration case 0 ran again";
  EXPECT_EQ(SlurpFile(out / "score.json"), score);
  const testing::CommandRun status = Roamlab("batch status gap_slurm", dir_);
  EXPECT_NE(status.out.find("4 runs: 4 done, 0 pending or running, 0 failed; state done"), std::string::npos)
      << status.out;
}

}  // namespace
}  // namespace roamlab
