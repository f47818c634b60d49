// The library of candidate effects (gap/internal/effect_library.h): which candidates apply to a nominal
// configuration, what each frees or shifts, and how fitted values read as the simulator's effect parameters.
#include "gap/internal/effect_library.h"

#include <algorithm>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gap/nominal_config.h"
#include "sim/scenario.h"
#include "tests/support/paths.h"

namespace roamlab::gap::internal {
namespace {

estimator::EstimatorConfig Nominal(const std::string& scenario_path) {
  auto scenario = sim::LoadScenario(roamlab::testing::SourceDir() + "/" + scenario_path);
  EXPECT_TRUE(scenario.ok()) << scenario.status().message();
  auto config = NominalConfig(scenario.value());
  EXPECT_TRUE(config.ok()) << config.status().message();
  return config.value();
}

std::vector<std::string> Names(const std::vector<Candidate>& library) {
  std::vector<std::string> names;
  for (const Candidate& c : library) names.push_back(c.name);
  return names;
}

// The candidate `name` of the library, or null.
const Candidate* Find(const std::vector<Candidate>& library, const std::string& name) {
  const auto it = std::find_if(library.begin(), library.end(), [&](const Candidate& c) { return c.name == name; });
  return it != library.end() ? &*it : nullptr;
}

// The ATV's nominal model (IMU misalignment free): no wheel candidate, no axle misalignment (it would duplicate the
// steering offset), the time shifts of the GPS and the IMU, in the library's order.
TEST(EffectLibraryTest, TheAtvGetsItsSensorsAndTiresCandidates) {
  const std::vector<Candidate> library = Library(Nominal("scenarios/atv_hills_sines.yaml"));
  const std::vector<std::string> expected = {"gps_latency",
                                             "imu_time_offset",
                                             "steering_offset",
                                             "gyro_scale_error",
                                             "gyro_bias_drift",
                                             "lateral_slip",
                                             "magnetometer_motor_interference",
                                             "longitudinal_slip",
                                             "slope_slip"};
  EXPECT_EQ(Names(library), expected);
  const Candidate* gps = Find(library, "gps_latency");
  ASSERT_NE(gps, nullptr);
  EXPECT_EQ(gps->shifted, std::vector<std::string>{"gps"});
  EXPECT_TRUE(gps->free.empty());
  // The IMU's clock: its streams shifted together, or the shared time_offset_s fitted.
  const Candidate* imu = Find(library, "imu_time_offset");
  ASSERT_NE(imu, nullptr);
  EXPECT_EQ(imu->free, std::vector<std::string>{"imu.time_offset_s"});
  EXPECT_FALSE(imu->shifted.empty());
}

// A steering offset reads as the departure of k_gamma from its believed value, with the fit's std.
TEST(EffectLibraryTest, AFreedSlotReadsAsTheDepartureFromItsNominalValue) {
  const estimator::EstimatorConfig config = Nominal("scenarios/atv_hills_sines.yaml");
  const std::vector<Candidate> library = Library(config);
  const Candidate* c = Find(library, "steering_offset");
  ASSERT_NE(c, nullptr);
  ASSERT_EQ(c->free, std::vector<std::string>{"odometer.k_gamma"});
  const double nominal = (*config.parameters.at("odometer.k_gamma").value)[0];
  EffectEstimate e;
  c->describe({{"odometer.k_gamma", Eigen::VectorXd::Constant(1, nominal + 0.03)}},
              {{"odometer.k_gamma", Eigen::VectorXd::Constant(1, 0.002)}}, &e);
  EXPECT_NEAR(e.parameters.at("offset_rad"), 0.03, 1e-12);
  EXPECT_NEAR(e.std.at("offset_rad"), 0.002, 1e-15);
}

// The differential drive (one radius for both wheels, the track fixed): the wheels' candidates apply; a track error
// reads in metres from the measured geometry.
TEST(EffectLibraryTest, TheDifferentialDriveGetsItsWheelCandidates) {
  const estimator::EstimatorConfig config = Nominal("scenarios/indoor_diffdrive_gap.yaml");
  const std::vector<Candidate> library = Library(config);
  const std::vector<std::string> expected = {"imu_time_offset",        "gyro_scale_error",  "gyro_bias_drift",
                                             "wheel_radius_asymmetry", "track_width_error", "wheel_deformation"};
  EXPECT_EQ(Names(library), expected);
  const Candidate* track = Find(library, "track_width_error");
  ASSERT_NE(track, nullptr);
  const double baseline = (*config.parameters.at("odometer.baseline").value)[0];
  EffectEstimate e;
  track->describe({{"odometer.baseline", Eigen::VectorXd::Constant(1, baseline + 0.01)}}, {}, &e);
  EXPECT_NEAR(e.parameters.at("track_error_m"), 0.01, 1e-12);
  EXPECT_FALSE(e.std.count("track_error_m"));
}

}  // namespace
}  // namespace roamlab::gap::internal
