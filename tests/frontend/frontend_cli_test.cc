// `roamlab frontend` on bad input: exit code 2 and one line naming the file and the problem; a good recording gives
// exit code 0 and the derived stream.
#include <string>

#include <gtest/gtest.h>

#include "frontend/laser_scan.h"
#include "recording/recording.h"
#include "tests/recording/temp_dir.h"

namespace roamlab {
namespace {

using roamlab::testing::CommandRun;
using roamlab::testing::TempDir;

CommandRun Roamlab(const std::string& args, const TempDir& dir) {
  return roamlab::testing::RunCommand(std::string(ROAMLAB_BINARY) + " " + args, dir.path());
}

// A recording with an imu stream only.
void WriteImuOnly(const std::string& directory) {
  recording::Recording rec;
  rec.platform.kind = "differential_drive";
  recording::Stream imu;
  imu.info.name = "imu";
  imu.info.type = recording::StreamType::kImu;
  imu.info.rate_hz = 100.0;
  imu.t = {Time::FromSeconds(0.0), Time::FromSeconds(0.01)};
  imu.values = Eigen::MatrixXd::Zero(2, 6);
  rec.streams.push_back(imu);
  ASSERT_TRUE(recording::WriteRecording(rec, directory).ok());
}

TEST(FrontEndCliTest, BadInputIsOneLineAndExitCode2) {
  TempDir dir;
  const CommandRun missing = Roamlab("frontend scan " + dir.File("absent") + " --out " + dir.File("out"), dir);
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_EQ(missing.err.rfind("roamlab frontend: " + dir.File("absent") + "/recording.yaml: ", 0), 0u) << missing.err;
  EXPECT_EQ(missing.err.find('\n'), missing.err.size() - 1) << missing.err;

  WriteImuOnly(dir.File("imu_only"));
  const CommandRun no_camera = Roamlab("frontend vo " + dir.File("imu_only") + " --out " + dir.File("out"), dir);
  EXPECT_EQ(no_camera.exit_code, 2);
  EXPECT_EQ(no_camera.err, "roamlab frontend: " + dir.File("imu_only") + "/recording.yaml: no camera stream\n");

  const CommandRun unknown = Roamlab("frontend lidar " + dir.File("imu_only") + " --out " + dir.File("out"), dir);
  EXPECT_EQ(unknown.exit_code, 2);
}

TEST(FrontEndCliTest, ScanMatchingOfStoredScans) {
  TempDir dir;
  // A corridor 2 m wide seen from two places 10 cm apart.
  frontend::ScanGeometry g;
  const auto scan = [&g](double x) {
    std::vector<double> ranges(static_cast<std::size_t>(g.beams));
    for (int k = 0; k < g.beams; ++k) {
      const double a = g.Angle(k);
      const double s = std::sin(a);
      const double c = std::cos(a);
      double r = std::abs(s) > 1e-9 ? 1.0 / std::abs(s) : 1e9;
      if (c > 1e-9) r = std::min(r, (2.5 - x) / c);
      ranges[static_cast<std::size_t>(k)] = r;
    }
    return ranges;
  };
  recording::Recording rec;
  rec.platform.kind = "differential_drive";
  recording::Stream laser;
  laser.info.name = "laser_scan";
  laser.info.type = recording::StreamType::kLaserScan;
  laser.info.rate_hz = 10.0;
  laser.info.columns = recording::LaserScanColumns(g.beams);
  laser.t = {Time::FromSeconds(0.0), Time::FromSeconds(0.1)};
  laser.values.resize(2, g.beams + 4);
  laser.values.row(0) = frontend::LaserScanRow(g, scan(0.0));
  laser.values.row(1) = frontend::LaserScanRow(g, scan(0.1));
  rec.streams.push_back(laser);
  ASSERT_TRUE(recording::WriteRecording(rec, dir.File("rec")).ok());

  const CommandRun run = Roamlab("frontend scan " + dir.File("rec") + " --out " + dir.File("out") + " --quiet", dir);
  EXPECT_EQ(run.exit_code, 0) << run.err;
  const auto read = recording::ReadRecording(dir.File("out"));
  ASSERT_TRUE(read.ok()) << read.status().message();
  const recording::Stream* matching = read.value().Find("scan_matching");
  ASSERT_NE(matching, nullptr);
  ASSERT_EQ(matching->t.size(), 1u);
  EXPECT_NEAR(matching->values(0, 0), 1.0, 0.05);  // 10 cm in 0.1 s
  EXPECT_NE(read.value().Find("laser_scan"), nullptr);
}

}  // namespace
}  // namespace roamlab
