#include "estimator/model_registry.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "estimator/calibration.h"
#include "estimator/problem.h"
#include "examples/consumer/beacon_drive.h"
#include "examples/consumer/range_beacon.h"

namespace roamlab::estimator {
namespace {

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  return pos == std::string::npos ? text : text.replace(pos, from.size(), to);
}

// A beacon's options.beacon_world as BeaconDriveConfig writes it.
std::string BeaconWorld(const Eigen::Vector3d& p) {
  std::ostringstream text;
  text << "beacon_world: [" << p.x() << ", " << p.y() << ", " << p.z() << "]";
  return text.str();
}

// The example's range_beacon model (examples/consumer), registered once for every test.
class RangeBeaconTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { ASSERT_TRUE(beacon::RegisterRangeBeaconModel().ok()); }
  beacon::BeaconDriveOptions drive_;
  recording::Recording rec_ = beacon::SimulateBeaconDrive(drive_);
};

// Builds the problem of `yaml` on the drive's recording; the error message, "" when it builds.
std::string BuildError(const std::string& yaml, const recording::Recording& rec) {
  const auto config = ParseEstimatorConfig(yaml, "beacon.yaml");
  if (!config.ok()) return config.status().message();
  const auto builder = ProblemBuilder::Create(config.value(), rec);
  return builder.ok() ? "" : builder.status().message();
}

TEST(ModelRegistryTest, HoldsTheBuiltInModelsWithTheirTraits) {
  const std::vector<std::string> names = ErrorModelNames();
  for (const char* model : {"ackermann", "ackermann_seed", "differential_drive", "omni3_drive", "mecanum_drive",
                            "omni4_drive", "tricycle_drive", "odometer", "relative_motion", "gyroscope",
                            "accelerometer", "magnetometer", "gps", "absolute_pose", "linear_velocity"}) {
    const ErrorModelDefinition* d = FindErrorModel(model);
    ASSERT_NE(d, nullptr) << model;
    EXPECT_NE(std::find(names.begin(), names.end(), model), names.end()) << model;
    EXPECT_FALSE(d->bind) << model << ": the builder makes the built-in models' factors";
    EXPECT_EQ(d->absolute, std::string(model) == "gps" || std::string(model) == "absolute_pose") << model;
  }
  EXPECT_EQ(FindErrorModel("galileo"), nullptr);
  EXPECT_EQ(FindErrorModel("accelerometer")->attachment, ModelAttachment::kTriple);
  EXPECT_EQ(FindErrorModel("relative_motion")->attachment, ModelAttachment::kInterval);
  EXPECT_EQ(FindErrorModel("mecanum_drive")->residual_dim, 7);
  // The non-holonomic pseudo-measurement reads no values: a built-in model that binds as a user model does.
  const ErrorModelDefinition* non_holonomic = FindErrorModel("non_holonomic");
  ASSERT_NE(non_holonomic, nullptr);
  EXPECT_TRUE(non_holonomic->bind);
  EXPECT_EQ(non_holonomic->attachment, ModelAttachment::kPair);
  EXPECT_EQ(non_holonomic->residual_dim, 2);
  EXPECT_FALSE(non_holonomic->absolute);
  EXPECT_FALSE(non_holonomic->spec.odometric);
}

TEST(ModelRegistryTest, BuiltInNoiseCovarianceRepeatsTheKeysInTheModelsOrder) {
  StreamConfig config;
  config.noise = {{"wheel_radps", 0.1}, {"lateral_mps", 0.2}, {"vertical_mps", 0.3}, {"tilt_radps", 0.4}};
  const Eigen::MatrixXd covariance = FindErrorModel("differential_drive")->noise_covariance(config);
  Eigen::VectorXd sigma(6);
  sigma << 0.1, 0.1, 0.2, 0.3, 0.4, 0.4;
  EXPECT_TRUE(covariance.isApprox(Eigen::MatrixXd(sigma.cwiseAbs2().asDiagonal()))) << covariance;
  // Without a layout of its own, a model's noise is the keys' squares in the spec's order.
  config.noise = {{"speed_mps", 1.0}, {"steering_rad", 2.0}, {"lateral_mps", 3.0}, {"vertical_mps", 4.0}};
  EXPECT_TRUE(FindErrorModel("ackermann")->noise_covariance(config).diagonal().isApprox(Eigen::Vector4d(1, 4, 9, 16)));
}

TEST(ModelRegistryTest, RefusesTakenNamesAndDefinitionsItCannotBuild) {
  const auto bind = [](const ModelBindContext&) -> Result<std::unique_ptr<BoundErrorModel>> {
    return Status::Error("never bound");
  };
  ErrorModelDefinition d;
  d.spec = {"gps", {""}, {"sigma_m"}, {}, {}, false, {}};
  d.residual_dim = 1;
  d.bind = bind;
  EXPECT_NE(RegisterErrorModel(d).message().find("'gps' is already registered"), std::string::npos);
  d.spec.name = "registry_test_model";
  d.bind = nullptr;
  EXPECT_NE(RegisterErrorModel(d).message().find("no bind"), std::string::npos);
  d.bind = bind;
  d.spec.odometric = true;
  EXPECT_NE(RegisterErrorModel(d).message().find("cannot be odometric"), std::string::npos);
  d.spec.odometric = false;
  d.attachment = ModelAttachment::kInterval;
  EXPECT_NE(RegisterErrorModel(d).message().find("interval"), std::string::npos);
  d.attachment = ModelAttachment::kPair;
  d.residual_dim = 0;
  EXPECT_NE(RegisterErrorModel(d).message().find("residual_dim"), std::string::npos);
  EXPECT_EQ(FindErrorModel("registry_test_model"), nullptr);
}

