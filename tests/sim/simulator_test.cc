// The simulator (sim/simulator.h): determinism, the noise it adds, run-time failures, and that the vehicle follows
// its driver over the hills.
#include "sim/simulator.h"

#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>
#include <GeographicLib/LocalCartesian.hpp>

#include "recording/recording.h"
#include "recording/truth.h"
#include "tests/recording/temp_dir.h"
#include "tests/sim/sim_testing.h"

namespace roamlab::sim {
namespace {

namespace fs = std::filesystem;

Simulation RunOrFail(const Scenario& scenario, SimulateOptions options = {}) {
  auto result = Simulate(scenario, options);
  EXPECT_TRUE(result.ok()) << result.status().message();
  return result.ok() ? std::move(result).value() : Simulation{};
}

void Write(const Simulation& simulation, const std::string& dir) {
  ASSERT_TRUE(recording::WriteRecording(simulation.recording, dir).ok());
  ASSERT_TRUE(recording::WriteTruth(simulation.truth, dir).ok());
}

// Every file of directory a, byte for byte equal to the same file in b (and the same set of files).
void ExpectSameFiles(const std::string& a, const std::string& b) {
  std::size_t files = 0;
  for (const auto& entry : fs::directory_iterator(a)) {
    const std::string name = entry.path().filename().string();
    EXPECT_EQ(roamlab::testing::ReadFile(entry.path().string()), roamlab::testing::ReadFile(b + "/" + name)) << name;
    ++files;
  }
  EXPECT_EQ(files, static_cast<std::size_t>(std::distance(fs::directory_iterator(b), fs::directory_iterator{})));
  EXPECT_EQ(files, 8u);  // recording.yaml, five streams, ground_truth.tum, truth.yaml
}

TEST(SimulatorTest, SameScenarioAndSeedGiveByteIdenticalRecordings) {
  const Scenario scenario = testing::AtvHills(2.0);
  SimulateOptions options;
  options.seed = 5;
  roamlab::testing::TempDir first, second, other_seed;
  Write(RunOrFail(scenario, options), first.path());
  Write(RunOrFail(scenario, options), second.path());
  ExpectSameFiles(first.path(), second.path());

  // Another seed: other noise on every sensor, the same drive and truth.
  options.seed = 6;
  Write(RunOrFail(scenario, options), other_seed.path());
  for (const char* stream : {"imu.csv", "magnetometer.csv", "gps.csv", "rear_wheel.csv", "steering.csv"}) {
    EXPECT_NE(roamlab::testing::ReadFile(first.File(stream)), roamlab::testing::ReadFile(other_seed.File(stream)))
        << stream;
  }
  EXPECT_EQ(roamlab::testing::ReadFile(first.File("ground_truth.tum")),
            roamlab::testing::ReadFile(other_seed.File("ground_truth.tum")));
  EXPECT_EQ(roamlab::testing::ReadFile(first.File("truth.yaml")),
            roamlab::testing::ReadFile(other_seed.File("truth.yaml")));
}

// The noise does not feed back into the physics, so a run with noise minus the same run without is the noise alone:
// zero-mean with the configured standard deviation on every channel.
TEST(SimulatorTest, NoiseHasTheConfiguredStandardDeviations) {
  const Scenario scenario = testing::AtvHills(10.0);
  const Simulation noisy = RunOrFail(scenario);
  SimulateOptions clean_options;
  clean_options.noise = false;
  const Simulation clean = RunOrFail(scenario, clean_options);
  ASSERT_NE(noisy.recording.Find("gps"), nullptr);
  const auto check = [&](const std::string& stream, int first_column, int columns, double sigma) {
    const Eigen::MatrixXd noise = noisy.recording.Find(stream)->values.middleCols(first_column, columns) -
                                  clean.recording.Find(stream)->values.middleCols(first_column, columns);
    const double n = static_cast<double>(noise.size());
    const double mean = noise.sum() / n;
    const double std = std::sqrt((noise.array() - mean).square().sum() / (n - 1));
    // n is 1001 to 3003 samples: the sample std is within 4 sigma of the true one when |std/sigma - 1| < 4/sqrt(2n).
    EXPECT_NEAR(std / sigma, 1.0, 4.0 / std::sqrt(2.0 * n)) << stream;
    EXPECT_NEAR(mean / sigma, 0.0, 4.0 / std::sqrt(n)) << stream;
  };
  check("imu", 0, 3, 0.033);
  check("imu", 3, 3, 0.067);
  check("magnetometer", 0, 3, 0.067);
  check("rear_wheel", 0, 1, 0.033);
  check("steering", 0, 1, 0.014);

  // GPS noise is added in ENU before the conversion to latitude, longitude, altitude.
  const recording::GeodeticOrigin& o = *noisy.recording.origin;
  const GeographicLib::LocalCartesian local(o.latitude_deg, o.longitude_deg, o.altitude_m);
  const auto enu = [&local](const recording::Stream& gps) {
    Eigen::MatrixXd out(gps.values.rows(), 3);
    for (Eigen::Index k = 0; k < gps.values.rows(); ++k)
      local.Forward(gps.values(k, 0), gps.values(k, 1), gps.values(k, 2), out(k, 0), out(k, 1), out(k, 2));
    return out;
  };
  const Eigen::MatrixXd gps_noise = enu(*noisy.recording.Find("gps")) - enu(*clean.recording.Find("gps"));
  const double n = static_cast<double>(gps_noise.size());  // 51 fixes, 153 values
  EXPECT_NEAR(std::sqrt(gps_noise.squaredNorm() / n) / 0.33, 1.0, 4.0 / std::sqrt(2.0 * n));
}

TEST(SimulatorTest, RatesMustBeWholePhysicsSteps) {
  Scenario s = testing::AtvHills(1.0);
  s.sensors.gps->rate_hz = 3.0;  // 333333333 ns, not a multiple of the 1 ms step
  auto simulator = Simulator::Create(s);
  ASSERT_FALSE(simulator.ok());
  EXPECT_NE(simulator.status().message().find("sensors.gps.rate_hz"), std::string::npos)
      << simulator.status().message();
}

TEST(SimulatorTest, LeavingTheTerrainIsARunTimeErrorWithItsTime) {
  Scenario s = testing::AtvHills(20.0);
  s.terrain.size_m = Eigen::Vector2d(30.0, 30.0);
  s.terrain.min_wavelength_m = 10.0;
  s.terrain.max_wavelength_m = 20.0;
  s.driver.handlebar_rad = Profile::Constant(0.0);
  auto simulator = Simulator::Create(s);
  ASSERT_TRUE(simulator.ok()) << simulator.status().message();
  auto run = simulator.value()->Run();
  ASSERT_FALSE(run.ok());
  EXPECT_NE(run.status().message().find("left the terrain at t = "), std::string::npos) << run.status().message();
}

// A few seconds of the default drive: the vehicle follows the speed set-point over the hills.
TEST(SimulatorTest, VehicleDrivesAtTheCommandedSpeed) {
  const Scenario s = testing::AtvHills(5.0);
  const Simulation sim = RunOrFail(s);
  double commanded = 0.0;
  for (double t = 0.0; t < 5.0; t += 0.01) commanded += 0.01 * s.driver.speed_mps.Evaluate(t);
  // The speed controller lags the set-point by a fraction of a second.
  EXPECT_NEAR(sim.stats.distance_m, commanded, 0.05 * commanded);
  EXPECT_GT(sim.stats.max_abs_pitch_rad, 0.02);
  EXPECT_EQ(sim.stats.physics_steps, 9000);  // 4 s lead-in and 5 s recorded at 1 kHz
}

}  // namespace
}  // namespace roamlab::sim
