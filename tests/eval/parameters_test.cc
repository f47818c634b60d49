#include "eval/parameters.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

#include "tests/recording/temp_dir.h"

namespace roamlab::eval {
namespace {

using ::roamlab::testing::TempDir;
using ::roamlab::testing::WriteFile;
using ::testing::HasSubstr;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = 180.0 / kPi;

std::vector<double> Wxyz(const Eigen::Quaterniond& q) { return {q.w(), q.x(), q.y(), q.z()}; }

Eigen::Quaterniond Exp(const Eigen::Vector3d& d) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(d.norm(), d.normalized()));
}

TEST(ParametersTest, VectorErrorAndErrorOverStd) {
  const Result<ParameterComparison> row =
      CompareParameter("gps.lever_arm", {1.0, 2.0, 3.0}, {ParameterKind::kVector, {1.1, 1.8, 3.0}, {0.1, 0.05, 0.0}});
  ASSERT_TRUE(row.ok()) << row.status().message();
  const ParameterComparison& r = row.value();
  ASSERT_EQ(r.error.size(), 3u);
  EXPECT_NEAR(r.error[0], 0.1, 1e-12);
  EXPECT_NEAR(r.error[1], -0.2, 1e-12);
  EXPECT_EQ(r.error[2], 0.0);
  EXPECT_NEAR(r.error_over_std[0], 1.0, 1e-10);
  EXPECT_NEAR(r.error_over_std[1], -4.0, 1e-10);
  EXPECT_TRUE(std::isnan(r.error_over_std[2]));  // zero std: no ratio
  EXPECT_TRUE(std::isnan(r.angle_error_deg));
  EXPECT_TRUE(r.component_error.empty());
}

TEST(ParametersTest, QuaternionOfAKnownRotation) {
  // Truth identity, estimate 10 deg about z: angle 10 deg, tangent error [0, 0, 10 deg in rad].
  const Eigen::Quaterniond q_est(Eigen::AngleAxisd(10.0 / kDeg, Eigen::Vector3d::UnitZ()));
  const Result<ParameterComparison> row = CompareParameter("imu.misalignment", {1.0, 0.0, 0.0, 0.0},
                                                           {ParameterKind::kQuaternion, Wxyz(q_est), {0.1, 0.1, 0.05}});
  ASSERT_TRUE(row.ok()) << row.status().message();
  const ParameterComparison& r = row.value();
  EXPECT_NEAR(r.angle_error_deg, 10.0, 1e-10);
  ASSERT_EQ(r.error.size(), 3u);
  EXPECT_NEAR(r.error[0], 0.0, 1e-14);
  EXPECT_NEAR(r.error[2], 10.0 / kDeg, 1e-12);
  EXPECT_NEAR(r.error_over_std[2], 10.0 / kDeg / 0.05, 1e-10);
  ASSERT_EQ(r.component_error.size(), 4u);
  EXPECT_NEAR(r.component_error[0], std::cos(5.0 / kDeg) - 1.0, 1e-12);
  EXPECT_NEAR(r.component_error[3], std::sin(5.0 / kDeg), 1e-12);
}

TEST(ParametersTest, QuaternionErrorIsTheBodyFrameTangentOfTheStd) {
  // q_est = q_true Exp(d): the error is d (right perturbation, as the calibration's std), for q_est and -q_est alike.
  const Eigen::Quaterniond q_true = Exp(Eigen::Vector3d(0.3, -0.6, 1.1));
  const Eigen::Vector3d d(0.01, -0.02, 0.03);
  const Eigen::Quaterniond q_est = q_true * Exp(d);
  for (double sign : {1.0, -1.0}) {
    std::vector<double> est = Wxyz(q_est);
    for (double& v : est) v *= sign;
    const Result<ParameterComparison> row = CompareParameter("q", Wxyz(q_true), {ParameterKind::kQuaternion, est, {}});
    ASSERT_TRUE(row.ok()) << row.status().message();
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(row.value().error[i], d[i], 1e-12);
    EXPECT_NEAR(row.value().angle_error_deg, d.norm() * kDeg, 1e-10);
    // Components compared on the same hemisphere: small.
    for (double c : row.value().component_error) EXPECT_LT(std::abs(c), d.norm());
    EXPECT_TRUE(std::isnan(row.value().error_over_std[0]));  // no std given
  }
}

