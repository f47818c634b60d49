// Plain trajectory files (eval/trajectory_file.h): TUM, KITTI and EuRoC parsing, format detection, bad input.
#include "eval/trajectory_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "tests/recording/temp_dir.h"

namespace roamlab::eval {
namespace {

using ::roamlab::testing::TempDir;
using ::roamlab::testing::WriteFile;
using ::testing::HasSubstr;
using ::testing::StartsWith;

std::string Error(const std::string& path, std::optional<TrajectoryFormat> format = std::nullopt) {
  const Result<TrajectoryFile> r = ReadTrajectoryFile(path, format);
  EXPECT_FALSE(r.ok()) << path;
  return r.ok() ? "" : r.status().message();
}

TEST(TrajectoryFileTest, KittiRowsArePosesIndexedByRow) {
  TempDir dir;
  // Pose 1: a quarter turn about z at (1, 2, 3).
  WriteFile(dir.File("poses.txt"),
            "1 0 0 0 0 1 0 0 0 0 1 0\n"
            "0 -1 0 1 1 0 0 2 0 0 1 3\n");
  const Result<TrajectoryFile> r = ReadTrajectoryFile(dir.File("poses.txt"), std::nullopt);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r.value().format, TrajectoryFormat::kKitti);
  EXPECT_FALSE(r.value().timed);
  ASSERT_EQ(r.value().poses.size(), 2u);
  EXPECT_EQ(r.value().poses[1].t, Time::FromSeconds(1.0));
  EXPECT_EQ(r.value().poses[1].p_world_body, Eigen::Vector3d(1.0, 2.0, 3.0));
  const Eigen::Quaterniond quarter(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  EXPECT_LT(r.value().poses[1].q_world_body.angularDistance(quarter), 1e-12);
}

TEST(TrajectoryFileTest, EurocCsvReadsNanosecondsPositionsAndWxyzQuaternions) {
  TempDir dir;
  const double h = std::sqrt(0.5);
  WriteFile(dir.File("data.csv"),
            "#timestamp [ns], p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], q_RS_z [], "
            "v_RS_R_x [m s^-1]\n"
            "1403636579758555392,4.688,-1.786,0.783,1,0,0,0,0.1\n"
            "1403636579763555584,4.689,-1.787,0.784," +
                std::to_string(h) + ",0,0," + std::to_string(h) + ",0.1\n");
  const Result<TrajectoryFile> r = ReadTrajectoryFile(dir.File("data.csv"), std::nullopt);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r.value().format, TrajectoryFormat::kEuroc);
  EXPECT_TRUE(r.value().timed);
  ASSERT_EQ(r.value().poses.size(), 2u);
  EXPECT_EQ(r.value().poses[0].t.nanoseconds(), 1403636579758555392LL);
  EXPECT_EQ(r.value().poses[1].p_world_body, Eigen::Vector3d(4.689, -1.787, 0.784));
  const Eigen::Quaterniond quarter(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  EXPECT_LT(r.value().poses[1].q_world_body.angularDistance(quarter), 1e-6);
  // A header without '#' is skipped as well.
  WriteFile(dir.File("est.csv"), "timestamp,x,y,z,qw,qx,qy,qz\n5,0,0,0,1,0,0,0\n");
  const Result<TrajectoryFile> headed = ReadTrajectoryFile(dir.File("est.csv"), std::nullopt);
  ASSERT_TRUE(headed.ok()) << headed.status().message();
  EXPECT_EQ(headed.value().poses.size(), 1u);
}

TEST(TrajectoryFileTest, DetectionByExtensionAndContent) {
  TempDir dir;
  WriteFile(dir.File("a.txt"), "# t x y z qx qy qz qw\n0.5 1 2 3 0 0 0 1\n");
  EXPECT_EQ(DetectTrajectoryFormat(dir.File("a.txt")).value(), TrajectoryFormat::kTum);
  EXPECT_EQ(DetectTrajectoryFormat(dir.File("missing.tum")).value(), TrajectoryFormat::kTum);
  WriteFile(dir.File("b.txt"), "1 2 3 4 5\n");
  const Result<TrajectoryFormat> five = DetectTrajectoryFormat(dir.File("b.txt"));
  ASSERT_FALSE(five.ok());
  EXPECT_THAT(five.status().message(), StartsWith(dir.File("b.txt") + ":1: 5 fields fit no trajectory format"));
  for (TrajectoryFormat f : {TrajectoryFormat::kTum, TrajectoryFormat::kKitti, TrajectoryFormat::kEuroc})
    EXPECT_EQ(ParseTrajectoryFormat(TrajectoryFormatName(f)), f);
  EXPECT_FALSE(ParseTrajectoryFormat("csv").has_value());
}

TEST(TrajectoryFileTest, BadInputNamesTheFileAndLine) {
  TempDir dir;
  EXPECT_THAT(Error(dir.File("none.txt")), StartsWith(dir.File("none.txt") + ": cannot open"));
  WriteFile(dir.File("k.txt"), "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1\n");
  EXPECT_THAT(Error(dir.File("k.txt"), TrajectoryFormat::kKitti),
              StartsWith(dir.File("k.txt") + ":2: expected 12 fields"));
  WriteFile(dir.File("r.txt"), "2 0 0 0 0 1 0 0 0 0 1 0\n");
  EXPECT_THAT(Error(dir.File("r.txt")), HasSubstr("not a proper orthonormal matrix"));
  WriteFile(dir.File("e.csv"), "10,0,0,0,1,0,0,0\n10,0,0,0,1,0,0,0\n");
  EXPECT_THAT(Error(dir.File("e.csv")), HasSubstr("e.csv:2: timestamp"));
  WriteFile(dir.File("f.csv"), "10,0,0,0,1,0,0\n");
  EXPECT_THAT(Error(dir.File("f.csv")), StartsWith(dir.File("f.csv") + ":1: expected at least 8"));
  WriteFile(dir.File("g.csv"), "10,0,nan,0,1,0,0,0\n");
  EXPECT_THAT(Error(dir.File("g.csv")), StartsWith(dir.File("g.csv") + ":1: column 3 is NaN"));
  WriteFile(dir.File("q.csv"), "10,0,0,0,2,0,0,0\n");
  EXPECT_THAT(Error(dir.File("q.csv")), HasSubstr("quaternion norm"));
  WriteFile(dir.File("t.tum"), "0 1 2 3 0 0 0\n");
  EXPECT_THAT(Error(dir.File("t.tum")), StartsWith(dir.File("t.tum") + ":1: expected 8 fields"));
}

}  // namespace
}  // namespace roamlab::eval
