#include "importers/optiodom.h"

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "recording/wheel_kinematics.h"
#include "tests/recording/temp_dir.h"
#include "tests/support/real_data.h"

namespace roamlab::importers {
namespace {

using ::roamlab::recording::Recording;
using ::roamlab::recording::Stream;
using ::roamlab::recording::StreamType;
using ::roamlab::testing::TempDir;
using ::roamlab::testing::WriteFile;
using ::testing::HasSubstr;

const std::string kData = ::roamlab::testing::RealData("optiodom/data");

// Writes <dir>/set_metadata.csv and <dir>/set_run-01.csv; returns the import's result.
Result<Recording> ImportWritten(const TempDir& dir, const std::string& metadata, const std::string& run) {
  WriteFile(dir.File("set_metadata.csv"), metadata);
  WriteFile(dir.File("set_run-01.csv"), run);
  return ImportOptiOdom(dir.File("set_run-01.csv"), dir.File("set_metadata.csv"));
}

const std::string kTricycleMetadata =
    "type,tricyc,\nngear,1,\nencRes,1600,\nLi,0.15,\nDi,0.065,\nThi,-0.02,\nN,2,\nL,,\nimarkers,5,1\n";
const std::string kOmni4Metadata =
    "type,omni4,,,\nngear,1,,,\nencRes,1,,,\nLi,0.2,0.22,,\nDi,0.06,0.061,0.062,0.063\nThi,,,,\nN,4,,,\n";

TEST(OptiOdomImportTest, TricycleRunGivesWheelAndSteeringStreams) {
  TempDir dir;
  auto rec =
      ImportWritten(dir, kTricycleMetadata, "0,0,0,0,0,0\n0.05,0.001,0,0.01,40,0.1\n0.1,0.002,0.0005,0.02,41,-0.2\n");
  ASSERT_TRUE(rec.ok()) << rec.status().message();
  const Recording& r = rec.value();
  EXPECT_EQ(r.platform.kind, "tricycle");
  EXPECT_DOUBLE_EQ(r.platform.geometry.at("wheel_to_axle_m"), 0.15);
  EXPECT_DOUBLE_EQ(r.platform.geometry.at("wheel_radius_front_m"), 0.0325);
  EXPECT_DOUBLE_EQ(r.platform.geometry.at("steering_offset_rad"), -0.02);
  const Stream* wheel = r.Find("wheel_encoders");
  const Stream* steering = r.Find("steering");
  ASSERT_NE(wheel, nullptr);
  ASSERT_NE(steering, nullptr);
  EXPECT_EQ(wheel->info.columns, std::vector<std::string>{"front"});
  EXPECT_NEAR(wheel->values(2, 0), 2.0 * M_PI * 81.0 / 1600.0, 1e-12);
  EXPECT_EQ(steering->info.type, StreamType::kSteering);
  EXPECT_EQ(steering->info.units, "rad");
  EXPECT_DOUBLE_EQ(steering->values(1, 0), 0.1);
  EXPECT_DOUBLE_EQ(steering->values(2, 0), -0.2);
  ASSERT_TRUE(r.ground_truth.has_value());
  EXPECT_EQ(r.ground_truth->size(), 3u);
}

TEST(OptiOdomImportTest, Omni4RunGivesFourNamedWheelsAndTheLayoutGeometry) {
  TempDir dir;
  auto rec = ImportWritten(dir, kOmni4Metadata, "0,0,0,0,-0,-0,-0,-0\n0.01,0,0,0,0.005,-0.003,0.005,-0.003\n");
  ASSERT_TRUE(rec.ok()) << rec.status().message();
  const Recording& r = rec.value();
  EXPECT_EQ(r.platform.kind, "omni4");
  EXPECT_DOUBLE_EQ(r.platform.geometry.at("wheelbase_m"), 0.2);
  EXPECT_DOUBLE_EQ(r.platform.geometry.at("track_m"), 0.22);
  EXPECT_DOUBLE_EQ(r.platform.geometry.at("wheel_radius_rear_right_m"), 0.0315);
  const Stream* wheels = r.Find("wheel_encoders");
  ASSERT_NE(wheels, nullptr);
  EXPECT_EQ(wheels->info.columns, (std::vector<std::string>{"front_left", "front_right", "rear_left", "rear_right"}));
  EXPECT_NEAR(wheels->values(1, 1), -2.0 * M_PI * 0.003, 1e-12);
  EXPECT_EQ(r.Find("steering"), nullptr);
}

TEST(OptiOdomImportTest, BadMetadataIsOneLineNamingTheFileAndTheProblem) {
  const std::string run4 = "0,0,0,0,0,0,0,0\n0.01,0,0,0,1,1,1,1\n";
  const std::string run_tricycle = "0,0,0,0,0,0\n0.05,0,0,0,1,0.1\n";
  struct Case {
    std::string metadata, run, problem;
  };
  const std::vector<Case> cases = {
      {"type,omni4\nngear,1\nencRes,1\nDi,0.06,0.06,0.06,0.06\n", run4, "missing key 'Li'"},
      {"type,omni4\nngear,1\nencRes,1\nLi,0.2,0.2\n", run4, "missing key 'Di'"},
      {"type,omni4\nngear,1\nencRes,1\nLi,0.2,0.2\nDi,0.06,0.06,0.06\n", run4,
       "Di has 3 diameters, type omni4 needs 4"},
      {"type,omni4\nngear,1\nencRes,1\nLi,0.2\nDi,0.06,0.06,0.06,0.06\n", run4,
       "Li has 1 distances, type omni4 needs 2"},
      {"type,tricyc\nngear,1\nencRes,1600\nLi,0.15\nDi,0.065,0.065\nThi,0\n", run_tricycle,
       "Di has 2 diameters, type tricyc needs 1"},
      {"type,tricyc\nngear,1\nencRes,1600\nLi,0.15\nDi,0.065\nThi,,\n", run_tricycle, "missing key 'Thi' (no value)"},
      {"type,tricyc\nngear,1\nencRes,1600\nLi,0.15\nDi,0.065\nThi,left\n", run_tricycle,
       "Thi: 'left' is not a finite number"},
      {"type,omni5\nngear,1\nencRes,1\nLi,0.2\nDi,0.06\n", run4, "type 'omni5' is not supported"},
      {kTricycleMetadata, run4, "8 columns, expected 6 (t, x, y, theta, front wheel ticks, steering angle)"},
      // A key given twice: the last no longer wins silently.
      {"type,tricyc\nngear,1\nencRes,1600\nLi,0.15\nDi,0.065\nThi,0\nLi,0.3\n", run_tricycle,
       ":7: duplicate key 'Li'"},
      {"type,tricyc\ntype,diff\nngear,1\nencRes,1600\nLi,0.15\nDi,0.065\nThi,0\n", run_tricycle,
       ":2: duplicate key 'type'"},
      {"type,tricyc\nngear,1\nencRes,1600\nLi,9.2e18\nDi,0.065\nThi,0\n", run_tricycle,
       "Li: 9.2e18 is outside the physical range"},
      // A stamp past the int64 nanoseconds (it used to overflow in the conversion).
      {kTricycleMetadata, "0,0,0,0,0,0\n9300000000,0,0,0,1,0.1\n", "set_run-01.csv:2: time 9300000000 s is outside"},
  };
  for (const Case& c : cases) {
    TempDir dir;
    auto rec = ImportWritten(dir, c.metadata, c.run);
    ASSERT_FALSE(rec.ok()) << c.problem;
    EXPECT_THAT(rec.status().message(), HasSubstr(c.problem));
    EXPECT_THAT(rec.status().message(), HasSubstr("set_"));
    EXPECT_EQ(rec.status().message().find('\n'), std::string::npos);
  }
}

double Yaw(const Stream& mocap, Eigen::Index k) { return 2.0 * std::atan2(mocap.values(k, 5), mocap.values(k, 6)); }

// Correlation and least-squares slope of y on x.
std::pair<double, double> CorrelationAndSlope(const std::vector<double>& x, const std::vector<double>& y) {
  double sxx = 0, syy = 0, sxy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxx += x[i] * x[i];
    syy += y[i] * y[i];
    sxy += x[i] * y[i];
  }
  return {sxy / std::sqrt(sxx * syy), sxy / sxx};
}

TEST(OptiOdomImportTest, RealOmni4RunFollowsTheDocumentedLayout) {
  const std::string set = kData + "/omni4/square/080920201205/080920201205";
  if (!std::filesystem::exists(set + "_metadata.csv")) GTEST_SKIP() << "real data absent: " << set;
  auto rec = ImportOptiOdom(set + "_run-01.csv", set + "_metadata.csv");
  ASSERT_TRUE(rec.ok()) << rec.status().message();
  const Stream& wheels = *rec.value().Find("wheel_encoders");
  const Stream& mocap = *rec.value().Find("mocap");
  EXPECT_EQ(rec.value().platform.kind, "omni4");
  EXPECT_EQ(wheels.values.rows(), 5824);
  // Each wheel's angle increments over 0.2 s against the increments the layout's rows predict from the mocap
  // displacement in the body frame: the same sign and a close linear relation (the scale is the learner's).
  const Eigen::Matrix<double, 4, 3> rows = recording::Omni4RatesFromTwist(Eigen::Vector4d::Ones(), 0.2, 0.2);
  std::vector<double> predicted[4], measured[4];
  for (Eigen::Index k = 0; k + 20 < wheels.values.rows(); k += 20) {
    const double yaw0 = Yaw(mocap, k), dyaw = std::remainder(Yaw(mocap, k + 20) - yaw0, 2.0 * M_PI);
    const Eigen::Vector2d d_world = (mocap.values.row(k + 20) - mocap.values.row(k)).head<2>().transpose();
    const Eigen::Vector2d d_body = Eigen::Rotation2Dd(-(yaw0 + 0.5 * dyaw)) * d_world;
    const Eigen::Vector4d rim = rows * Eigen::Vector3d(d_body.x(), d_body.y(), dyaw);
    for (int i = 0; i < 4; ++i) {
      predicted[i].push_back(rim[i]);
      measured[i].push_back(0.03 * (wheels.values(k + 20, i) - wheels.values(k, i)));
    }
  }
  for (int i = 0; i < 4; ++i) {
    const auto [correlation, slope] = CorrelationAndSlope(predicted[i], measured[i]);
    EXPECT_GT(correlation, 0.95) << wheels.info.columns[static_cast<std::size_t>(i)];
    EXPECT_GT(slope, 0.5) << wheels.info.columns[static_cast<std::size_t>(i)];
  }
}

TEST(OptiOdomImportTest, RealTricycleRunTurnsWithTheSteeringSign) {
  const std::string set = kData + "/tricyc/circular/140120211415/140120211415";
  if (!std::filesystem::exists(set + "_metadata.csv")) GTEST_SKIP() << "real data absent: " << set;
  auto rec = ImportOptiOdom(set + "_run-01.csv", set + "_metadata.csv");
  ASSERT_TRUE(rec.ok()) << rec.status().message();
  const Recording& r = rec.value();
  EXPECT_EQ(r.platform.kind, "tricycle");
  const Stream& wheel = *r.Find("wheel_encoders");
  const Stream& steering = *r.Find("steering");
  const Stream& mocap = *r.Find("mocap");
  EXPECT_EQ(wheel.values.rows(), 1896);
  // Yaw increments over 0.5 s against rim travel x sin(steering) / L (positive steering: counter-clockwise).
  const double radius = r.platform.geometry.at("wheel_radius_front_m");
  const double L = r.platform.geometry.at("wheel_to_axle_m");
  std::vector<double> predicted, measured;
  for (Eigen::Index k = 0; k + 10 < wheel.values.rows(); k += 10) {
    double turn = 0.0;
    for (Eigen::Index j = k + 1; j <= k + 10; ++j)
      turn += radius * (wheel.values(j, 0) - wheel.values(j - 1, 0)) * std::sin(steering.values(j, 0)) / L;
    predicted.push_back(turn);
    measured.push_back(std::remainder(Yaw(mocap, k + 10) - Yaw(mocap, k), 2.0 * M_PI));
  }
  const auto [correlation, slope] = CorrelationAndSlope(predicted, measured);
  EXPECT_GT(correlation, 0.95);
  EXPECT_GT(slope, 0.5);
}

}  // namespace
}  // namespace roamlab::importers
