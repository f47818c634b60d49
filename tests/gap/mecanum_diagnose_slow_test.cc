// The reality-gap diagnosis of a 30 s mecanum drive (scenarios/indoor_mecanum_gap.yaml) with a hidden
// track_width_error: it names the effect and recovers track_error_m within three of its reported standard deviations;
// without an effect the verdict stays "none".
// The baseline is learned once on a nominal simulation with a seed the cases do not use, as `roamlab diagnose` does.
// The truth is the effect put in the scenario; the diagnosis sees the recording only.
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "gap/diagnose.h"
#include "sim/simulator.h"
#include "tests/gap/gap_testing.h"

namespace roamlab::gap {
namespace {

class MecanumDiagnoseTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    auto loaded = sim::LoadScenario(std::string(ROAMLAB_SOURCE_DIR) + "/scenarios/indoor_mecanum_gap.yaml");
    ASSERT_TRUE(loaded.ok()) << loaded.status().message();
    nominal_ = new sim::Scenario(loaded.value());
    auto config = NominalConfig(*nominal_);
    ASSERT_TRUE(config.ok()) << config.status().message();
    config_ = new estimator::EstimatorConfig(config.value());
    DiagnoseOptions learn;
    learn.max_effects = 0;
    auto learned = Diagnose(*config_, testing::SimulatedWithSeed(*nominal_, 900001).recording, learn);
    ASSERT_TRUE(learned.ok()) << learned.status().message();
    baseline_ = new Baseline(BaselineFrom(learned.value()));
  }
  static void TearDownTestSuite() {
    delete nominal_;
    delete config_;
    delete baseline_;
  }

  // The nominal scenario with `effects` hidden, simulated with noise seed `seed` and diagnosed with the baseline.
  static Diagnosis Diagnosed(const std::vector<sim::EffectOptions>& effects, std::uint64_t seed) {
    sim::Scenario hidden = *nominal_;
    hidden.effects = effects;
    DiagnoseOptions options;
    options.baseline = baseline_;
    auto d = Diagnose(*config_, testing::SimulatedWithSeed(hidden, seed).recording, options);
    EXPECT_TRUE(d.ok()) << d.status().message();
    if (!d.ok()) return {};
    std::string names;
    for (const EffectEstimate& e : d.value().effects) names += e.name + " ";
    std::cout << "verdict " << d.value().verdict << ", named: " << names << "(" << d.value().seconds << " s)\n";
    for (const EffectEstimate& e : d.value().candidates) {
      std::cout << "  " << e.name << " LR " << e.lr << " dBIC " << e.delta_bic << " " << e.decision;
      for (const auto& [k, v] : e.parameters)
        std::cout << " " << k << " " << v << " +- " << (e.std.count(k) ? e.std.at(k) : 0.0);
      std::cout << "\n";
    }
    return std::move(d).value();
  }

  static sim::Scenario* nominal_;
  static estimator::EstimatorConfig* config_;
  static Baseline* baseline_;
};
sim::Scenario* MecanumDiagnoseTest::nominal_ = nullptr;
estimator::EstimatorConfig* MecanumDiagnoseTest::config_ = nullptr;
Baseline* MecanumDiagnoseTest::baseline_ = nullptr;

// Wheels 2 cm further apart on each side: lx + ly grows from 0.38 m by 0.02 m.
TEST_F(MecanumDiagnoseTest, NamesTrackWidthErrorAndRecoversIt) {
  const double track_error_m = 0.04;
  const Diagnosis d = Diagnosed({{"track_width_error", {{"track_error_m", track_error_m}}}}, 11);
  EXPECT_EQ(d.verdict, "named");
  ASSERT_FALSE(d.effects.empty());
  const EffectEstimate& e = d.effects.front();
  EXPECT_EQ(e.name, "track_width_error");
  ASSERT_TRUE(e.parameters.count("track_error_m") && e.std.count("track_error_m"));
  const double estimate = e.parameters.at("track_error_m"), std = e.std.at("track_error_m");
  std::cout << "track_error_m " << estimate << " +- " << std << " (true " << track_error_m << "), held-out chi2 "
            << 100.0 * e.heldout_improvement << " % lower\n";
  EXPECT_GT(std, 0.0);
  EXPECT_NEAR(estimate, track_error_m, 3.0 * std);
  EXPECT_GT(e.heldout_improvement, 0.0);
}

TEST_F(MecanumDiagnoseTest, NoEffectStaysNone) {
  const Diagnosis d = Diagnosed({}, 12);
  EXPECT_EQ(d.verdict, "none");
  EXPECT_TRUE(d.effects.empty());
}

}  // namespace
}  // namespace roamlab::gap
