// The runner of an external estimator under test (experiment/external.h): the command line it builds, the input it
// hands over (no truth), and each way the program under test can fail, reported as one line naming the command and
// the file.
#include "experiment/external.h"

#include <chrono>
#include <filesystem>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "common/interrupt.h"
#include "tests/recording/temp_dir.h"

namespace roamlab::experiment {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

constexpr char kTwoPoses[] =
    "# t x y z qx qy qz qw\n"
    "0.000000000 0 0 0 0 0 0 1\n"
    "0.010000000 0.01 0 0 0 0 0 1\n";

// A command that writes `trajectory` (and `covariance` when not empty) into {out}, through files of `dir`.
ExternalCommand Writer(const testing::TempDir& dir, const std::string& trajectory, const std::string& covariance = "") {
  testing::WriteFile(dir.File("trajectory.in"), trajectory);
  std::string line = "cp trajectory.in {out}/trajectory.tum";
  if (!covariance.empty()) {
    testing::WriteFile(dir.File("covariance.in"), covariance);
    line += " && cp covariance.in {out}/covariance.csv";
  }
  return {line, dir.path(), 10.0};
}

// Runs the command on an empty recording directory into DIR/out, then reads what it wrote.
Result<ExternalEstimate> RunAndRead(const testing::TempDir& dir, const ExternalCommand& command) {
  fs::create_directories(dir.File("rec"));
  const Status ran = RunExternalCommand(command, dir.File("rec"), dir.File("out"), dir.File("estimator.log"));
  if (!ran.ok()) return ran;
  return ReadExternalEstimate(dir.File("out"));
}

TEST(ExternalTest, ExpandsQuotedAbsolutePathsOrAppendsThem) {
  const std::string cwd = fs::current_path().string();
  EXPECT_EQ(ExpandCommand("prog --in {recording} -o {out}/x", "/a b/rec", "/o'ut"),
            "prog --in '/a b/rec' -o '/o'\\''ut'/x");
  EXPECT_EQ(ExpandCommand("prog", "rec", "/out"), "prog '" + cwd + "/rec' '/out'");
}

TEST(ExternalTest, SuccessReadsTrajectoryAndCovariance) {
  testing::TempDir dir;
  const auto read = RunAndRead(dir, Writer(dir, kTwoPoses,
                                           "t,xx,xy,xz,yx,yy,yz,zx,zy,zz\n"
                                           "0.000000000,1,0,0,0,2,0,0,0,3\n"
                                           "0.010000000,4,0,0,0,5,0,0,0,6\n"));
  ASSERT_TRUE(read.ok()) << read.status().message();
  ASSERT_EQ(read.value().trajectory.size(), 2u);
  EXPECT_DOUBLE_EQ(read.value().trajectory[1].p_world_body.x(), 0.01);
  ASSERT_TRUE(read.value().position_covariance_world.has_value());
  EXPECT_DOUBLE_EQ((*read.value().position_covariance_world)[1](2, 2), 6.0);
}

TEST(ExternalTest, WithoutCovarianceTheEstimateHasNone) {
  testing::TempDir dir;
  const auto read = RunAndRead(dir, Writer(dir, kTwoPoses));
  ASSERT_TRUE(read.ok()) << read.status().message();
  EXPECT_FALSE(read.value().position_covariance_world.has_value());
}

TEST(ExternalTest, RunsInItsWorkingDirectoryWithTheRecordingAndItsOutput) {
  testing::TempDir dir;
  fs::create_directories(dir.File("rec"));
  testing::WriteFile(dir.File("rec/recording.yaml"), "format_version: 1\n");
  testing::WriteFile(dir.File("script.sh"), "test -f \"$1/recording.yaml\" && pwd > \"$2/where\"\n");
  const Status ran =
      RunExternalCommand({"sh script.sh", dir.path(), 10.0}, dir.File("rec"), dir.File("out"), dir.File("log"));
  ASSERT_TRUE(ran.ok()) << ran.message();
  EXPECT_EQ(testing::ReadFile(dir.File("out/where")), fs::canonical(dir.path()).string() + "\n");
}

TEST(ExternalTest, NonZeroExitNamesTheCommandStatusAndLog) {
  testing::TempDir dir;
  const Status ran = RunExternalCommand({"echo cannot read the encoders >&2; exit 3", dir.path(), 10.0}, dir.path(),
                                        dir.File("out"), dir.File("estimator.log"));
  ASSERT_FALSE(ran.ok());
  EXPECT_THAT(ran.message(), HasSubstr("estimator command 'echo cannot read the encoders >&2; exit 3'"));
  EXPECT_THAT(ran.message(), HasSubstr("exited with status 3"));
  EXPECT_THAT(ran.message(), HasSubstr(dir.File("estimator.log") + ": cannot read the encoders"));
}

TEST(ExternalTest, AProgramThatDoesNotExistIsAFailureNotACrash) {
  testing::TempDir dir;
  const Status ran = RunExternalCommand({"./no_such_program {recording} {out}", dir.path(), 10.0}, dir.path(),
                                        dir.File("out"), dir.File("estimator.log"));
  ASSERT_FALSE(ran.ok());
  EXPECT_THAT(ran.message(), HasSubstr("status 127 (command not found)"));
}

TEST(ExternalTest, MissingTrajectoryNamesTheFile) {
  testing::TempDir dir;
  const auto read = RunAndRead(dir, {"true", dir.path(), 10.0});
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().message(), dir.File("out") + "/trajectory.tum: missing: the estimator wrote no trajectory");
}

