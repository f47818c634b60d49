// The re-simulation against a recording (gap/resimulate.h): on a recording of the scenario's own drive, the noise-free
// nominal simulation leaves exactly the recording's noise (whitened RMS 1 within its chi-square spread); a hidden GPS
// latency shows in the GPS stream, and the simulation with that latency applied brings it back to the noise.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "gap/resimulate.h"
#include "sim/simulator.h"
#include "tests/gap/gap_testing.h"
#include "tests/support/paths.h"

namespace roamlab::gap {
namespace {

constexpr double kDurationS = 8.0;

sim::Scenario ShortAtv() {
  auto s = sim::LoadScenario(roamlab::testing::SourceDir() + "/scenarios/atv_hills_sines.yaml");
  EXPECT_TRUE(s.ok()) << s.status().message();
  sim::Scenario scenario = s.value();
  scenario.duration_s = kDurationS;
  return scenario;
}

// A whitened RMS over `count` independent unit-variance residuals: its square is chi2(count) / count, whose standard
// deviation is sqrt(2 / count); 5 of them either side.
void ExpectNoiseLevel(const SimulatedStreamFit& fit, const std::string& stream) {
  const double count = static_cast<double>(fit.samples) * static_cast<double>(fit.component_rms.size());
  ASSERT_GT(count, 0.0) << stream;
  EXPECT_NEAR(fit.rms * fit.rms, 1.0, 5.0 * std::sqrt(2.0 / count)) << stream << " over " << fit.samples << " samples";
}

TEST(ResimulateTest, TheNominalDriveLeavesOnlyTheRecordingsNoise) {
  const sim::Scenario scenario = ShortAtv();
  const sim::Simulation recorded = testing::SimulatedWithSeed(scenario, 5);
  auto c = CompareWithSimulation(scenario, {}, recorded.recording, 2.0);
  ASSERT_TRUE(c.ok()) << c.status().message();
  for (const char* stream : {"gyroscope", "accelerometer", "magnetometer", "gps", "rear_wheel", "steering"}) {
    ASSERT_TRUE(c.value().before.count(stream)) << stream;
    ExpectNoiseLevel(c.value().before.at(stream), stream);
    // White noise averages out of the 1 s means: 1 / sqrt(samples per second), 0.1 at 100 Hz, 0.45 at 5 Hz.
    EXPECT_LT(c.value().before.at(stream).rms_1s, 0.6 * c.value().before.at(stream).rms) << stream;
    EXPECT_EQ(c.value().after.at(stream).rms, c.value().before.at(stream).rms) << stream;
  }
  EXPECT_TRUE(c.value().left_out.empty());
}

TEST(ResimulateTest, AHiddenGpsLatencyIsInTheGpsStreamUntilTheSimulationAppliesIt) {
  sim::Scenario hidden = ShortAtv();
  hidden.effects = {{"gps_latency", {{"latency_s", 0.3}}}};
  const sim::Simulation recorded = testing::SimulatedWithSeed(hidden, 5);
  EffectEstimate latency;
  latency.name = "gps_latency";
  latency.parameters = {{"latency_s", 0.3004}};  // as fitted: the simulator takes whole 1 ms physics steps
  auto c = CompareWithSimulation(ShortAtv(), {latency}, recorded.recording, 2.0);
  ASSERT_TRUE(c.ok()) << c.status().message();
  // 0.3 s at about 4 m/s is about 1.2 m along the track, several times the fix's 0.33 m.
  EXPECT_GT(c.value().before.at("gps").rms, 2.0);
  EXPECT_GT(c.value().before.at("gps").rms_1s, 2.0);  // a systematic offset: it stays in the means
  ExpectNoiseLevel(c.value().after.at("gps"), "gps");
  ExpectNoiseLevel(c.value().after.at("gyroscope"), "gyroscope");
  EXPECT_TRUE(c.value().not_simulated.empty()) << c.value().not_simulated;
  ASSERT_EQ(c.value().effects.size(), 1u);
  EXPECT_NEAR(c.value().effects[0].parameters.at("latency_s"), 0.3, 1e-12);
}

TEST(ResimulateTest, TheRearCorneringComplianceBecomesTheTiresContactTimeScale) {
  EffectEstimate slip;
  slip.name = "lateral_slip";
  slip.parameters = {{"cornering_front_rads2pm", 0.01}, {"cornering_rear_s", 0.0406}};
  slip.std = {{"cornering_rear_s", 0.00203}};
  std::map<std::string, double> std;
  const sim::EffectOptions e = SimulatorEffect(slip, &std);
  EXPECT_EQ(e.name, "lateral_slip");
  ASSERT_EQ(e.parameters.size(), 1u);
  EXPECT_NEAR(e.parameters.at("contact_time_scale"), 3.0, 1e-12);
  EXPECT_NEAR(std.at("contact_time_scale"), 0.1, 1e-12);
  slip.parameters["cornering_rear_s"] = -0.01;  // stiffer than nominal: the simulator's tires go no stiffer
  EXPECT_EQ(SimulatorEffect(slip).parameters.at("contact_time_scale"), 1.0);
}

TEST(ResimulateTest, ARecordingOfAnotherRobotIsRefused) {
  const sim::Scenario scenario = ShortAtv();
  recording::Recording other;
  other.platform.kind = "differential_drive";
  const auto c = CompareWithSimulation(scenario, {}, other, 0.0);
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.status().message().find("differential_drive"), std::string::npos) << c.status().message();
}

}  // namespace
}  // namespace roamlab::gap
