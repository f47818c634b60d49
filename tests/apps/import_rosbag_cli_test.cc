// `roamlab import rosbag` end to end on a hand-built ROS 1 bag: the summary names each topic's message type, the checks
// are warning lines, --list, --topic and --odometry-topic; bad input is one line and exit 2, a directory included.
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "recording/recording.h"
#include "tests/recording/temp_dir.h"
#include "tests/support/bag_writers.h"
#include "tests/support/message_writer.h"

namespace roamlab {
namespace {

namespace fs = std::filesystem;
namespace bag = importers::testing;

using testing::CommandRun;
using ::testing::HasSubstr;

CommandRun Roamlab(const std::string& args, const fs::path& dir) {
  return testing::RunCommand(std::string(ROAMLAB_BINARY) + " " + args, dir.string());
}

// Two odometry topics (one all zero), an IMU whose stamps are 100 ms behind its receive times.
std::string TwoOdometryBag() {
  const bag::Wire ros1 = bag::Wire::kRos1;
  const std::vector<double> q = {0, 0, 0, 1};
  std::string chunk = bag::Connection(0, "/imu", "sensor_msgs/Imu") +
                      bag::Connection(1, "/wheel/odom", "nav_msgs/Odometry") +
                      bag::Connection(2, "/zero/odom", "nav_msgs/Odometry");
  for (std::uint32_t k = 0; k < 5; ++k) {
    const std::uint32_t nsec = 100000000 * k;
    chunk += bag::BagRecord(bag::Op(0x02) + bag::BagField("conn", bag::U32(0)) +
                                bag::BagField("time", bag::U32(20) + bag::U32(nsec + 100000000)),
                            bag::ImuMessage(ros1, 20, nsec, 0.1 * k));
    chunk += bag::MessageRecord(1, 19, nsec, bag::OdometryMessage(ros1, 20, nsec, "odom", "base", q, 1.0, 0, 0.2));
    chunk += bag::MessageRecord(2, 19, nsec, bag::OdometryMessage(ros1, 20, nsec, "odom", "base", q, 0, 0, 0));
  }
  return bag::BagOf(chunk);
}

class ImportRosbagCliTest : public ::testing::Test {
 protected:
  void SetUp() override { testing::WriteFile((dir_ / "two.bag").string(), TwoOdometryBag()); }
  testing::TempDir temp_;
  fs::path dir_{temp_.path()};
  std::string bag_ = (dir_ / "two.bag").string();
};

TEST_F(ImportRosbagCliTest, SummaryNamesTypesAndWarnsOfChecks) {
  const std::string rec = (dir_ / "rec").string();
  CommandRun r = Roamlab("import rosbag " + bag_ + " --out " + rec + " --platform skid_steer", dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("/imu (sensor_msgs/Imu) -> imu: 5 samples"));
  EXPECT_THAT(r.out, HasSubstr("/wheel/odom (nav_msgs/Odometry) -> wheel_odom: 5 samples"));
  EXPECT_THAT(r.out, HasSubstr("/wheel/odom (nav_msgs/Odometry) -> wheel_odom_pose: 5 samples"));
  EXPECT_THAT(r.err, HasSubstr("roamlab import: warning: /imu (imu): header stamps are 100 ms earlier than the bag's "
                               "receive times\n"));
  EXPECT_THAT(r.err, HasSubstr("roamlab import: warning: /zero/odom (zero_odom): all values are zero\n"));
  EXPECT_EQ(r.err.rfind("import: 100%, ", 0), 0u) << r.err;  // the progress (common/progress.h), off a terminal
  Result<recording::Recording> back = recording::ReadRecording(rec);
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back.value().streams.size(), 5u);

  // --quiet: no progress, no summary; the warnings stay.
  r = Roamlab("import rosbag " + bag_ + " --out " + rec + " --platform skid_steer --quiet", dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "");
  EXPECT_THAT(r.err, ::testing::Not(HasSubstr("import: 100%")));
  EXPECT_THAT(r.err, HasSubstr("roamlab import: warning: /zero/odom (zero_odom): all values are zero\n"));
}

TEST_F(ImportRosbagCliTest, ListTopicAndOdometryTopic) {
  CommandRun r = Roamlab("import rosbag " + bag_ + " --list", dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("topic\ttype\tmessages\trate_hz"));
  EXPECT_THAT(r.out, HasSubstr("/wheel/odom\tnav_msgs/Odometry\t5\t10\t"));
  EXPECT_FALSE(fs::exists(dir_ / "rec"));

  const std::string wheels =
      " --platform skid_steer --geometry wheel_radius_m=0.1 --geometry baseline_m=0.5 "
      "--wheels-from-odometry --out " +
      (dir_ / "rec").string();
  r = Roamlab("import rosbag " + bag_ + wheels, dir_);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("several odometry topics (/wheel/odom, /zero/odom); choose one with --odometry-topic"));
  r = Roamlab("import rosbag " + bag_ + wheels +
                  " --odometry-topic /wheel/odom --topic /wheel/odom=odometry "
                  "--topic /zero/odom=idle",
              dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  Result<recording::Recording> back = recording::ReadRecording((dir_ / "rec").string());
  ASSERT_TRUE(back.ok()) << back.status().message();
  ASSERT_NE(back.value().Find("wheels"), nullptr);
  ASSERT_NE(back.value().Find("odometry"), nullptr);
  EXPECT_EQ(back.value().Find("imu"), nullptr);
  // 1 m/s turning at 0.2 rad/s for 0.4 s, wheels of 0.1 m on a 0.5 m track: the left wheel turns at
  // (1 - 0.2 * 0.25) / 0.1 rad/s, the right one at (1 + 0.2 * 0.25) / 0.1 rad/s.
  EXPECT_NEAR(back.value().Find("wheels")->values(4, 0), 0.4 * (1.0 - 0.2 * 0.25) / 0.1, 1e-9);
  EXPECT_NEAR(back.value().Find("wheels")->values(4, 1), 0.4 * (1.0 + 0.2 * 0.25) / 0.1, 1e-9);
}

TEST_F(ImportRosbagCliTest, BadInputIsOneLineAndExitTwo) {
  fs::create_directories(dir_ / "not_a_bag");
  for (const std::string& args :
       {"import rosbag " + (dir_ / "not_a_bag").string() + " --out " + (dir_ / "rec").string(),  // no rosbag2 bag
        "import rosbag " + (dir_ / "none.bag").string() + " --out " + (dir_ / "rec").string(),
        "import rosbag " + bag_ + " --topic /imu --out " + (dir_ / "rec").string(),
        "import rosbag " + bag_ + " --topic /nothing=x --out " + (dir_ / "rec").string(), "import rosbag " + bag_}) {
    CommandRun r = Roamlab(args, dir_);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    EXPECT_EQ(r.err.rfind("roamlab import: ", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
}

}  // namespace
}  // namespace roamlab