TEST(ExternalTest, MalformedTumLineNamesFileAndLine) {
  testing::TempDir dir;
  const auto read = RunAndRead(dir, Writer(dir, "0.0 0 0 0 0 0 0 1\n0.01 0 0 zero 0 0 0 1\n"));
  ASSERT_FALSE(read.ok());
  EXPECT_THAT(read.status().message(), HasSubstr(dir.File("out") + "/trajectory.tum:2"));
}

TEST(ExternalTest, CovarianceRowsMustPairWithThePoses) {
  testing::TempDir dir;
  const std::string header = "t,xx,xy,xz,yx,yy,yz,zx,zy,zz\n";
  const auto fewer = RunAndRead(dir, Writer(dir, kTwoPoses, header + "0.000000000,1,0,0,0,1,0,0,0,1\n"));
  ASSERT_FALSE(fewer.ok());
  EXPECT_THAT(fewer.status().message(), HasSubstr("covariance.csv: 1 rows for 2 poses"));
  const auto shifted = RunAndRead(
      dir, Writer(dir, kTwoPoses, header + "0.000000000,1,0,0,0,1,0,0,0,1\n0.020000000,1,0,0,0,1,0,0,0,1\n"));
  ASSERT_FALSE(shifted.ok());
  EXPECT_THAT(shifted.status().message(), HasSubstr("covariance.csv:3: stamp 0.020000000 is not the stamp of pose 2"));
}

// The time-out ends the command and what it started (its process group) and says so.
TEST(ExternalTest, TimeOutKillsTheCommand) {
  testing::TempDir dir;
  const auto start = std::chrono::steady_clock::now();
  const Status ran = RunExternalCommand({"sleep 30 & sleep 30; touch {out}/late", dir.path(), 0.3}, dir.path(),
                                        dir.File("out"), dir.File("estimator.log"));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_FALSE(ran.ok());
  EXPECT_THAT(ran.message(), HasSubstr("killed after the time-out of 0.3 s"));
  EXPECT_LT(seconds, 5.0);
  EXPECT_FALSE(fs::exists(dir.File("out/late")));
}

// What the command leaves running when it exits (a background job in its process group) is killed with it.
TEST(ExternalTest, WhatTheCommandLeftRunningIsKilled) {
  testing::TempDir dir;
  const Status ran = RunExternalCommand({"sleep 30 & echo $! > {out}/pid", dir.path(), 10.0}, dir.path(),
                                        dir.File("out"), dir.File("estimator.log"));
  ASSERT_TRUE(ran.ok()) << ran.message();
  const std::string pid = testing::ReadFile(dir.File("out/pid"));
  ASSERT_FALSE(pid.empty());
  // Gone, or a zombie waiting for its new parent to reap it: state Z in /proc/PID/stat.
  bool ended = false;
  for (int k = 0; k < 100 && !ended; ++k) {
    const std::string stat = testing::ReadFile("/proc/" + pid.substr(0, pid.find('\n')) + "/stat");
    const std::size_t close = stat.rfind(')');
    ended = stat.empty() || (close != std::string::npos && stat.compare(close + 2, 1, "Z") == 0);
    if (!ended) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_TRUE(ended) << "pid " << pid;
}

// The command names {out}, so that no paths are appended to sleep's arguments (which would end it at once).
TEST(ExternalTest, AnInterruptStopsTheCommand) {
  testing::TempDir dir;
  RequestInterrupt(2);
  const Status ran =
      RunExternalCommand({"sleep 30 && test -d {out}", dir.path(), 60.0}, dir.path(), dir.File("out"),
                         dir.File("estimator.log"));
  ClearInterrupt();
  ASSERT_FALSE(ran.ok());
  EXPECT_THAT(ran.message(), HasSubstr("interrupted by SIGINT"));
}

TEST(ExternalTest, InvalidCommandIsRefused) {
  EXPECT_EQ((ExternalCommand{" ", "", 1.0}.Validate()), "the estimator command is empty");
  EXPECT_THAT((ExternalCommand{"true", "", 0.0}.Validate()), HasSubstr("timeout_s must be positive"));
  EXPECT_THAT((ExternalCommand{"true", "/no/such/dir", 1.0}.Validate()), HasSubstr("/no/such/dir: not a directory"));
}

// The estimator's input holds the recording's files but never its truth.
TEST(ExternalTest, InputLeavesTheTruthOut) {
  testing::TempDir dir;
  fs::create_directories(dir.File("rec"));
  for (const char* name : {"recording.yaml", "imu.csv", "ground_truth.tum", "truth.yaml"})
    testing::WriteFile(dir.File(std::string("rec/") + name), name);
  ASSERT_TRUE(MakeEstimatorInput(dir.File("rec"), dir.File("input")).ok());
  EXPECT_EQ(testing::ReadFile(dir.File("input/imu.csv")), "imu.csv");
  EXPECT_TRUE(fs::exists(dir.File("input/recording.yaml")));
  EXPECT_FALSE(fs::exists(dir.File("input/ground_truth.tum")));
  EXPECT_FALSE(fs::exists(dir.File("input/truth.yaml")));
}

}  // namespace
}  // namespace roamlab::experiment
