// The simulator's default 30 s drive (labelled slow: about a second of simulation, but the whole drive).
#include <cstdio>

#include <gtest/gtest.h>

#include "sim/simulator.h"
#include "tests/sim/sim_testing.h"

namespace roamlab::sim {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

// The whole default drive (30 s): distance, attitude from the hills, relief.
TEST(SimulatorSlowTest, DefaultDriveRoamsTheHills) {
  auto loaded = LoadScenario(testing::SourcePath("scenarios/atv_hills.yaml"));
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  auto run = Simulate(loaded.value());
  ASSERT_TRUE(run.ok()) << run.status().message();
  const Simulation& sim = run.value();
  const SimulationStats& st = sim.stats;
  std::printf(
      "30 s drive: %.1f m, pitch %.1f deg, roll %.1f deg, height range %.2f m, relief %.2f m, %.1fx real time\n",
      st.distance_m, st.max_abs_pitch_rad * 57.29578, st.max_abs_roll_rad * 57.29578, st.path_height_range_m,
      st.terrain_relief_m, st.realtime_factor);
  EXPECT_GT(st.distance_m, 80.0);
  EXPECT_GT(st.max_abs_pitch_rad, 4.0 * kDeg);
  EXPECT_GT(st.max_abs_roll_rad, 4.0 * kDeg);
  EXPECT_GT(st.terrain_relief_m, 2.0);
  EXPECT_LT(st.terrain_relief_m, 6.0);
  EXPECT_GT(st.path_height_range_m, 1.0);
  EXPECT_TRUE(st.warnings.empty());
}

}  // namespace
}  // namespace roamlab::sim
