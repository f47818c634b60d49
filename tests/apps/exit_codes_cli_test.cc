// Every command of `roamlab` with a bad input (a file, an option, a configuration, a scenario): exit code 2 and one
// line on stderr that names the file.
#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "recording/recording.h"
#include "tests/recording/temp_dir.h"
#include "tests/support/paths.h"
#include "tests/support/synthetic.h"

namespace roamlab {
namespace {

namespace fs = std::filesystem;

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  return pos == std::string::npos ? text : text.replace(pos, from.size(), to);
}

// The lines of `err` that are not warnings or progress.
std::vector<std::string> ErrorLines(const std::string& err) {
  std::vector<std::string> lines;
  std::size_t begin = 0;
  while (begin < err.size()) {
    const std::size_t end = std::min(err.find('\n', begin), err.size());
    const std::string line = err.substr(begin, end - begin);
    if (!line.empty() && line.find(": warning: ") == std::string::npos && line.rfind("roamlab", 0) == 0)
      lines.push_back(line);
    begin = end + 1;
  }
  return lines;
}

class ExitCodesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    testing::SyntheticOptions options;
    options.duration_s = 3.0;
    ASSERT_TRUE(recording::WriteRecording(testing::MakeAtvRecording(options).recording, rec_).ok());
    testing::WriteFile(file_, "a regular file\n");
    config_ = testing::ReadFile(roamlab::testing::SourceDir() + "/configs/atv_calibration.yaml");
  }
  // Writes `text` as dir/name and returns the path.
  std::string Write(const std::string& name, const std::string& text) {
    const std::string path = (dir_ / name).string();
    testing::WriteFile(path, text);
    return path;
  }
  // Runs `roamlab args` and expects exit 2 and a single error line that names `file`.
  void ExpectBadInput(const std::string& args, const std::string& file) {
    const testing::CommandRun r =
        testing::RunCommand(std::string(ROAMLAB_BINARY) + " " + args + " --quiet", dir_.string());
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    const std::vector<std::string> lines = ErrorLines(r.err);
    ASSERT_EQ(lines.size(), 1u) << args << "\n" << r.err;
    EXPECT_NE(lines[0].find(file), std::string::npos) << args << ": " << lines[0] << " does not name " << file;
  }

  testing::TempDir temp_;
  fs::path dir_{temp_.path()};
  std::string rec_ = (dir_ / "rec").string();
  std::string file_ = (dir_ / "regular_file").string();
  std::string out_ = (dir_ / "out").string();
  std::string config_;
};

// Configuration errors found against the recording (they used to exit 1 as run-time failures).
TEST_F(ExitCodesTest, ConfigurationErrorsAgainstTheRecordingAreBadInput) {
  const std::string wrong_size =
      Write("size.yaml", Replace(config_, "gps.lever_arm: {value: [0, 0, 0]", "gps.lever_arm: {value: [0, 0, 0, 0]"));
  ExpectBadInput("calibrate " + rec_ + " --config " + wrong_size + " --out " + out_, "size.yaml");
  const std::string unused =
      Write("unused.yaml", Replace(config_, "parameters:\n", "parameters:\n  wheel.nothing: {value: 1.0}\n"));
  ExpectBadInput("calibrate " + rec_ + " --config " + unused + " --out " + out_, "unused.yaml");
  const std::string stage =
      Write("stage.yaml", Replace(config_, "stages:\n", "stages:\n  - [odometer.cornering_rear]\n"));
  ExpectBadInput("calibrate " + rec_ + " --config " + stage + " --out " + out_, "stage.yaml");
  const std::string typo =
      Write("typo.yaml", Replace(config_, "{misalignment: imu.misalignment}", "{misalignment: imu.misalignmnet}"));
  ExpectBadInput("calibrate " + rec_ + " --config " + typo + " --out " + out_, "typo.yaml");
  const std::string tiny = Write("tiny.yaml", Replace(config_, "sigma_m: ", "sigma_m: 1e-300 #"));
  ExpectBadInput("track " + rec_ + " --config " + tiny + " --out " + out_, "tiny.yaml");
}

