#include "estimator/config.h"

#include <algorithm>
#include <set>
#include <string>

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

TEST(ConfigTest, StreamsReadAreTheStreamsSources) {
  const auto config = ParseEstimatorConfig(testing::AtvConfigYaml({"gps.lever_arm"}), "est.yaml");
  ASSERT_TRUE(config.ok()) << config.status().message();
  const std::set<std::string> read = StreamsRead(config.value());
  EXPECT_EQ(read, (std::set<std::string>{"gps", "imu", "magnetometer", "rear_wheel", "steering"}));
}

// The calibration's gate starts under Huber's loss unless the configuration turns it off.
TEST(ConfigTest, GatingRobustStartIsOnUnlessTurnedOff) {
  const std::string good = testing::AtvConfigYaml({});
  const auto by_default = ParseEstimatorConfig(
      Replace(good, "master: odometer", "master: odometer\ngating: {probability: 0.999}"), "est.yaml");
  ASSERT_TRUE(by_default.ok()) << by_default.status().message();
  EXPECT_TRUE(by_default.value().gate_robust_start);
  const auto off = ParseEstimatorConfig(
      Replace(good, "master: odometer", "master: odometer\ngating: {probability: 0.999, robust_start: false}"),
      "est.yaml");
  ASSERT_TRUE(off.ok()) << off.status().message();
  EXPECT_FALSE(off.value().gate_robust_start);
  ExpectError(Replace(good, "master: odometer", "master: odometer\ngating: {probability: 0.999, robust_start: 3}"),
              "gating.robust_start");
}

// A stream is gated unless its configuration says `gate: false`.
TEST(ConfigTest, AStreamIsGatedUnlessItSaysGateFalse) {
  const std::string good = testing::AtvConfigYaml({});
  const auto by_default = ParseEstimatorConfig(good, "est.yaml");
  ASSERT_TRUE(by_default.ok()) << by_default.status().message();
  EXPECT_TRUE(by_default.value().streams.at("gps").gated);
  const std::string fixes = "noise: {sigma_m: 0.33}";
  const auto off = ParseEstimatorConfig(Replace(good, fixes, fixes + ", gate: false"), "est.yaml");
  ASSERT_TRUE(off.ok()) << off.status().message();
  EXPECT_FALSE(off.value().streams.at("gps").gated);
  EXPECT_TRUE(off.value().streams.at("odometer").gated);
  ExpectError(Replace(good, fixes, fixes + ", gate: sometimes"), "stream 'gps'.gate");
}

TEST(ConfigTest, SolverDampsEveryVariableUnlessItSaysParameters) {
  const std::string good = testing::AtvConfigYaml({});
  const auto by_default = ParseEstimatorConfig(good, "est.yaml");
  ASSERT_TRUE(by_default.ok()) << by_default.status().message();
  EXPECT_EQ(by_default.value().solver.damping, SolverOptions::Damping::kAll);
  const std::string method = "method: levenberg_marquardt";
  const auto parameters = ParseEstimatorConfig(Replace(good, method, method + ", damping: parameters"), "est.yaml");
  ASSERT_TRUE(parameters.ok()) << parameters.status().message();
  EXPECT_EQ(parameters.value().solver.damping, SolverOptions::Damping::kParameters);
  ExpectError(Replace(good, method, method + ", damping: poses"), "solver.damping must be all or parameters");
}

TEST(ConfigTest, RejectsUnknownKeysModelsAndMissingNoise) {
  const std::string good = testing::AtvConfigYaml({});
  ExpectError(Replace(good, "master: odometer", "master: odometer\nwindow: 3"), "unknown key 'window'");
  // Errors carry the line: the stray key is on line 2.
  ExpectError(Replace(good, "master: odometer", "master: odometer\nwindow: 3"), "est.yaml:2:");
  ExpectError(Replace(good, "model: gps", "model: galileo"), "unknown model 'galileo'");
  ExpectError(Replace(good, "noise: {sigma_m: 0.33}", "noise: {sigma: 0.33}"), "unknown key 'sigma'");
  ExpectError(Replace(good, "noise: {sigma_m: 0.33}", "noise: {}"), "noise needs 'sigma_m'");
  ExpectError(Replace(good, "noise: {sigma_m: 0.33}", "noise: {sigma_m: -1}"), "range [1e-9, 1e6] of a standard");
  ExpectError(Replace(good, "master: odometer", "master: gps"), "must use an odometric model");
  ExpectError(Replace(good, "free: false}", "free: maybe}"), "must be true or false");
  ExpectError(Replace(good, "method: levenberg_marquardt", "method: newton"), "solver.method");
}

