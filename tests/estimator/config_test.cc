#include "estimator/config.h"

#include <gtest/gtest.h>

#include "tests/estimator/estimation_testing.h"

namespace roamlab::estimator {
namespace {

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  return text.replace(pos, from.size(), to);
}

void ExpectError(const std::string& yaml, const std::string& fragment) {
  const auto config = ParseEstimatorConfig(yaml, "est.yaml");
  ASSERT_FALSE(config.ok()) << "accepted a configuration that should fail with: " << fragment;
  EXPECT_NE(config.status().message().find("est.yaml"), std::string::npos) << config.status().message();
  EXPECT_NE(config.status().message().find(fragment), std::string::npos) << config.status().message();
}

TEST(ConfigTest, ParsesTheAtvConfiguration) {
  const auto config = ParseEstimatorConfig(testing::AtvConfigYaml({"gps.lever_arm"}), "est.yaml");
  ASSERT_TRUE(config.ok()) << config.status().message();
  EXPECT_EQ(config.value().master, "odometer");
  EXPECT_EQ(config.value().streams.size(), 5u);
  EXPECT_TRUE(config.value().parameters.at("gps.lever_arm").free);
  EXPECT_DOUBLE_EQ(config.value().streams.at("gps").noise.at("sigma_m"), 0.33);
}

TEST(ConfigTest, RejectsUnknownKeysModelsAndMissingNoise) {
  const std::string good = testing::AtvConfigYaml({});
  ExpectError(Replace(good, "master: odometer", "master: odometer\nwindow: 3"), "unknown key 'window'");
  // Errors carry the line: the stray key is on line 2.
  ExpectError(Replace(good, "master: odometer", "master: odometer\nwindow: 3"), "est.yaml:2:");
  ExpectError(Replace(good, "model: gps", "model: galileo"), "unknown model 'galileo'");
  ExpectError(Replace(good, "noise: {sigma_m: 0.33}", "noise: {sigma: 0.33}"), "unknown key 'sigma'");
  ExpectError(Replace(good, "noise: {sigma_m: 0.33}", "noise: {}"), "noise needs 'sigma_m'");
  ExpectError(Replace(good, "noise: {sigma_m: 0.33}", "noise: {sigma_m: -1}"), "must be positive");
  ExpectError(Replace(good, "master: odometer", "master: gps"), "must use an odometric model");
  ExpectError(Replace(good, "free: false}", "free: maybe}"), "must be true or false");
  ExpectError(Replace(good, "method: levenberg_marquardt", "method: newton"), "solver.method");
}

// A time-varying parameter's process: one sigma and tau for all three components, or one per component.
TEST(ConfigTest, ProcessSigmaAndTauAreOneNumberOrOnePerComponent) {
  const std::string good = testing::AtvConfigYaml({});
  // The parameter list precedes `streams:`.
  const auto parameter = [&](const std::string& process) {
    return Replace(good, "streams:\n",
                   "  odometer.disturbance: {value: [0, 0, 0], free: true, process: " + process + "}\nstreams:\n");
  };
  auto config = ParseEstimatorConfig(
      parameter("{type: gauss_markov, sigma: [0.006, 0.002, 0.025], tau_s: [0.7, 1.2, 1.8]}"), "est.yaml");
  ASSERT_TRUE(config.ok()) << config.status().message();
  const ProcessConfig& gm = config.value().parameters.at("odometer.disturbance").process;
  EXPECT_EQ(gm.type, ProcessConfig::Type::kGaussMarkov);
  EXPECT_TRUE(gm.sigma.isApprox(Eigen::Vector3d(0.006, 0.002, 0.025)));
  EXPECT_TRUE(gm.tau_s.isApprox(Eigen::Vector3d(0.7, 1.2, 1.8)));
  config = ParseEstimatorConfig(parameter("{type: random_walk, sigma: 1.0e-4}"), "est.yaml");
  ASSERT_TRUE(config.ok()) << config.status().message();
  EXPECT_TRUE(
      config.value().parameters.at("odometer.disturbance").process.sigma.isApprox(Eigen::Vector3d::Constant(1.0e-4)));
  ExpectError(parameter("{type: gauss_markov, sigma: [0.006, 0.002], tau_s: 1.0}"), "a list of 3 numbers");
  ExpectError(parameter("{type: gauss_markov, sigma: 0.01, tau_s: [0.7, -1.2, 1.8]}"), "tau_s must be positive");
  ExpectError(parameter("{type: gauss_markov, sigma: [0.01, 0, 0.01], tau_s: 1.0}"), "sigma must be positive");
}

// The spacing of a process's instances: absent means one per pose; given, a positive number of seconds, and only for a
// time-varying process.
TEST(ConfigTest, ProcessIntervalIsAPositiveNumberOfSeconds) {
  const std::string good = testing::AtvConfigYaml({});
  const auto parameter = [&](const std::string& process) {
    return Replace(good, "streams:\n",
                   "  odometer.disturbance: {value: [0, 0, 0], free: true, process: " + process + "}\nstreams:\n");
  };
  auto config = ParseEstimatorConfig(parameter("{type: gauss_markov, sigma: 0.01, tau_s: 1.0}"), "est.yaml");
  ASSERT_TRUE(config.ok()) << config.status().message();
  EXPECT_EQ(config.value().parameters.at("odometer.disturbance").process.interval_s, 0.0);
  config =
      ParseEstimatorConfig(parameter("{type: gauss_markov, sigma: 0.01, tau_s: 1.0, interval_s: 0.1}"), "est.yaml");
  ASSERT_TRUE(config.ok()) << config.status().message();
  EXPECT_DOUBLE_EQ(config.value().parameters.at("odometer.disturbance").process.interval_s, 0.1);
  config = ParseEstimatorConfig(parameter("{type: random_walk, sigma: 1.0e-4, interval_s: 0.5}"), "est.yaml");
  ASSERT_TRUE(config.ok()) << config.status().message();
  EXPECT_DOUBLE_EQ(config.value().parameters.at("odometer.disturbance").process.interval_s, 0.5);
  const std::string positive = "process.interval_s must be a positive number of seconds";
  ExpectError(parameter("{type: gauss_markov, sigma: 0.01, tau_s: 1.0, interval_s: 0}"), positive);
  ExpectError(parameter("{type: gauss_markov, sigma: 0.01, tau_s: 1.0, interval_s: -0.1}"), positive);
  ExpectError(parameter("{type: gauss_markov, sigma: 0.01, tau_s: 1.0, interval_s: .nan}"), positive);
  ExpectError(parameter("{type: gauss_markov, sigma: 0.01, tau_s: 1.0, interval_s: soon}"), "must be a number");
  ExpectError(parameter("{type: constant, interval_s: 0.1}"), "interval_s needs a random_walk or gauss_markov");
}

// The magnetometer's motor-interference proxy reads another recording stream through `inputs` (models/magnetometer.h);
// a model accepts only its own input roles.
TEST(ConfigTest, MagnetometerTakesTheSpecificForceInput) {
  const std::string good = testing::AtvConfigYaml({});
  const std::string mag = "options: {field_world: [0.0, 0.5, -0.8660254037844386]}";
  const auto config =
      ParseEstimatorConfig(Replace(good, mag, mag + ",\n                 inputs: {specific_force: imu}"), "est.yaml");
  ASSERT_TRUE(config.ok()) << config.status().message();
  EXPECT_EQ(config.value().streams.at("magnetometer").inputs.at("specific_force"), "imu");
  EXPECT_TRUE(config.value().streams.at("gps").inputs.empty());
  ExpectError(Replace(good, mag, mag + ",\n                 inputs: {torque: imu}"), "unknown key 'torque'");
  ExpectError(Replace(good, "noise: {sigma_m: 0.33}", "noise: {sigma_m: 0.33}, inputs: {specific_force: imu}"),
              "unknown key 'specific_force'");
}

// tracking.calibrate names a calibration configuration relative to the file that names it.
TEST(ConfigTest, TrackingCalibrateIsRelativeToTheConfigFile) {
  const std::string good = testing::AtvConfigYaml({});
  const std::string with = Replace(good, "master: odometer", "master: odometer\ntracking: {calibrate: cal.yaml}");
  const auto config = ParseEstimatorConfig(with, "configs/est.yaml");
  ASSERT_TRUE(config.ok()) << config.status().message();
  EXPECT_EQ(config.value().tracking.calibrate, "configs/cal.yaml");
  EXPECT_EQ(ParseEstimatorConfig(good, "est.yaml").value().tracking.calibrate, "");
  ExpectError(Replace(good, "master: odometer", "master: odometer\ntracking: {calibrate: ''}"),
              "tracking.calibrate must name a configuration file");
}

// tracking.relinearize_threshold: 0 by default, a non-negative number.
TEST(ConfigTest, TrackingRelinearizeThreshold) {
  const std::string good = testing::AtvConfigYaml({});
  EXPECT_EQ(ParseEstimatorConfig(good, "est.yaml").value().tracking.relinearize_threshold, 0.0);
  const auto config = ParseEstimatorConfig(
      Replace(good, "initialization_s: 1.0}", "initialization_s: 1.0, relinearize_threshold: 0.01}"), "est.yaml");
  ASSERT_TRUE(config.ok()) << config.status().message();
  EXPECT_EQ(config.value().tracking.relinearize_threshold, 0.01);
  ExpectError(Replace(good, "initialization_s: 1.0}", "initialization_s: 1.0, relinearize_threshold: -0.1}"),
              "tracking.relinearize_threshold must be >= 0");
}

}  // namespace
}  // namespace roamlab::estimator
