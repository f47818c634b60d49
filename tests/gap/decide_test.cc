// The diagnosis's share rule (gap/diagnose.h: HeldoutExcess, ExplainedShare) on made-up held-out statistics: a
// candidate that removes the mismatch explains most of it; one that leaves another stream's large excess in place (an
// out-of-library effect pulling a library parameter) explains little.
#include "gap/diagnose.h"

#include <gtest/gtest.h>

namespace roamlab::gap {
namespace {

TEST(DecisionTest, HeldoutExcessSumsTheChiSquareAboveTheNominalLevel) {
  const std::map<std::string, ComponentLevel> components = {
      {"gyroscope/2", {3.0, 1000}},      // 2000 above a level of 1
      {"accelerometer/1", {1.2, 1000}},  // 200 above a level of 1 (missing from `expected`)
      {"gps/0", {0.5, 100}},             // below its level 0.8: adds nothing
      {"odometer/0", {10.0, 1000}}};     // not located: not counted
  const std::map<std::string, double> expected = {{"gyroscope/2", 1.0}, {"gps/0", 0.8}};
  const std::vector<std::string> keys = {"gyroscope/2", "accelerometer/1", "gps/0", "wheels/0"};
  EXPECT_NEAR(HeldoutExcess(components, keys, expected), 2200.0, 1e-9);
  EXPECT_DOUBLE_EQ(HeldoutExcess(components, {}, expected), 0.0);
}

TEST(DecisionTest, ExplainedShareTellsAnEffectFromADecoysPull) {
  const std::map<std::string, double> expected = {{"gyroscope/2", 1.0}, {"accelerometer/0", 1.0}};
  const std::vector<std::string> keys = {"gyroscope/2", "accelerometer/0"};
  // A gyroscope bias: its axis 3x its level, the accelerometer above it too; the bias brings the gyroscope back
  // (held-out chi2 drop 1950) to 50 above its level and leaves the accelerometer's 400.
  const std::map<std::string, ComponentLevel> with_bias = {{"gyroscope/2", {1.05, 1000}},
                                                           {"accelerometer/0", {1.4, 1000}}};
  EXPECT_NEAR(ExplainedShare(1950.0, HeldoutExcess(with_bias, keys, expected)), 1950.0 / (1950.0 + 450.0), 1e-12);
  // An accelerometer gain error (40x its level) that pulls the gyroscope's scale: the scale lowers the gyroscope a
  // little (drop 300) and leaves the accelerometer as it was.
  const std::map<std::string, ComponentLevel> with_scale = {{"gyroscope/2", {1.0, 1000}},
                                                            {"accelerometer/0", {39.9, 1000}}};
  const double share = ExplainedShare(300.0, HeldoutExcess(with_scale, keys, expected));
  EXPECT_NEAR(share, 300.0 / (300.0 + 38900.0), 1e-12);
  EXPECT_LT(share, kDefaultMinExplainedShare);
  // An effect whose own components were not located (an oval tire's wheel rows) still explains its drop against what
  // stays located; nothing left located: all of it; no drop: nothing.
  EXPECT_NEAR(ExplainedShare(30.0, 60.0), 1.0 / 3.0, 1e-12);
  EXPECT_DOUBLE_EQ(ExplainedShare(30.0, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(ExplainedShare(-5.0, 100.0), 0.0);
  EXPECT_DOUBLE_EQ(ExplainedShare(0.0, 0.0), 0.0);
}

}  // namespace
}  // namespace roamlab::gap