// Noise and values are range-checked at load, naming the file, line and key: a sigma whose square underflows would
// otherwise reach the graph as a singular covariance.
TEST(ConfigTest, RefusesNoiseAndValuesOutsideThePhysicalRange) {
  const std::string good = testing::AtvConfigYaml({"gps.lever_arm"});
  ExpectError(Replace(good, "noise: {sigma_m: 0.33}", "noise: {sigma_m: 1e-300}"),
              "noise.sigma_m: 1e-300 is outside the accepted range");
  ExpectError(Replace(good, "noise: {sigma_m: 0.33}", "noise: {sigma_m: 1e300}"), "noise.sigma_m: 1e300 is beyond");
  ExpectError(Replace(good, "noise: {sigma_m: 0.33}", "noise: {sigma_m: .nan}"), "must be a finite number");
  ExpectError(Replace(good, "noise: {sigma_m: 0.33}", "noise: {sigma_m: .inf}"), "must be a finite number");
  ExpectError(Replace(good, "{value: [0, 0, 0], free: true}", "{value: [9.2e18, 0, 0], free: true}"),
              "gps.lever_arm.value: 9.2e18 is beyond the physical range");
  ExpectError(Replace(good, "{value: [0, 0, 0], free: true}", "{value: [.nan, 0, 0], free: true}"),
              "must be a finite number");
  // prior_sigma keeps .inf ("no prior on this component").
  const auto config = ParseEstimatorConfig(
      Replace(good, "{value: [0, 0, 0], free: true}", "{value: [0, 0, 0], free: true, prior_sigma: [.inf, .inf, 0.5]}"),
      "est.yaml");
  ASSERT_TRUE(config.ok()) << config.status().message();
}

// A slot mapped to a parameter nobody declares or shares is a typo: refused instead of silently running a different
// model.
TEST(ConfigTest, RefusesUndeclaredParameterNames) {
  const std::string good = testing::AtvConfigYaml({});
  const std::string gyro = "parameters: {misalignment: imu.misalignment, time_offset_s: imu.time_offset_s}}";
  ExpectError(Replace(good, gyro, "parameters: {misalignment: imu.misalignmnet, time_offset_s: imu.time_offset_s}}"),
              "names parameter 'imu.misalignmnet', which no parameters: entry declares");
  ExpectError(Replace(good, gyro, "parameters: {misalignment: nan, time_offset_s: imu.time_offset_s}}"),
              "names parameter 'nan'");
  // The default name and a name shared by several slots stay accepted.
  EXPECT_TRUE(
      ParseEstimatorConfig(
          Replace(good, gyro, "parameters: {misalignment: gyroscope.misalignment, time_offset_s: imu.time_offset_s}}"),
          "est.yaml")
          .ok());
}

// `roamlab design`'s target of a free parameter: one standard deviation for every tangent component. A target on a
// fixed parameter, a list, zero or an unknown spelling are refused naming the file and the parameter's line.
TEST(ConfigTest, TargetStdIsOnePositiveStdOfAFreeParameter) {
  const std::string good = testing::AtvConfigYaml({"gps.lever_arm"});
  const std::string free_lever_arm = "{value: [0, 0, 0], free: true}";
  const auto with = [&](const std::string& entry) { return Replace(good, free_lever_arm, entry); };
  auto config = ParseEstimatorConfig(with("{value: [0, 0, 0], free: true, target_std: 0.033}"), "est.yaml");
  ASSERT_TRUE(config.ok()) << config.status().message();
  EXPECT_DOUBLE_EQ(config.value().parameters.at("gps.lever_arm").target_std.value(), 0.033);
  EXPECT_FALSE(config.value().parameters.at("imu.misalignment").target_std.has_value());

  // The lever arm's line, 1-based.
  const std::string line = std::to_string(
      1 + std::count(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(good.find(free_lever_arm)), '\n'));
  const std::string at = "est.yaml:" + line + ": ";
  ExpectError(with("{value: [0, 0, 0], free: true, target_std: 0}"), at + "parameters.gps.lever_arm.target_std: 0 is");
  ExpectError(with("{value: [0, 0, 0], free: true, target_std: -0.1}"), "target_std: -0.1 is outside the accepted");
  ExpectError(with("{value: [0, 0, 0], free: true, target_std: abc}"), "target_std must be a number");
  ExpectError(with("{value: [0, 0, 0], free: true, target_std: [0.1, 0.1, 0.1]}"), at + "parameters.gps.lever_arm");
  ExpectError(with("{value: [0, 0, 0], free: false, target_std: 0.033}"),
              at + "parameter 'gps.lever_arm': target_std is for a free parameter");
  ExpectError(with("{value: [0, 0, 0], free: true, target: 0.033}"), at + "unknown key 'target'");
}

TEST(ConfigTest, RefusesDuplicateKeys) {
  const std::string good = testing::AtvConfigYaml({});
  ExpectError(Replace(good, "master: odometer", "master: odometer\nmaster: gps"), "est.yaml:2: duplicate key 'master'");
  ExpectError(Replace(good, "noise: {sigma_m: 0.33}", "noise: {sigma_m: 0.33, sigma_m: 3.3}"),
              "duplicate key 'sigma_m'");
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
  ExpectError(parameter("{type: gauss_markov, sigma: [0.01, 0, 0.01], tau_s: 1.0}"),
              "process sigma must be in [1e-9, 1e6]");
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
  ExpectError(parameter("{type: gauss_markov, sigma: 0.01, tau_s: 1.0, interval_s: .nan}"), "must be a finite number");
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
  const std::string with = Replace(good, "tracking: {", "tracking: {calibrate: cal.yaml, ");
  const auto config = ParseEstimatorConfig(with, "configs/est.yaml");
  ASSERT_TRUE(config.ok()) << config.status().message();
  EXPECT_EQ(config.value().tracking.calibrate, "configs/cal.yaml");
  EXPECT_EQ(ParseEstimatorConfig(good, "est.yaml").value().tracking.calibrate, "");
  ExpectError(Replace(good, "tracking: {", "tracking: {calibrate: '', "),
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