// A stream that does not overlap the master is refused with the stream's file.
TEST_F(ExitCodesTest, StreamOutsideTheMastersSpanIsBadInput) {
  std::string gps = testing::ReadFile(rec_ + "/gps.csv");
  std::string shifted = gps.substr(0, gps.find('\n') + 1);
  for (std::size_t begin = shifted.size(); begin < gps.size();) {
    const std::size_t comma = gps.find(',', begin);
    const std::size_t end = gps.find('\n', begin);
    const std::string t = FormatSeconds(Time::FromSeconds(std::stod(gps.substr(begin, comma - begin)) + 1000.0));
    shifted += t + gps.substr(comma, end + 1 - comma);
    begin = end + 1;
  }
  testing::WriteFile(rec_ + "/gps.csv", shifted);
  const std::string config = Write("est.yaml", config_);
  ExpectBadInput("calibrate " + rec_ + " --config " + config + " --out " + out_, "gps.csv");
}

// Every command with a missing or malformed input file, and an output under a regular file.
TEST_F(ExitCodesTest, EveryCommandRefusesABadInputWithCodeTwo) {
  const std::string missing = (dir_ / "missing.yaml").string();
  const std::string dup = Write("dup.yaml", "name: a\nname: b\n");
  const std::string config = Write("est.yaml", config_);
  const std::string scenario = roamlab::testing::SourceDir() + "/scenarios/indoor_diffdrive_slip.yaml";
  ExpectBadInput("simulate " + dup + " --out " + out_, "dup.yaml");
  ExpectBadInput("simulate " + scenario + " --out " + file_ + "/sub", "regular_file");
  ExpectBadInput("calibrate " + rec_ + " --config " + missing + " --out " + out_, "missing.yaml");
  ExpectBadInput("calibrate " + rec_ + " --config " + config + " --out " + file_ + "/sub", "regular_file");
  ExpectBadInput("track " + rec_ + " --config " + dup + " --out " + out_, "dup.yaml");
  ExpectBadInput("evaluate --estimate " + (dir_ / "none").string() + " --recording " + rec_ + " --out " + out_, "none");
  ExpectBadInput("montecarlo " + missing + " --config " + config + " --out " + out_, "missing.yaml");
  ExpectBadInput("init " + (dir_ / "norec").string() + " --out " + out_ + ".yaml", "norec");
  ExpectBadInput(
      "diagnose --real " + (dir_ / "norec").string() + " --config " + config + " --no-baseline --out " + out_, "norec");
  ExpectBadInput("gap-benchmark --atv " + missing + " --cases 1 --calibration-cases 1 --out " + out_, "missing.yaml");
  ExpectBadInput("regress " + dup + " --out " + out_, "dup.yaml");
  ExpectBadInput("odometry learn --recording " + (dir_ / "norec").string() + " --out " + out_ + ".json", "norec");
  ExpectBadInput("odometry evaluate --model " + missing + " --recording " + rec_ + " --out " + out_, "missing.yaml");
  const std::string run = Write("set_run-01.csv", "0,0,0,0,0,0\n0.05,0,0,0,1,0.1\n");
  const std::string metadata =
      Write("set_metadata.csv", "type,tricyc\nngear,1\nencRes,1600\nLi,0.15\nDi,0.065\nThi,0\nDi,0.07\n");
  ExpectBadInput("import optiodom " + run + " --metadata " + metadata + " --out " + out_, "set_metadata.csv");
  const std::string good_metadata =
      Write("good_metadata.csv", "type,tricyc\nngear,1\nencRes,1600\nLi,0.15\nDi,0.065\nThi,0\n");
  ExpectBadInput("import optiodom " + run + " --metadata " + good_metadata + " --out " + file_ + "/sub",
                 "regular_file");
  ExpectBadInput("import rosbag " + (dir_ / "missing.bag").string() + " --out " + out_, "missing.bag");
  ExpectBadInput("import csv " + file_ + " --map " + dup + " --out " + out_, "dup.yaml");
  ExpectBadInput("frontend vo " + (dir_ / "norec").string() + " --out " + out_, "norec");
}

}  // namespace
}  // namespace roamlab
