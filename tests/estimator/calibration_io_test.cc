#include "estimator/calibration_io.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/recording/temp_dir.h"

namespace roamlab::estimator {
namespace {

using ::roamlab::testing::TempDir;
using ::roamlab::testing::WriteFile;
using ::testing::HasSubstr;

// What WriteCalibrationFile writes, ReadCalibrationValues and ReadCalibrationPrior read back.
TEST(CalibrationIoTest, ValuesAndPriorRoundTrip) {
  TempDir dir;
  const std::string path = dir.File("calibration.json");
  CalibrationResult result;
  ParameterEstimate lever;
  lever.name = "gps.lever_arm";
  lever.manifold = Manifold::Euclidean(3);
  lever.estimate = Eigen::Vector3d(0.5, -0.25, 1.125);
  lever.std = Eigen::Vector3d(0.1, 0.2, 0.3);
  lever.components.assign(3, Observability::kObservable);
  ParameterEstimate offset = lever;
  offset.name = "imu.time_offset";
  offset.manifold = Manifold::Euclidean(1);
  offset.estimate = Eigen::VectorXd::Constant(1, 0.003);
  offset.std = Eigen::VectorXd::Constant(1, 0.001);
  offset.components.assign(1, Observability::kObservable);
  result.parameters = {lever, offset};
  result.information = Eigen::MatrixXd::Identity(4, 4) * 2.0;
  result.information(0, 3) = result.information(3, 0) = 0.5;
  ASSERT_TRUE(WriteCalibrationFile(result, "REC", "EST.yaml", path).ok());

  const auto read = ReadCalibrationValues(path);
  ASSERT_TRUE(read.ok()) << read.status().message();
  ASSERT_EQ(read.value().size(), 2u);
  EXPECT_EQ(read.value().at("gps.lever_arm"), lever.estimate);
  EXPECT_EQ(read.value().at("imu.time_offset"), offset.estimate);
  const auto read_prior = ReadCalibrationPrior(path);
  ASSERT_TRUE(read_prior.ok()) << read_prior.status().message();
  EXPECT_EQ(read_prior.value().names, (std::vector<std::string>{"gps.lever_arm", "imu.time_offset"}));
  EXPECT_EQ(read_prior.value().information, result.information);
}

TEST(CalibrationIoTest, BadFilesNameTheFileAndTheProblem) {
  TempDir dir;
  const std::string path = dir.File("calibration.json");
  EXPECT_THAT(ReadCalibrationValues(path).status().message(), HasSubstr(path + ": cannot open"));
  WriteFile(path, "{\"parameters\": {\"a\": {\"estimate\": [1, \"x\"]}}}");
  EXPECT_THAT(ReadCalibrationValues(path).status().message(),
              HasSubstr("parameter 'a': 'estimate' must be an array of numbers"));
  WriteFile(path, "{\"parameters\": {\"a\": {\"estimate\": [1]}}}");
  EXPECT_THAT(ReadCalibrationPrior(path).status().message(), HasSubstr("no 'information'"));
  WriteFile(path, "{\"parameters\": {}, \"information\": {\"parameters\": [\"a\"], \"matrix\": [[null]]}}");
  EXPECT_THAT(ReadCalibrationPrior(path).status().message(), HasSubstr("information.matrix has a non-number"));
  WriteFile(path, "{\"parameters\": {}, \"information\": {\"parameters\": [\"a\"], \"matrix\": [[1, 2]]}}");
  EXPECT_THAT(ReadCalibrationPrior(path).status().message(), HasSubstr("information.matrix must be square"));
  WriteFile(path, "not json");
  EXPECT_THAT(ReadCalibrationValues(path).status().message(), HasSubstr("not valid JSON"));
}

// Without tracking.calibration_prior no file is read; with it, a calibration file is required.
TEST(CalibrationIoTest, TrackingOptionsReadThePriorOnlyWhenAskedFor) {
  EstimatorConfig config;
  config.source_file = "est.yaml";
  config.tracking.calibration_prior = false;
  const auto without = TrackingOptionsFor(config, "");
  ASSERT_TRUE(without.ok());
  EXPECT_FALSE(without.value().calibration_prior);
  config.tracking.calibration_prior = true;
  EXPECT_THAT(TrackingOptionsFor(config, "").status().message(),
              HasSubstr("est.yaml: tracking.calibration_prior needs --calibration"));
}

}  // namespace
}  // namespace roamlab::estimator
