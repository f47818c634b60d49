// Seed 001's configuration F1 end to end (label slow: two simulated drives of 150 s and 100 s with the laser scan
// matcher, about a minute): the taped-wheel differential drive of scenarios/deformed_f1_train.yaml, models learned from
// the scan matcher's displacements, evaluated on the other path of deformed_f1_test.yaml. The targets: the
// best learned model's ATE at most 1/5 of the nominal model's, and the linear-kernel CGP within 10 % of the robust
// linear model.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/recording/temp_dir.h"
#include "tests/support/paths.h"

namespace roamlab {
namespace {

namespace fs = std::filesystem;

testing::CommandRun Roamlab(const std::string& args, const fs::path& dir) {
  return testing::RunCommand(std::string(ROAMLAB_BINARY) + " " + args, dir.string());
}

TEST(DeformedOdometryTest, TapedWheelLearnedModelsBeatTheNominalModel) {
  testing::TempDir temp;
  const fs::path dir = temp.path();
  for (const std::string role : {"train", "test"}) {
    const testing::CommandRun r = Roamlab("simulate " + roamlab::testing::SourceDir() + "/scenarios/deformed_f1_" +
                                              role + ".yaml --out " + (dir / role).string() + " --quiet",
                                          dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  for (const std::string model : {"linear", "gp --mean zero --kernel linear"}) {
    const std::string file = (dir / (model == "linear" ? "linear.json" : "gp.json")).string();
    const testing::CommandRun r = Roamlab("odometry learn --recording " + (dir / "train").string() + " --model " +
                                              model + " --interval 0.3 --out " + file + " --quiet",
                                          dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  const testing::CommandRun r = Roamlab("odometry evaluate --model " + (dir / "linear.json").string() + " " +
                                            (dir / "gp.json").string() + " --recording " + (dir / "test").string() +
                                            " --out " + (dir / "eval").string() + " --no-plots --quiet",
                                        dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(dir / "eval" / "table.json");
  const nlohmann::json table = nlohmann::json::parse(in);
  ASSERT_EQ(table["rows"].size(), 3u);
  const double nominal = table["rows"][0]["ate_m"];
  const double linear = table["rows"][1]["ate_m"];
  const double gp_linear = table["rows"][2]["ate_m"];
  EXPECT_LE(std::min(linear, gp_linear), 0.2 * nominal) << "nominal " << nominal << " linear " << linear;
  EXPECT_LE(std::abs(gp_linear - linear), 0.1 * linear) << "gp (zero, linear) " << gp_linear << " linear " << linear;
}

}  // namespace
}  // namespace roamlab
