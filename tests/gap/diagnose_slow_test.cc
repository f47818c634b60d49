// The reality-gap diagnosis of 30 s ATV drives (scenarios/atv_hills_sines.yaml) with one hidden effect, or none: it
// names the effect and recovers its parameter within three of its reported standard deviations, stays at "none"
// without one, and says "unknown" for an effect outside its library. The baseline (the nominal model on a nominal
// simulation) is learned once, from a seed the cases do not use.
// The truth is read from the simulation in memory, as evaluation does; the diagnosis sees the recording only.
#include <cmath>
#include <iostream>
#include <string>

#include <gtest/gtest.h>

#include "gap/diagnose.h"
#include "gap/learn_baseline.h"
#include "gap/nominal_config.h"
#include "sim/simulator.h"
#include "tests/gap/gap_testing.h"
#include "tests/support/paths.h"

namespace roamlab::gap {
namespace {

constexpr std::uint64_t kBaselineSeed = 900001;

sim::Scenario Atv() {
  auto s = sim::LoadScenario(roamlab::testing::SourceDir() + "/scenarios/atv_hills_sines.yaml");
  EXPECT_TRUE(s.ok()) << s.status().message();
  return s.value();
}

class DiagnoseTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const sim::Scenario nominal = Atv();
    auto config = NominalConfig(nominal);
    ASSERT_TRUE(config.ok()) << config.status().message();
    config_ = new estimator::EstimatorConfig(config.value());
    LearnBaselineOptions learn;
    learn.seed = kBaselineSeed;
    auto learned = LearnBaseline(nominal, *config_, learn);
    ASSERT_TRUE(learned.ok()) << learned.status().message();
    baseline_ = new Baseline(learned.value().baseline);
  }
  static void TearDownTestSuite() {
    delete config_;
    delete baseline_;
  }

  // Simulates the scenario with `effects` and diagnoses it against the nominal model.
  static Diagnosis Run(const std::vector<sim::EffectOptions>& effects, std::uint64_t seed, sim::Simulation* sim,
                       double max_shift_s = DiagnoseOptions().max_shift_s) {
    sim::Scenario scenario = Atv();
    scenario.effects = effects;
    *sim = testing::SimulatedWithSeed(scenario, seed);
    DiagnoseOptions options;
    options.baseline = baseline_;
    options.max_shift_s = max_shift_s;
    auto d = Diagnose(*config_, sim->recording, options);
    EXPECT_TRUE(d.ok()) << d.status().message();
    return std::move(d).value();
  }

  // The diagnosis names exactly the hidden effect and recovers each of its non-neutral parameters within 3 std.
  static void ExpectNamed(const Diagnosis& d, const recording::Effect& truth, const std::vector<std::string>& checked) {
    std::string names;
    for (const EffectEstimate& e : d.effects) names += e.name + " ";
    ASSERT_EQ(d.verdict, "named");
    ASSERT_EQ(d.effects.size(), 1u) << names;
    const EffectEstimate& e = d.effects[0];
    EXPECT_EQ(e.name, truth.name);
    for (const std::string& p : checked) {
      ASSERT_TRUE(e.parameters.count(p) && e.std.count(p)) << p;
      const double error = e.parameters.at(p) - truth.parameters.at(p);
      std::cout << truth.name << "." << p << ": truth " << truth.parameters.at(p) << " estimate " << e.parameters.at(p)
                << " std " << e.std.at(p) << " error/std " << error / e.std.at(p) << "\n";
      EXPECT_LT(std::abs(error), 3.0 * e.std.at(p)) << p;
    }
    EXPECT_GT(e.heldout_improvement, 0.0);
    for (const auto& [stream, before] : d.before) EXPECT_LE(d.after.at(stream).chi2, before.chi2 * 1.05) << stream;
  }

  static estimator::EstimatorConfig* config_;
  static Baseline* baseline_;
};
estimator::EstimatorConfig* DiagnoseTest::config_ = nullptr;
Baseline* DiagnoseTest::baseline_ = nullptr;

TEST_F(DiagnoseTest, NoEffectGivesNone) {
  sim::Simulation sim;
  const Diagnosis d = Run({}, 12, &sim);
  EXPECT_EQ(d.verdict, "none");
  EXPECT_TRUE(d.effects.empty());
}

TEST_F(DiagnoseTest, SteeringOffset) {
  sim::Simulation sim;
  const Diagnosis d = Run({{"steering_offset", {{"offset_rad", 0.03}}}}, 13, &sim);
  ExpectNamed(d, sim.truth.effects.at(0), {"offset_rad"});
}

TEST_F(DiagnoseTest, GyroScaleError) {
  sim::Simulation sim;
  const Diagnosis d = Run({{"gyro_scale_error", {{"scale_z", 1.03}}}}, 14, &sim);
  ExpectNamed(d, sim.truth.effects.at(0), {"scale_x", "scale_y", "scale_z"});
}

// A constant gyroscope bias (no random walk) of a few tenths of a degree per second, a typical MEMS turn-on bias.
TEST_F(DiagnoseTest, GyroBiasDrift) {
  sim::Simulation sim;
  const Diagnosis d =
      Run({{"gyro_bias_drift", {{"initial_x", 0.003}, {"initial_y", -0.002}, {"initial_z", 0.005}}}}, 17, &sim);
  ExpectNamed(d, sim.truth.effects.at(0), {"initial_x", "initial_y", "initial_z"});
}

