// `roamlab design`'s command line: malformed targets and options are refused with one line naming them, exit 2,
// before any drive is simulated.
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "tests/recording/temp_dir.h"
#include "tests/support/paths.h"

namespace roamlab {
namespace {

namespace fs = std::filesystem;

testing::CommandRun Design(const std::string& options, const fs::path& dir) {
  const std::string source = testing::SourceDir();
  return testing::RunCommand(std::string(ROAMLAB_BINARY) + " design " + source + "/scenarios/atv_hills.yaml --config " +
                                 source + "/configs/atv_calibration.yaml --out " + (dir / "d.yaml").string() + " " +
                                 options,
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

}  // namespace
}  // namespace roamlab
