// Outputs of `roamlab` under interruption and against its inputs: SIGINT stops `regress` between cases and SIGTERM
// stops `calibrate` within a second with exit 130 / 143, an INCOMPLETE marker that says what was done, and no partial
// or temporary file; `regress --resume` then gives the same results.json and junit.xml bytes as an uninterrupted run;
// an --out equal to or inside an input directory is refused.
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "recording/recording.h"
#include "recording/truth.h"
#include "tests/recording/temp_dir.h"
#include "tests/support/paths.h"
#include "tests/support/synthetic.h"

namespace roamlab {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using nlohmann::json;

constexpr int kCases = 6;

// A running `roamlab` with its standard output and error in files of `dir`.
pid_t Start(const std::vector<std::string>& args, const std::string& dir) {
  const pid_t pid = ::fork();
  if (pid != 0) return pid;
  const int out = ::open((dir + "/stdout.txt").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  const int err = ::open((dir + "/stderr.txt").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  ::dup2(out, STDOUT_FILENO);
  ::dup2(err, STDERR_FILENO);
  std::vector<char*> argv;
  const std::string binary = ROAMLAB_BINARY;
  argv.push_back(const_cast<char*>(binary.c_str()));
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  ::execv(binary.c_str(), argv.data());
  ::_exit(127);
}

// The exit code of `pid` (-1 when it did not exit within `timeout_s` or ended by a signal).
int Wait(pid_t pid, double timeout_s) {
  const auto deadline = Clock::now() + std::chrono::duration<double>(timeout_s);
  int status = 0;
  while (::waitpid(pid, &status, WNOHANG) == 0) {
    if (Clock::now() > deadline) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      return -1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// Waits until `path` exists; false after `timeout_s`.
bool WaitFor(const std::string& path, double timeout_s) {
  const auto deadline = Clock::now() + std::chrono::duration<double>(timeout_s);
  while (!fs::exists(path)) {
    if (Clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return true;
}

// Every file below `dir` whose name holds ".tmp-" (a temporary file of common/atomic_file.h).
std::vector<std::string> TemporaryFiles(const std::string& dir) {
  std::vector<std::string> found;
  for (const auto& entry : fs::recursive_directory_iterator(dir))
    if (entry.path().filename().string().find(".tmp-") != std::string::npos) found.push_back(entry.path().string());
  return found;
}

class InterruptCliTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new testing::TempDir();
    for (const auto& [name, duration_s] : {std::pair{"rec", 6.0}, std::pair{"long_rec", 60.0}}) {
      testing::SyntheticOptions options;
      options.duration_s = duration_s;
      const testing::SyntheticRecording synthetic = testing::MakeAtvRecording(options);
      ASSERT_TRUE(recording::WriteRecording(synthetic.recording, dir_->File(name)).ok());
      ASSERT_TRUE(recording::WriteTruth(synthetic.truth, dir_->File(name)).ok());
    }
    testing::WriteFile(dir_->File("cal.yaml"),
                       testing::ReadFile(roamlab::testing::SourceDir() + "/configs/atv_calibration.yaml"));
    std::string suite = "suite: interrupted\ncases:\n";
    for (int i = 0; i < kCases; ++i)
      suite += "  - name: case_" + std::to_string(i) +
               "\n    mode: calibrate\n    recording: rec\n    config: cal.yaml\n    checks:\n"
               "      - {metric: calibration.solver.iterations, bound: \">= 1\"}\n"
               "      - {metric: metrics.ate_m, bound: \"<= 5\"}\n";
    testing::WriteFile(dir_->File("suite.yaml"), suite);
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static std::string Path(const std::string& name) { return dir_->File(name); }

  static testing::TempDir* dir_;
};
testing::TempDir* InterruptCliTest::dir_ = nullptr;

TEST_F(InterruptCliTest, RegressStopsOnSigintAndResumesToTheSameBytes) {
  // The reference: one uninterrupted run.
  const std::string whole = Path("regress_whole");
  const int whole_code = Wait(Start({"regress", Path("suite.yaml"), "--out", whole, "--jobs", "1"}, dir_->path()), 600);
  ASSERT_TRUE(whole_code == 0 || whole_code == 1) << testing::ReadFile(Path("stderr.txt"));
  EXPECT_FALSE(fs::exists(whole + "/INCOMPLETE"));

  // An earlier run's report and a case not in the suite, both stale.
  const std::string out = Path("regress_cut");
  fs::create_directories(out + "/cases/old_case");
  testing::WriteFile(out + "/results.json", "{}\n");

  const pid_t pid = Start({"regress", Path("suite.yaml"), "--out", out, "--jobs", "1"}, dir_->path());
  ASSERT_TRUE(WaitFor(out + "/cases/case_0/case_result.json", 300));
  const auto signalled = Clock::now();
  ASSERT_EQ(::kill(pid, SIGINT), 0);
  EXPECT_EQ(Wait(pid, 30), 130) << testing::ReadFile(Path("stderr.txt"));
  const double stop_s = std::chrono::duration<double>(Clock::now() - signalled).count();
  EXPECT_LT(stop_s, 1.0);

  const json marker = json::parse(testing::ReadFile(out + "/INCOMPLETE"));
  EXPECT_EQ(marker["state"], "interrupted");
  EXPECT_EQ(marker["signal"], "SIGINT");
  ASSERT_GE(marker["done"].size(), 1u);
  ASSERT_LT(marker["done"].size(), static_cast<std::size_t>(kCases)) << "the run ended before the signal";
  EXPECT_EQ(marker["done"][0], "case case_0");
  EXPECT_NE(marker["command"].get<std::string>().find("regress"), std::string::npos);
  // Only finished cases are on disk, each with its record; no report, no stale file, no temporary file.
  for (const auto& entry : fs::directory_iterator(out + "/cases"))
    EXPECT_TRUE(fs::exists(entry.path() / "case_result.json")) << entry.path();
  EXPECT_EQ(static_cast<std::size_t>(std::distance(fs::directory_iterator(out + "/cases"), {})), marker["done"].size());
  EXPECT_FALSE(fs::exists(out + "/results.json"));
  EXPECT_FALSE(fs::exists(out + "/junit.xml"));
  EXPECT_TRUE(TemporaryFiles(out).empty());

  // --resume (two jobs: the scheduling does not matter): the rest runs, the reports are the uninterrupted run's bytes.
  const int resumed =
      Wait(Start({"regress", Path("suite.yaml"), "--out", out, "--jobs", "2", "--resume"}, dir_->path()), 600);
  EXPECT_EQ(resumed, whole_code) << testing::ReadFile(Path("stderr.txt"));
  EXPECT_NE(testing::ReadFile(Path("stderr.txt")).find("resumed"), std::string::npos);
  EXPECT_EQ(testing::ReadFile(out + "/results.json"), testing::ReadFile(whole + "/results.json"));
  EXPECT_EQ(testing::ReadFile(out + "/junit.xml"), testing::ReadFile(whole + "/junit.xml"));
  EXPECT_FALSE(fs::exists(out + "/INCOMPLETE"));
  EXPECT_TRUE(TemporaryFiles(out).empty());
}

TEST_F(InterruptCliTest, CalibrateStopsOnSigtermWithoutPartialFiles) {
  // An earlier run's result: removed when this run starts, so that the interrupted directory holds no result.
  const std::string out = Path("calibrate_cut");
  fs::create_directories(out);
  testing::WriteFile(out + "/calibration.json", "{}\n");
  const pid_t pid = Start({"calibrate", Path("long_rec"), "--config", Path("cal.yaml"), "--out", out}, dir_->path());
  ASSERT_TRUE(WaitFor(out + "/INCOMPLETE", 120));
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // into the solver
  const auto signalled = Clock::now();
  ASSERT_EQ(::kill(pid, SIGTERM), 0);
  EXPECT_EQ(Wait(pid, 30), 143) << testing::ReadFile(Path("stderr.txt"));
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - signalled).count(), 1.0);
  const json marker = json::parse(testing::ReadFile(out + "/INCOMPLETE"));
  EXPECT_EQ(marker["state"], "interrupted");
  EXPECT_EQ(marker["signal"], "SIGTERM");
  EXPECT_NE(marker["message"].get<std::string>().find("interrupted by SIGTERM"), std::string::npos) << marker.dump();
  EXPECT_FALSE(fs::exists(out + "/calibration.json"));
  EXPECT_FALSE(fs::exists(out + "/trajectory.tum"));
  EXPECT_TRUE(TemporaryFiles(out).empty());
  const std::string err = testing::ReadFile(Path("stderr.txt"));
  EXPECT_NE(err.find("roamlab calibrate: "), std::string::npos) << err;
  EXPECT_NE(err.find("interrupted by SIGTERM"), std::string::npos) << err;
}

TEST_F(InterruptCliTest, OutEqualToOrInsideAnInputIsRefused) {
  const std::string rec = Path("rec");
  const std::string calibrate = std::string(ROAMLAB_BINARY) + " calibrate " + rec + " --config " + Path("cal.yaml");
  for (const std::string& out : {rec, rec + "/", rec + "/calibration", rec + "/../rec/x"}) {
    const testing::CommandRun r = testing::RunCommand(calibrate + " --out " + out + " --quiet", dir_->path());
    EXPECT_EQ(r.exit_code, 2) << out << "\n" << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find("roamlab calibrate: --out " + out + " is"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("input directory " + rec), std::string::npos) << r.err;
  }
  EXPECT_FALSE(fs::exists(rec + "/calibration"));
  EXPECT_FALSE(fs::exists(rec + "/calibration.json"));

  // An output file equal to an input file; an import into the directory of its source file.
  testing::WriteFile(Path("log.csv"), "t,x\n0,1\n");
  testing::WriteFile(Path("map.yaml"), "files: []\n");
  const testing::CommandRun init = testing::RunCommand(
      std::string(ROAMLAB_BINARY) + " init " + rec + " --out " + rec + "/recording.yaml", dir_->path());
  EXPECT_EQ(init.exit_code, 2) << init.err;
  const testing::CommandRun import =
      testing::RunCommand(std::string(ROAMLAB_BINARY) + " import csv " + Path("log.csv") + " --map " +
                              Path("map.yaml") + " --out " + dir_->path(),
                          dir_->path());
  EXPECT_EQ(import.exit_code, 2) << import.err;
  EXPECT_NE(import.err.find("roamlab import: --out " + dir_->path() + " is the directory of the input file"),
            std::string::npos)
      << import.err;

  // Beside the configuration (in its directory) is fine.
  const testing::CommandRun beside =
      testing::RunCommand(calibrate + " --out " + Path("cal_out") + " --quiet", dir_->path());
  EXPECT_EQ(beside.exit_code, 0) << beside.err;
  EXPECT_TRUE(fs::exists(Path("cal_out/calibration.json")));
  EXPECT_FALSE(fs::exists(Path("cal_out/INCOMPLETE")));
}

}  // namespace
}  // namespace roamlab
