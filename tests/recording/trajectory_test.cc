#include "recording/trajectory.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/recording/temp_dir.h"

namespace roamlab {
namespace {

using ::roamlab::testing::ReadFile;
using ::roamlab::testing::TempDir;
using ::roamlab::testing::WriteFile;
using ::testing::AllOf;
using ::testing::HasSubstr;

// The error message of reading `path`, or "" when it reads (which fails the calling test's expectations).
std::string ReadTumError(const std::string& path) {
  const Result<Trajectory> result = ReadTum(path);
  EXPECT_FALSE(result.ok()) << "expected an error reading " << path;
  return result.ok() ? "" : result.status().message();
}

Trajectory MakeTrajectory() {
  Trajectory trajectory;
  for (int i = 0; i < 4; ++i) {
    StampedPose pose;
    pose.t = Time::FromNanoseconds(1431705823000000000LL + 33333333LL * i);
    pose.p_world_body = Eigen::Vector3d(0.1 * i, -1.0 / 3.0, 1e-9 * i);
    pose.q_world_body = Eigen::Quaterniond(0.7, 0.1 * i, -0.2, 0.3).normalized();
    trajectory.push_back(pose);
  }
  return trajectory;
}

TEST(TumTest, RoundTripIsExactAndDeterministic) {
  TempDir dir;
  const Trajectory written = MakeTrajectory();
  ASSERT_TRUE(WriteTum(written, dir.File("a.tum")).ok());
  const Result<Trajectory> read = ReadTum(dir.File("a.tum"));
  ASSERT_TRUE(read.ok()) << read.status().message();
  ASSERT_EQ(read.value().size(), written.size());
  for (std::size_t i = 0; i < written.size(); ++i) {
    EXPECT_EQ(read.value()[i].t, written[i].t);
    EXPECT_EQ(read.value()[i].p_world_body, written[i].p_world_body);
    EXPECT_EQ(read.value()[i].q_world_body.coeffs(), written[i].q_world_body.coeffs());
  }
  // Reading and writing again gives the same bytes.
  ASSERT_TRUE(WriteTum(read.value(), dir.File("b.tum")).ok());
  EXPECT_EQ(ReadFile(dir.File("a.tum")), ReadFile(dir.File("b.tum")));
  EXPECT_THAT(ReadFile(dir.File("a.tum")), HasSubstr("\n1431705823.033333333 0.10000000000000001 "));
}

TEST(TumTest, AcceptsCommentsBlankLinesAndTabs) {
  TempDir dir;
  WriteFile(dir.File("t.tum"),
            "# timestamp tx ty tz qx qy qz qw\n"
            "\n"
            "1.0 1 2 3 0 0 0 1\n"
            "   # indented comment\n"
            "1.5\t4 5 6  0 0 1 0\r\n");
  const Result<Trajectory> read = ReadTum(dir.File("t.tum"));
  ASSERT_TRUE(read.ok()) << read.status().message();
  ASSERT_EQ(read.value().size(), 2u);
  EXPECT_EQ(read.value()[1].t.nanoseconds(), 1500000000);
  EXPECT_EQ(read.value()[1].p_world_body, Eigen::Vector3d(4, 5, 6));
  EXPECT_EQ(read.value()[1].q_world_body.z(), 1.0);  // file order is qx qy qz qw
  EXPECT_EQ(read.value()[1].q_world_body.w(), 0.0);
}

TEST(TumTest, NormalizesNearlyUnitQuaternions) {
  TempDir dir;
  WriteFile(dir.File("t.tum"), "0.0 0 0 0 0 0 0 1.0005\n");
  const Result<Trajectory> read = ReadTum(dir.File("t.tum"));
  ASSERT_TRUE(read.ok()) << read.status().message();
  EXPECT_NEAR(read.value()[0].q_world_body.norm(), 1.0, 1e-15);
}

TEST(TumTest, RejectsNonUnitQuaternion) {
  TempDir dir;
  WriteFile(dir.File("t.tum"), "0.0 0 0 0 0 0 0 1\n0.1 0 0 0 0 0 0 1.01\n");
  EXPECT_THAT(ReadTumError(dir.File("t.tum")), AllOf(HasSubstr("t.tum:2:"), HasSubstr("quaternion norm")));
}

TEST(TumTest, RejectsDuplicateAndBackwardTime) {
  TempDir dir;
  WriteFile(dir.File("t.tum"), "# header\n0.1 0 0 0 0 0 0 1\n0.1 0 0 0 0 0 0 1\n");
  EXPECT_THAT(ReadTumError(dir.File("t.tum")), AllOf(HasSubstr("t.tum:3:"), HasSubstr("duplicate")));
  WriteFile(dir.File("t.tum"), "0.1 0 0 0 0 0 0 1\n0.05 0 0 0 0 0 0 1\n");
  EXPECT_THAT(ReadTumError(dir.File("t.tum")), AllOf(HasSubstr("t.tum:2:"), HasSubstr("goes backwards")));
}

TEST(TumTest, RejectsBadFields) {
  TempDir dir;
  WriteFile(dir.File("t.tum"), "0.1 0 0 0 0 0 1\n");
  EXPECT_THAT(ReadTumError(dir.File("t.tum")), AllOf(HasSubstr("t.tum:1:"), HasSubstr("found 7")));
  WriteFile(dir.File("t.tum"), "0.1 0 nan 0 0 0 0 1\n");
  EXPECT_THAT(ReadTumError(dir.File("t.tum")), AllOf(HasSubstr("t.tum:1:"), HasSubstr("'y' is NaN")));
  WriteFile(dir.File("t.tum"), "x 0 0 0 0 0 0 1\n");
  EXPECT_THAT(ReadTumError(dir.File("t.tum")), AllOf(HasSubstr("t.tum:1:"), HasSubstr("not a time")));
  EXPECT_THAT(ReadTumError(dir.File("missing.tum")), HasSubstr("missing.tum: cannot open"));
}

TEST(TumTest, WriterRefusesNonIncreasingTime) {
  TempDir dir;
  Trajectory trajectory = MakeTrajectory();
  trajectory[2].t = trajectory[1].t;
  const Status status = WriteTum(trajectory, dir.File("t.tum"));
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), AllOf(HasSubstr("pose 2"), HasSubstr("duplicate")));
}

}  // namespace
}  // namespace roamlab