// On this 30 s drive (20 s of training) the continuous IMU offset (imu.time_offset_s, the gyroscope's and
// accelerometer's, each reading moved along its own stream's slope) names a 30 ms offset first and alone:
// 28.1 +- 5.1 ms (-0.4 std), p = 3.3e-8, Delta BIC -22. With the offset's derivative from the poses instead it was
// 24.6 +- 3.8 ms, but the odometer's held-out chi2 rose 6.5 % with it, beyond the 5 % this test allows every stream.
TEST_F(DiagnoseTest, ImuTimeOffset) {
  sim::Simulation sim;
  const Diagnosis d = Run({{"imu_time_offset", {{"offset_s", 0.03}}}}, 15, &sim);
  for (const EffectEstimate& e : d.candidates) {
    std::cout << e.name << ":";
    for (const auto& [k, v] : e.parameters) std::cout << " " << k << " = " << v << " +- " << e.std.at(k);
    std::cout << " LR " << e.lr << " p " << e.lr_pvalue << " dBIC " << e.delta_bic << " (" << e.decision << ")\n";
  }
  for (const std::string& u : d.unexplained) std::cout << "unexplained: " << u << "\n";
  ExpectNamed(d, sim.truth.effects.at(0), {"offset_s"});
}

// An offset near the first-order model's 0.1 s (gap-benchmark seed 2, case 41): beside the nominal model's own
// offset on this drive (about 0.025 s on the baseline) the minimum lies near 0.12 s, on the grid of stamp shifts, where
// moving the IMU by a sample re-pairs its noise and the chi-square jitters by tens. The downhill walk stopped at
// 0.10 s on such a bump and the parabola of the window around it, its vertex at the window's edge, gave
// 0.105 +- 0.096 s, which the likelihood-ratio test rejected (p 0.27); the window now follows the vertex.
TEST_F(DiagnoseTest, ImuTimeOffsetAtTheFirstOrderRangesEnd) {
  sim::Simulation sim;
  const Diagnosis d = Run({{"imu_time_offset", {{"offset_s", 0.096}}}}, 2041, &sim);
  for (const EffectEstimate& e : d.candidates)
    if (e.name == "imu_time_offset")
      std::cout << "offset " << e.parameters.at("offset_s") << " +- " << e.std.at("offset_s") << ": " << e.decision
                << "\n";
  ExpectNamed(d, sim.truth.effects.at(0), {"offset_s"});
}

TEST_F(DiagnoseTest, GpsLatency) {
  sim::Simulation sim;
  const Diagnosis d = Run({{"gps_latency", {{"latency_s", 0.3}}}}, 16, &sim);
  ExpectNamed(d, sim.truth.effects.at(0), {"latency_s"});
}

// A latency beyond the time-shift range (0.5 s by default): the parabola's vertex past the grid's end is rejected as
// out of range, not kept and not blamed on the held-out part (the parts are cut for shifts within the range: a fit
// beyond it would lose fixes on the held-out part); with the range widened to 0.8 s it is named.
TEST_F(DiagnoseTest, GpsLatencyBeyondTheShiftRange) {
  sim::Simulation sim;
  const Diagnosis d = Run({{"gps_latency", {{"latency_s", 0.572}}}}, 16, &sim);
  for (const EffectEstimate& e : d.effects) EXPECT_NE(e.name, "gps_latency");
  bool rejected = false;
  for (const EffectEstimate& e : d.candidates) {
    if (e.name != "gps_latency") continue;
    std::cout << "latency " << e.parameters.at("latency_s") << " +- " << e.std.at("latency_s") << ": " << e.decision
              << "\n";
    rejected = e.decision.find("beyond the time-shift range") != std::string::npos;
  }
  EXPECT_TRUE(rejected);
  const Diagnosis wide = Run({{"gps_latency", {{"latency_s", 0.572}}}}, 16, &sim, 0.8);
  ExpectNamed(wide, sim.truth.effects.at(0), {"latency_s"});
}

// A decoy (gap-benchmark): an accelerometer gain error, which no candidate models. Its residuals give it away: the
// accelerometer components are inconsistent and follow the motion (the gain scales gravity and the accelerations, so
// the residual moves with the slope, the speed or the lateral acceleration), and whatever library parameter it pulls
// on (through the shared attitude) leaves them inconsistent on the held-out part, so the verdict is "unknown". Such a
// pull explains a small share of the held-out mismatch (DiagnoseOptions::min_explained_share), so no library effect
// is kept either (gap-benchmark's rule: a decoy with a kept effect is a false discovery).
TEST_F(DiagnoseTest, AccelerometerGainDecoyIsUnknown) {
  sim::Simulation sim;
  const Diagnosis d = Run({{"accelerometer_scale_error", {{"scale_z", 1.03}}}}, 18, &sim);
  for (const std::string& u : d.unexplained) std::cout << "unexplained: " << u << "\n";
  for (const EffectEstimate& e : d.candidates)
    if (e.evaluated_heldout)
      std::cout << e.name << ": held-out drop " << e.heldout_improvement << ", share explained " << e.explained_share
                << " (" << e.decision << ")\n";
  EXPECT_EQ(d.verdict, "unknown");
  EXPECT_TRUE(d.effects.empty()) << d.effects.front().name;
  bool accelerometer = false;
  for (const std::string& u : d.unexplained) accelerometer = accelerometer || u.rfind("accelerometer/", 0) == 0;
  EXPECT_TRUE(accelerometer);
  for (const LocatedComponent& lc : d.located) {
    if (lc.stream != "accelerometer" || lc.component != 2) continue;
    EXPECT_TRUE(lc.inconsistent);
    EXPECT_GT(lc.chi2_per_dof, 3.0 * lc.expected_chi2_per_dof);
    ASSERT_FALSE(lc.correlates.empty());
    EXPECT_GT(std::abs(lc.correlates.front().rho), 0.3) << lc.correlates.front().condition;
  }
}

}  // namespace
}  // namespace roamlab::gap
