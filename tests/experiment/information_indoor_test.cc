// `roamlab information` on the indoor robots (differential drive, three-wheel omni, mecanum) with their calibration
// configurations: short MuJoCo drives analysed noise-free at their truth; every free parameter of the robot's own
// kinematics gets a finite bound, and the variance split by stream and by window adds up to the whole.
#include <cmath>
#include <fstream>
#include <map>
#include <numeric>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "experiment/information.h"
#include "tests/recording/temp_dir.h"
#include "tests/support/paths.h"

namespace roamlab::experiment {
namespace {

// The shares of one split sum to 1 up to rounding.
constexpr double kSumTolerance = 1e-6;

// A short drive of the indoor robot `kind` (model file `model`) with the driver and sensors given as YAML lines.
std::string IndoorScenario(const std::string& kind, const std::string& model, const std::string& world,
                           const std::string& driver_and_sensors) {
  return "name: short_" + kind + "\nduration_s: 6.0\nseed: 1\nground_truth_rate_hz: 100\nrobot:\n  kind: " + kind +
         "\n  model: " + roamlab::testing::SourceDir() + "/models/" + model +
         "\n  start: {position_m: [0.0, 0.0], heading_deg: 0.0}\nworld:\n  terrain: {type: flat, friction: 0.6}\n" +
         world + driver_and_sensors;
}

const char* kImuAndEncoders =
    "  imu: {rate_hz: 100, gyro_sigma_radps: 0.01, accel_sigma_mps2: 0.05}\n"
    "  wheel_encoders: {rate_hz: 100, ticks_per_revolution: 2048}\n";

// Back and forth with a yaw rate that sweeps both ways (scenarios/indoor_diffdrive_mocap.yaml, periods shortened).
std::string DiffDrive() {
  return IndoorScenario("differential_drive", "diffdrive.xml", "",
                        "driver:\n  type: body_velocity\n  lead_in_s: 1.0\n  linear_mps:\n    - constant: 0.15\n"
                        "    - sine: {amplitude: 0.3, period_s: 4.0, phase_rad: 0.0}\n  angular_radps:\n"
                        "    - sine: {amplitude: 0.6, period_s: 5.0, phase_rad: 0.0}\nsensors:\n" +
                            std::string(kImuAndEncoders) +
                            "  mocap: {rate_hz: 20, position_sigma_m: 0.001, orientation_sigma_rad: 0.005}\n");
}

// Smooth forward, sideways and yaw set-points (scenarios/indoor_mecanum_gap.yaml, periods shortened).
std::string Mecanum() {
  return IndoorScenario("mecanum", "mecanum.xml", "",
                        "driver:\n  type: body_velocity\n  lead_in_s: 1.0\n  linear_mps:\n    - constant: 0.15\n"
                        "    - sine: {amplitude: 0.1, period_s: 3.0, phase_rad: 0.0}\n  lateral_mps:\n"
                        "    - sine: {amplitude: 0.1, period_s: 4.0, phase_rad: 1.0}\n  angular_radps:\n"
                        "    - sine: {amplitude: 0.4, period_s: 5.0, phase_rad: 0.0}\nsensors:\n" +
                            std::string(kImuAndEncoders) +
                            "  gps: {rate_hz: 10, sigma_m: 0.01, lever_arm_m: [0.0, 0.0, 0.1]}\n");
}

// Smooth set-points in the room, with the laser and no camera (scenarios/indoor_omni_slip.yaml without its square
// waves: the bound is the same analysis on a shorter, cheaper drive).
std::string Omni() {
  return IndoorScenario("omni3", "omni3.xml", "  model: " + roamlab::testing::SourceDir() + "/models/indoor_room.xml\n",
                        "driver:\n  type: body_velocity\n  lead_in_s: 1.0\n  linear_mps:\n"
                        "    - sine: {amplitude: 0.3, period_s: 3.0, phase_rad: 0.3}\n  lateral_mps:\n"
                        "    - sine: {amplitude: 0.2, period_s: 4.0, phase_rad: 1.1}\n  angular_radps:\n"
                        "    - sine: {amplitude: 0.8, period_s: 5.0, phase_rad: 0.5}\nsensors:\n" +
                            std::string(kImuAndEncoders) +
                            "  laser: {rate_hz: 10, beams: 683, fov_deg: 240, min_range_m: 0.02, max_range_m: 4.0, "
                            "sigma_m: 0.01}\n");
}

InformationRun Analyse(const std::string& scenario_text, const std::string& config, const testing::TempDir& dir) {
  std::ofstream(dir.File("scenario.yaml")) << scenario_text;
  InformationRequest request;
  request.scenario = dir.File("scenario.yaml");
  request.config = roamlab::testing::SourceDir() + "/configs/" + config;
  request.out = dir.File("out");
  InformationRun run;
  const Outcome outcome = InformationToDirectory(request, &run);
  EXPECT_TRUE(outcome.ok()) << outcome.status.message();
  return run;
}

double Sum(const std::map<std::string, double>& shares) {
  double sum = 0.0;
  for (const auto& [stream, share] : shares) sum += share;
  return sum;
}

double Sum(const std::vector<double>& shares) { return std::accumulate(shares.begin(), shares.end(), 0.0); }

// Every component: a finite positive bound; the variance shares by stream, by window and by stream and window, and
// the measured shares, each summing to 1; the stream-and-window shares adding up to the stream's and the window's.
void ExpectSplitsSumToTheTotal(const estimator::InformationResult& r) {
  for (const estimator::InformationComponent& c : r.components) {
    SCOPED_TRACE(c.label);
    EXPECT_TRUE(std::isfinite(c.crb_std));
    EXPECT_GT(c.crb_std, 0.0);
    EXPECT_NEAR(Sum(c.by_stream), 1.0, kSumTolerance);
    EXPECT_NEAR(Sum(c.by_window), 1.0, kSumTolerance);
    EXPECT_NEAR(Sum(c.measured_by), 1.0, kSumTolerance);
    ASSERT_EQ(c.by_window.size(), static_cast<std::size_t>(r.windows));
    std::vector<double> per_window(c.by_window.size(), 0.0);
    for (const auto& [stream, shares] : c.by_stream_window) {
      ASSERT_EQ(shares.size(), per_window.size());
      EXPECT_NEAR(Sum(shares), c.by_stream.at(stream), kSumTolerance) << stream;
      for (std::size_t k = 0; k < shares.size(); ++k) per_window[k] += shares[k];
    }
    for (std::size_t k = 0; k < per_window.size(); ++k) EXPECT_NEAR(per_window[k], c.by_window[k], kSumTolerance);
  }
}

// The labels of the analysed components.
std::vector<std::string> Labels(const estimator::InformationResult& r) {
  std::vector<std::string> out;
  for (const estimator::InformationComponent& c : r.components) out.push_back(c.label);
  return out;
}

TEST(InformationIndoorTest, DifferentialDriveSplitsSumToTheTotal) {
  testing::TempDir dir;
  const InformationRun run = Analyse(DiffDrive(), "indoor_diffdrive_mocap_calibration.yaml", dir);
  EXPECT_EQ(run.result.windows, 6);
  EXPECT_EQ(Labels(run.result),
            (std::vector<std::string>{"imu.misalignment[rx]", "imu.misalignment[ry]", "imu.misalignment[rz]",
                                      "odometer.baseline", "odometer.radius_left", "odometer.radius_right"}));
  ExpectSplitsSumToTheTotal(run.result);
  // The wheel radii and the baseline are read by the encoders: the odometer carries all of their measured share.
  for (const estimator::InformationComponent& c : run.result.components)
    if (c.parameter.rfind("odometer.", 0) == 0) {
      EXPECT_NEAR(c.measured_by.at("odometer"), 1.0, 1e-9) << c.label;
    }
}

TEST(InformationIndoorTest, MecanumSplitsSumToTheTotal) {
  testing::TempDir dir;
  const InformationRun run = Analyse(Mecanum(), "indoor_mecanum_calibration.yaml", dir);
  EXPECT_EQ(Labels(run.result),
            (std::vector<std::string>{"imu.misalignment[rx]", "imu.misalignment[ry]", "imu.misalignment[rz]",
                                      "odometer.lx_plus_ly", "odometer.radius_0", "odometer.radius_1",
                                      "odometer.radius_2", "odometer.radius_3"}));
  ExpectSplitsSumToTheTotal(run.result);
  for (const estimator::InformationParameter& p : run.result.parameters) EXPECT_TRUE(p.has_truth) << p.name;
}

TEST(InformationIndoorTest, OmniSplitsSumToTheTotal) {
  testing::TempDir dir;
  const InformationRun run = Analyse(Omni(), "indoor_omni_calibration.yaml", dir);
  EXPECT_EQ(
      Labels(run.result),
      (std::vector<std::string>{"imu.misalignment[rx]", "imu.misalignment[ry]", "imu.misalignment[rz]",
                                "odometer.distance", "odometer.radius_0", "odometer.radius_1", "odometer.radius_2"}));
  ExpectSplitsSumToTheTotal(run.result);
  // The scan matcher is the metric reference of the radii and the distance: its noise carries part of their variance.
  for (const estimator::InformationComponent& c : run.result.components)
    if (c.parameter.rfind("odometer.", 0) == 0) {
      EXPECT_GT(c.by_stream.at("scan_matching"), 0.05) << c.label;
    }
}

}  // namespace
}  // namespace roamlab::experiment
