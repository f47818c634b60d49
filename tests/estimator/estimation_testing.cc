#include "tests/estimator/estimation_testing.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include <Eigen/Geometry>

#include <gtest/gtest.h>

namespace roamlab::estimator::testing {

std::string AtvConfigYaml(const std::vector<std::string>& free, int window) {
  // Nominal (initial) values for free parameters, true values (synthetic defaults) for fixed ones.
  const std::map<std::string, std::pair<std::string, std::string>> values = {
      {"gps.lever_arm", {"[0, 0, 0]", "[0.57, -0.46, 0.32]"}},
      {"imu.misalignment",
       {"[1, 0, 0, 0]",
        "[0.9382604033979289, 0.1040288720185337, 0.31308689367116393, "
        "0.1040288720185337]"}},
      {"magnetometer.A", {"[1, 0, 0, 0, 1, 0, 0, 0, 1]", "[0.87, -0.02, -0.02, 0, 0.88, 0, -0.02, -0.04, 0.85]"}},
      {"magnetometer.b", {"[0, 0, 0]", "[-0.008, -0.007, -0.04]"}},
      {"odometer.kv_over_L", {"0.8", "0.8"}},
      {"odometer.k_theta", {"1.0", "1.0"}},
      {"odometer.k_gamma", {"0.0", "0.0"}},
      {"imu.time_offset_s", {"0.0", "0.0"}},
  };
  std::string yaml =
      "master: odometer\n"
      "solver: {method: levenberg_marquardt, max_iterations: 100, function_tolerance: 1.0e-9}\n"
      "tracking: {window: " +
      std::to_string(window) +
      ", max_iterations: 5, improvement_threshold: 1.0e-3, time_budget_s: 1.0, initialization_s: 1.0}\n"
      "parameters:\n";
  for (const auto& [name, v] : values) {
    const bool is_free = std::find(free.begin(), free.end(), name) != free.end();
    yaml +=
        "  " + name + ": {value: " + (is_free ? v.first : v.second) + ", free: " + (is_free ? "true" : "false") + "}\n";
  }
  yaml += R"(streams:
  odometer:
    model: ackermann
    source: {speed: rear_wheel, steering: steering}
    noise: {speed_mps: 0.033, steering_rad: 0.014, lateral_mps: 0.02, vertical_mps: 0.02}
  gyroscope: {model: gyroscope, source: imu, noise: {sigma_radps: 0.033},
              parameters: {misalignment: imu.misalignment, time_offset_s: imu.time_offset_s}}
  accelerometer: {model: accelerometer, source: imu, noise: {sigma_mps2: 0.067},
                  parameters: {misalignment: imu.misalignment, time_offset_s: imu.time_offset_s}}
  magnetometer: {model: magnetometer, source: magnetometer, noise: {sigma: 0.067},
                 parameters: {misalignment: imu.misalignment, time_offset_s: imu.time_offset_s},
                 options: {field_world: [0.0, 0.5, -0.8660254037844386]}}
  gps: {model: gps, source: gps, noise: {sigma_m: 0.33}}
)";
  return yaml;
}

EstimatorConfig AtvConfig(const std::vector<std::string>& free, int window) {
  auto config = ParseEstimatorConfig(AtvConfigYaml(free, window), "atv_test.yaml");
  EXPECT_TRUE(config.ok()) << config.status().message();
  return config.value();
}

recording::Recording DiffDriveArcWithMotionCapture(int samples, double yaw0_rad, const Eigen::Vector2d& start_m) {
  recording::Recording rec;
  rec.platform.kind = "differential_drive";
  recording::Stream enc, mocap;
  enc.info.name = "wheels";
  enc.info.type = recording::StreamType::kWheelEncoders;
  enc.info.columns = {"left", "right"};
  enc.info.units = "rad";
  mocap.info.name = "mocap";
  mocap.info.type = recording::StreamType::kPose;
  enc.values.resize(samples, 2);
  mocap.values.resize(samples, 7);
  double yaw = yaw0_rad, left = 0.0, right = 0.0;
  Eigen::Vector2d p = start_m;
  const double v = 0.1, omega = 0.5;
  for (int k = 0; k < samples; ++k) {
    enc.t.push_back(Time::FromSeconds(k * kArcDt_s));
    mocap.t.push_back(Time::FromSeconds(k * kArcDt_s));
    enc.values.row(k) << left, right;
    const Eigen::Quaterniond q(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
    mocap.values.row(k) << p.x(), p.y(), 0.0, q.x(), q.y(), q.z(), q.w();
    left += (v - 0.5 * omega * kArcTrack_m) / kArcRadius_m * kArcDt_s;
    right += (v + 0.5 * omega * kArcTrack_m) / kArcRadius_m * kArcDt_s;
    p += v * kArcDt_s * Eigen::Vector2d(std::cos(yaw + 0.5 * omega * kArcDt_s), std::sin(yaw + 0.5 * omega * kArcDt_s));
    yaw += omega * kArcDt_s;
  }
  rec.streams = {enc, mocap};
  return rec;
}

std::string ArcConfigYaml(const ArcNoise& noise, const std::string& sections) {
  std::ostringstream yaml;
  yaml << "master: wheels\n"
       << sections << "parameters:\n"
       << "  wheels.radius: {value: [" << kArcRadius_m << "]}\n"
       << "  wheels.baseline: {value: [" << kArcTrack_m << "]}\n"
       << "streams:\n"
       << "  wheels:\n"
       << "    model: differential_drive\n"
       << "    source: wheels\n"
       << "    noise: {wheel_radps: " << noise.wheel_radps << ", lateral_mps: 0.002, vertical_mps: 0.002, "
       << "tilt_radps: 0.02}\n"
       << "    parameters: {radius_left: wheels.radius, radius_right: wheels.radius, baseline: wheels.baseline}\n"
       << "  mocap:\n"
       << "    model: absolute_pose\n"
       << "    source: mocap\n"
       << "    noise: {position_m: " << noise.position_m << ", orientation_rad: " << noise.orientation_rad << "}\n";
  return yaml.str();
}

}  // namespace roamlab::estimator::testing
