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
  static void SetUpTestSuite() { nominal_ = testing::LearnNominal("scenarios/indoor_mecanum_gap.yaml").release(); }
  static void TearDownTestSuite() { delete nominal_; }
  void SetUp() override { ASSERT_NE(nominal_, nullptr); }

  // The nominal scenario with `effects` hidden, simulated with noise seed `seed` and diagnosed with the baseline.
  static Diagnosis Diagnosed(const std::vector<sim::EffectOptions>& effects, std::uint64_t seed) {
    auto d = testing::DiagnoseHidden(*nominal_, effects, seed);
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

  static testing::LearnedNominal* nominal_;
};
testing::LearnedNominal* MecanumDiagnoseTest::nominal_ = nullptr;

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