TEST(ParametersTest, PoseComparesPositionAndRotation) {
  const Eigen::Quaterniond q_est(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX()));
  const Result<ParameterComparison> row = CompareParameter(
      "cam.pose", {1.0, 2.0, 3.0, 1.0, 0.0, 0.0, 0.0},
      {ParameterKind::kPose, {1.5, 2.0, 3.0, q_est.w(), q_est.x(), q_est.y(), q_est.z()}, {0.5, 1, 1, 0.1, 1, 1}});
  ASSERT_TRUE(row.ok()) << row.status().message();
  ASSERT_EQ(row.value().error.size(), 6u);
  EXPECT_NEAR(row.value().error[0], 0.5, 1e-12);
  EXPECT_NEAR(row.value().error[3], 0.1, 1e-12);
  EXPECT_NEAR(row.value().error_over_std[0], 1.0, 1e-12);
  EXPECT_NEAR(row.value().error_over_std[3], 1.0, 1e-10);
  EXPECT_NEAR(row.value().angle_error_deg, 0.1 * kDeg, 1e-10);
  EXPECT_EQ(row.value().component_error.size(), 7u);
}

TEST(ParametersTest, SizeMismatchesAreErrorsNamingTheParameter) {
  EXPECT_THAT(CompareParameter("a.b", {1.0, 2.0}, {ParameterKind::kVector, {1.0, 2.0, 3.0}, {}}).status().message(),
              HasSubstr("parameter 'a.b': truth has 2 values"));
  EXPECT_THAT(
      CompareParameter("q", {1, 0, 0, 0}, {ParameterKind::kQuaternion, {1, 0, 0, 0}, {1, 1, 1, 1}}).status().message(),
      HasSubstr("std has 4 values, expected 3"));
  EXPECT_THAT(CompareParameter("q", {0, 0, 0, 0}, {ParameterKind::kQuaternion, {1, 0, 0, 0}, {}}).status().message(),
              HasSubstr("zero quaternion"));
}

TEST(ParametersTest, CompareParametersSplitsByTruth) {
  std::vector<std::string> without_truth;
  const Result<std::vector<ParameterComparison>> rows = CompareParameters(
      {{"a", {1.0}}, {"only_truth", {2.0}}},
      {{"a", {ParameterKind::kVector, {1.5}, {0.25}}}, {"b", {ParameterKind::kVector, {0.0}, {}}}}, &without_truth);
  ASSERT_TRUE(rows.ok());
  ASSERT_EQ(rows.value().size(), 1u);
  EXPECT_EQ(rows.value()[0].name, "a");
  EXPECT_EQ(without_truth, std::vector<std::string>{"b"});
  const nlohmann::json table = ParameterTableJson(rows.value());
  EXPECT_EQ(table["a"]["error"][0], 0.5);
  EXPECT_EQ(table["a"]["error_over_std"][0], 2.0);
  EXPECT_EQ(table["a"]["manifold"], "R1");
}

TEST(ParametersTest, ManifoldNames) {
  EXPECT_EQ(ParameterKindFromManifold("R3"), ParameterKind::kVector);
  EXPECT_EQ(ParameterKindFromManifold("R12"), ParameterKind::kVector);
  EXPECT_EQ(ParameterKindFromManifold("S3"), ParameterKind::kQuaternion);
  EXPECT_EQ(ParameterKindFromManifold("SE3"), ParameterKind::kPose);
  EXPECT_FALSE(ParameterKindFromManifold("R").has_value());
  EXPECT_FALSE(ParameterKindFromManifold("R0").has_value());
  EXPECT_FALSE(ParameterKindFromManifold("SO3").has_value());
}

TEST(ParametersTest, ReadsCalibrationJson) {
  TempDir dir;
  WriteFile(dir.File("calibration.json"),
            R"({"parameters": {"gps.lever_arm": {"estimate": [0.6, -0.5, 0.3], "std": [0.04, 0.04, null],
                                                 "manifold": "R3"},
                               "imu.misalignment": {"estimate": [1, 0, 0, 0], "std": [0.01, 0.01, 0.01],
                                                    "manifold": "S3"},
                               "k": {"estimate": [0.8]}}})");
  const auto estimates = ReadCalibrationEstimates(dir.File("calibration.json"));
  ASSERT_TRUE(estimates.ok()) << estimates.status().message();
  const auto& e = estimates.value();
  ASSERT_EQ(e.size(), 3u);
  EXPECT_EQ(e.at("gps.lever_arm").estimate[1], -0.5);
  EXPECT_TRUE(std::isnan(e.at("gps.lever_arm").std[2]));
  EXPECT_EQ(e.at("imu.misalignment").kind, ParameterKind::kQuaternion);
  EXPECT_EQ(e.at("k").kind, ParameterKind::kVector);
  EXPECT_TRUE(e.at("k").std.empty());

  WriteFile(dir.File("bad.json"), R"({"parameters": {"x": {"estimate": "no"}}})");
  EXPECT_THAT(ReadCalibrationEstimates(dir.File("bad.json")).status().message(),
              HasSubstr("bad.json: parameter 'x': 'estimate' must be an array of numbers"));
  WriteFile(dir.File("broken.json"), "{");
  EXPECT_THAT(ReadCalibrationEstimates(dir.File("broken.json")).status().message(), HasSubstr("not valid JSON"));
}

}  // namespace
}  // namespace roamlab::eval
