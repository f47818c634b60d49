// The reality-gap diagnosis of a 30 s differential drive (scenarios/indoor_diffdrive_gap.yaml) with a hidden
// wheel_radius_asymmetry: it names the effect and recovers the ratio within three of its reported standard deviations.
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

TEST(DiffDriveDiagnoseTest, NamesWheelRadiusAsymmetryAndRecoversTheRatio) {
  auto loaded = sim::LoadScenario(std::string(ROAMLAB_SOURCE_DIR) + "/scenarios/indoor_diffdrive_gap.yaml");
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  const sim::Scenario nominal = loaded.value();
  auto config = NominalConfig(nominal);
  ASSERT_TRUE(config.ok()) << config.status().message();

  DiagnoseOptions learn;
  learn.max_effects = 0;
  auto learned = Diagnose(config.value(), testing::SimulatedWithSeed(nominal, 900001).recording, learn);
  ASSERT_TRUE(learned.ok()) << learned.status().message();
  const Baseline baseline = BaselineFrom(learned.value());

  const double rho = 1.02;
  sim::Scenario hidden = nominal;
  hidden.effects = {{"wheel_radius_asymmetry", {{"ratio_right_left", rho}}}};
  const sim::Simulation real = testing::SimulatedWithSeed(hidden, 7);
  DiagnoseOptions options;
  options.baseline = &baseline;
  auto d = Diagnose(config.value(), real.recording, options);
  ASSERT_TRUE(d.ok()) << d.status().message();
  ASSERT_EQ(d.value().verdict, "named");
  ASSERT_FALSE(d.value().effects.empty());
  const EffectEstimate& e = d.value().effects.front();
  EXPECT_EQ(e.name, "wheel_radius_asymmetry");
  const double estimate = e.parameters.at("ratio_right_left"), std = e.std.at("ratio_right_left");
  std::cout << "ratio_right_left " << estimate << " +- " << std << " (true " << rho << "), held-out chi2 "
            << 100.0 * e.heldout_improvement << " % lower\n";
  EXPECT_GT(std, 0.0);
  EXPECT_NEAR(estimate, rho, 3.0 * std);
  EXPECT_GT(e.heldout_improvement, 0.0);
}

}  // namespace
}  // namespace roamlab::gap