TEST_F(RangeBeaconTest, IsUsedByNameFromTheConfiguration) {
  const auto config = ParseEstimatorConfig(beacon::BeaconDriveConfig(drive_), "beacon.yaml");
  ASSERT_TRUE(config.ok()) << config.status().message();
  const Eigen::Vector3d& beacon = drive_.beacons_world[1];
  EXPECT_EQ(config.value().streams.at("uwb_1").options.at("beacon_world"),
            (std::vector<double>{beacon.x(), beacon.y(), beacon.z()}));
  const auto builder = ProblemBuilder::Create(config.value(), rec_);
  ASSERT_TRUE(builder.ok()) << builder.status().message();
  EXPECT_EQ(builder.value()->ResidualDim("uwb_0"), 1);
  EXPECT_TRUE(builder.value()->has_absolute_sensor());
  // The unknown-model message lists the registered models, the user's among them.
  const auto unknown =
      ParseEstimatorConfig(Replace(beacon::BeaconDriveConfig(drive_), "range_beacon", "range_beaco"), "beacon.yaml");
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.status().message().find("unknown model 'range_beaco' (registered: "), std::string::npos);
  EXPECT_NE(unknown.status().message().find("range_beacon"), std::string::npos) << unknown.status().message();
}

TEST_F(RangeBeaconTest, ConfigurationErrorsNameTheFileStreamAndKey) {
  const std::string good = beacon::BeaconDriveConfig(drive_);
  const std::string first = BeaconWorld(drive_.beacons_world[0]);
  // The parser reads the model's keys from its spec: an option it does not declare is refused.
  EXPECT_NE(BuildError(Replace(good, "options: {" + first, "options: {beacon:" + first.substr(13)), rec_)
                .find("unknown key 'beacon'"),
            std::string::npos);
  // The model's bind checks its options and its recording stream; the builder names the file and stream.
  EXPECT_NE(BuildError(Replace(good, "    options: {" + first + "}\n", ""), rec_)
                .find("beacon.yaml: stream 'uwb_0': range_beacon needs options.beacon_world"),
            std::string::npos);
  EXPECT_NE(BuildError(Replace(good, first, "beacon_world: [10, 0]"), rec_).find("needs options.beacon_world"),
            std::string::npos);
  EXPECT_NE(BuildError(Replace(good, "source: uwb_0", "source: odometer"), rec_)
                .find("stream 'uwb_0': recording stream 'odometer' must be an inputs stream"),
            std::string::npos);
  EXPECT_NE(BuildError(Replace(good, "noise: {sigma_m: 0.05}", "noise: {}"), rec_).find("noise needs 'sigma_m'"),
            std::string::npos);
}

// The offline calibration with the user model finds the antenna's lever arm within four of its standard deviations,
// every range sample attached.
TEST_F(RangeBeaconTest, CalibratesTheLeverArmOfTheRangingAntenna) {
  const auto config = ParseEstimatorConfig(beacon::BeaconDriveConfig(drive_), "beacon.yaml");
  ASSERT_TRUE(config.ok()) << config.status().message();
  const auto result = Calibrate(config.value(), rec_);
  ASSERT_TRUE(result.ok()) << result.status().message();
  for (int b = 0; b < 3; ++b) {
    const std::string stream = "uwb_" + std::to_string(b);
    EXPECT_EQ(result.value().counts.at(stream).attached, static_cast<int>(rec_.Find(stream)->t.size())) << stream;
  }
  const auto lever = std::find_if(result.value().parameters.begin(), result.value().parameters.end(),
                                  [](const ParameterEstimate& p) { return p.name == "antenna.lever_arm"; });
  ASSERT_NE(lever, result.value().parameters.end());
  for (int i = 0; i < 2; ++i) {
    ASSERT_TRUE(std::isfinite(lever->std[i]) && lever->std[i] > 0.0)
        << i << " estimate " << lever->estimate.transpose() << " std " << lever->std.transpose() << " obs "
        << ObservabilityName(lever->components[i]) << " " << result.value().termination << " cost "
        << result.value().final_cost;
    EXPECT_NEAR(lever->estimate[i], drive_.p_body_antenna[i], 4.0 * lever->std[i]) << i;
  }
  // The configuration's prior holds the height at its value.
  EXPECT_NEAR(lever->estimate[2], drive_.p_body_antenna.z(), 4.0 * 0.001);
}

}  // namespace
}  // namespace roamlab::estimator
