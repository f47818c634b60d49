// The simulated recording against the kinematic generator of tests/support (which the estimator configurations in
// scenarios/ are written for): same streams, columns, units, nominal noise, sample times, truth names, provenance.
// A binary of its own because the generator links the estimator, which the simulator itself never does.
#include <gtest/gtest.h>

#include "sim/simulator.h"
#include "tests/sim/sim_testing.h"
#include "tests/support/synthetic.h"

namespace roamlab::sim {
namespace {

TEST(SimulatorLayoutTest, RecordingMatchesTheSyntheticGenerator) {
  auto run = Simulate(testing::AtvHills(1.0));
  ASSERT_TRUE(run.ok()) << run.status().message();
  const Simulation& sim = run.value();
  roamlab::testing::SyntheticOptions synthetic_options;
  synthetic_options.duration_s = 1.0;
  const auto synthetic = roamlab::testing::MakeAtvRecording(synthetic_options);
  const recording::Recording& a = sim.recording;
  const recording::Recording& b = synthetic.recording;
  ASSERT_EQ(a.streams.size(), b.streams.size());
  for (std::size_t i = 0; i < a.streams.size(); ++i) {
    const recording::StreamInfo& x = a.streams[i].info;
    const recording::StreamInfo& y = b.streams[i].info;
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.type, y.type) << x.name;
    EXPECT_EQ(x.rate_hz, y.rate_hz) << x.name;
    EXPECT_EQ(x.columns, y.columns) << x.name;
    EXPECT_EQ(x.units, y.units) << x.name;
    EXPECT_EQ(x.noise, y.noise) << x.name;
    EXPECT_EQ(x.mounting.has_value(), y.mounting.has_value()) << x.name;
    EXPECT_EQ(a.streams[i].t, b.streams[i].t) << x.name;
  }
  EXPECT_EQ(a.platform.kind, b.platform.kind);
  EXPECT_EQ(a.platform.geometry.at("wheelbase_m"), b.platform.geometry.at("wheelbase_m"));
  EXPECT_EQ(a.origin->latitude_deg, b.origin->latitude_deg);
  // The generator's kinematic tires roll at their radius; the simulated ones sink into the ground, so the simulator
  // states the scenario's kv/L as kv_over_L_geometric and its kv_over_L lies below it by the sink (under 0.2 %).
  ASSERT_EQ(sim.truth.calibration.size(), synthetic.truth.calibration.size() + 1);
  ASSERT_EQ(sim.truth.calibration.count("odometer.kv_over_L_geometric"), 1u);
  for (const auto& [name, values] : synthetic.truth.calibration) {
    ASSERT_EQ(sim.truth.calibration.count(name), 1u) << name;
    const bool rolling = name == "odometer.kv_over_L";
    const std::vector<double>& ours = sim.truth.calibration.at(rolling ? name + "_geometric" : name);
    ASSERT_EQ(ours.size(), values.size()) << name;
    for (std::size_t i = 0; i < values.size(); ++i) EXPECT_NEAR(ours[i], values[i], 1e-15) << name;
    if (rolling) {
      EXPECT_LT(sim.truth.calibration.at(name)[0], values[0]);
      EXPECT_GT(sim.truth.calibration.at(name)[0], values[0] * (1.0 - 0.002));
    }
  }
  EXPECT_TRUE(sim.truth.effects.empty());
  EXPECT_EQ(a.provenance.source, "simulated");
  EXPECT_NE(a.provenance.scenario.find("atv_hills.yaml"), std::string::npos);
  EXPECT_EQ(a.provenance.seed, std::optional<std::uint64_t>(1));
}

}  // namespace
}  // namespace roamlab::sim
