// `roamlab design`'s command line: malformed targets and options are refused with one line naming them, exit 2,
// before any drive is simulated.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "tests/experiment/design_testing.h"
#include "tests/recording/temp_dir.h"
#include "tests/support/paths.h"

namespace roamlab {
namespace {

namespace fs = std::filesystem;

testing::CommandRun Design(const std::string& options, const fs::path& dir,
                           const std::string& config = testing::SourceDir() + "/configs/atv_calibration.yaml") {
  const std::string source = testing::SourceDir();
  return testing::RunCommand(std::string(ROAMLAB_BINARY) + " design " + source + "/scenarios/atv_hills.yaml --config " +
                                 config + " --out " + (dir / "d.yaml").string() + " " + options,
                             dir.string());
}

TEST(DesignCliTest, BadTargetsAndOptionsExitTwoNamingTheProblem) {
  testing::TempDir dir;
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--target odometer.k_theta", "--target 'odometer.k_theta': expected NAME=STD"},
      {"--target odometer.k_theta=abc", "'abc' is not a number"},
      {"--target odometer.k_theta=0.01 --target odometer.k_theta=0.02", "odometer.k_theta given twice"},
      {"--target gps.nonsense=0.1", "--target gps.nonsense: not a free parameter of"},
      {"--target odometer.cornering_rear=0.1", "--target odometer.cornering_rear: not a free parameter of"},
      {"--target odometer.k_theta=-1", "--target odometer.k_theta: must be > 0"},
      {"--target odometer.k_theta=0.01 --speed-range 4 2", "--speed-range: need min < max"},
      {"--target odometer.k_theta=0.01 --speed-range -1 2", "--speed-range: an ackermann drive needs 0 < min"},
      {"--target odometer.k_theta=0.01 --max-lateral-speed 0.2", "--max-lateral-speed: a robot of kind ackermann"},
      {"--target odometer.k_theta=0.01 --budget 0", "--budget: must be >= 1"},
      {"--target odometer.k_theta=0.01 --duration -5", "--duration"},
  };
  for (const auto& [options, message] : cases) {
    const testing::CommandRun run = Design(options, fs::path(dir.path()));
    EXPECT_EQ(run.exit_code, 2) << options << ": " << run.err;
    EXPECT_NE(run.err.find(message), std::string::npos) << options << ": " << run.err;
    EXPECT_FALSE(fs::exists(dir.File("d.yaml"))) << options;
  }
}

// Without --target the configuration's target_std entries are the targets: none there is bad input, and so is a
// malformed one, named with the configuration's file and line.
TEST(DesignCliTest, TargetsFromTheConfigurationAreCheckedToo) {
  testing::TempDir dir;
  const std::string untargeted = testing::ConfigWithoutTargets("atv_calibration.yaml", dir);
  testing::CommandRun run = Design("", fs::path(dir.path()), untargeted);
  EXPECT_EQ(run.exit_code, 2) << run.err;
  EXPECT_NE(run.err.find("no target given, and no parameter of " + untargeted + " has a target_std"), std::string::npos)
      << run.err;

  std::ifstream in(untargeted);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string k_theta = "odometer.k_theta: {value: 1.0, free: true";
  const std::size_t at = text.find(k_theta);
  ASSERT_NE(at, std::string::npos);
  text.insert(at + k_theta.size(), ", target_std: 0");
  const std::string line =
      std::to_string(1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
  testing::WriteFile(dir.File("zero.yaml"), text);
  run = Design("", fs::path(dir.path()), dir.File("zero.yaml"));
  EXPECT_EQ(run.exit_code, 2) << run.err;
  EXPECT_NE(run.err.find(dir.File("zero.yaml") + ":" + line + ": parameters.odometer.k_theta.target_std: 0 is outside"),
            std::string::npos)
      << run.err;
  EXPECT_FALSE(fs::exists(dir.File("d.yaml")));
}

}  // namespace
}  // namespace roamlab
