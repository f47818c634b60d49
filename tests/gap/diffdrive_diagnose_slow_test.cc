// The reality-gap diagnosis of a 30 s differential drive (scenarios/indoor_diffdrive_gap.yaml) with a hidden
// wheel_radius_asymmetry or wheel_deformation: it names the effect and recovers its parameter within three of its
// reported standard deviations.
// The baseline is learned once on a nominal simulation with a seed the case does not use, as `roamlab diagnose` does.
// The truth is read from the simulation in memory, as evaluation does; the diagnosis sees the recording only.
#include <cmath>
#include <iostream>
#include <string>

#include <gtest/gtest.h>

#include "gap/diagnose.h"
#include "sim/simulator.h"
#include "tests/gap/gap_testing.h"

namespace roamlab::gap {
namespace {

class DiffDriveDiagnoseTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { nominal_ = testing::LearnNominal("scenarios/indoor_diffdrive_gap.yaml").release(); }
  static void TearDownTestSuite() { delete nominal_; }
  void SetUp() override { ASSERT_NE(nominal_, nullptr); }

  // The nominal scenario with `effect` hidden, simulated with noise seed `seed` and diagnosed; `effect` must be named
  // first, with a held-out improvement.
  static EffectEstimate NamedEffect(const sim::EffectOptions& effect, std::uint64_t seed) {
    auto d = testing::DiagnoseHidden(*nominal_, {effect}, seed);
    EXPECT_TRUE(d.ok()) << d.status().message();
    if (!d.ok()) return {};
    EXPECT_EQ(d.value().verdict, "named");
    for (const std::string& u : d.value().unexplained) std::cout << "unexplained: " << u << "\n";
    std::string names;
    for (const EffectEstimate& e : d.value().effects) names += e.name + " ";
    std::cout << "named: " << names << "\n";
    if (d.value().effects.empty()) return {};
    const EffectEstimate& e = d.value().effects.front();
    EXPECT_EQ(e.name, effect.name) << names;
    EXPECT_GT(e.heldout_improvement, 0.0);
    return e;
  }

  static testing::LearnedNominal* nominal_;
};
testing::LearnedNominal* DiffDriveDiagnoseTest::nominal_ = nullptr;

TEST_F(DiffDriveDiagnoseTest, NamesWheelRadiusAsymmetryAndRecoversTheRatio) {
  const double rho = 1.02;
  const EffectEstimate e = NamedEffect({"wheel_radius_asymmetry", {{"ratio_right_left", rho}}}, 7);
  ASSERT_TRUE(e.parameters.count("ratio_right_left") && e.std.count("ratio_right_left"));
  const double estimate = e.parameters.at("ratio_right_left"), std = e.std.at("ratio_right_left");
  std::cout << "ratio_right_left " << estimate << " +- " << std << " (true " << rho << "), held-out chi2 "
            << 100.0 * e.heldout_improvement << " % lower\n";
  EXPECT_GT(std, 0.0);
  EXPECT_NEAR(estimate, rho, 3.0 * std);
}

// A constant gyroscope bias about z: at a forward speed that never stops it reads like a wheel-radius ratio (a turn
// rate in proportion to the speed); the drive's reversals tell them apart, and the bias must be named first.
TEST_F(DiffDriveDiagnoseTest, NamesAGyroBiasApartFromAWheelRatio) {
  const double bias_radps = 0.006;
  const EffectEstimate e = NamedEffect({"gyro_bias_drift", {{"initial_z", bias_radps}}}, 10);
  ASSERT_TRUE(e.parameters.count("initial_z") && e.std.count("initial_z"));
  const double estimate = e.parameters.at("initial_z"), std = e.std.at("initial_z");
  std::cout << "gyro bias z " << estimate << " +- " << std << " rad/s (true " << bias_radps << "), held-out chi2 "
            << 100.0 * e.heldout_improvement << " % lower\n";
  EXPECT_GT(std, 0.0);
  EXPECT_NEAR(estimate, bias_radps, 3.0 * std);
}

// An out-of-round right tire: 2 mm of ovality on the 75 mm tire at the nominal mean rolling radius, the rolling
// radius 1 mm either side of it twice per revolution (models/differential_drive.h).
TEST_F(DiffDriveDiagnoseTest, NamesWheelDeformationAndRecoversTheOvality) {
  const double ovality_m = 0.002;
  const EffectEstimate e = NamedEffect({"wheel_deformation", {{"wheel", 1.0}, {"ovality_m", ovality_m}}}, 8);
  ASSERT_TRUE(e.parameters.count("ovality_m") && e.std.count("ovality_m"));
  const double estimate = e.parameters.at("ovality_m"), std = e.std.at("ovality_m");
  std::cout << "wheel " << e.parameters.at("wheel") << " ovality " << estimate << " +- " << std << " m (true "
            << ovality_m << "), held-out chi2 " << 100.0 * e.heldout_improvement << " % lower\n";
  EXPECT_EQ(e.parameters.at("wheel"), 1.0);
  EXPECT_GT(std, 0.0);
  EXPECT_NEAR(estimate, ovality_m, 3.0 * std);
}

}  // namespace
}  // namespace roamlab::gap
