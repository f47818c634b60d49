#include "frontend/laser_scan.h"

#include <cmath>
#include <limits>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "recording/recording.h"
#include "tests/recording/temp_dir.h"

namespace roamlab::frontend {
namespace {

using ::testing::HasSubstr;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

ScanGeometry FiveBeams() {
  ScanGeometry g;
  g.beams = 5;
  g.first_angle_rad = -1.0;
  g.increment_rad = 0.5;
  g.min_range_m = 0.1;
  g.max_range_m = 4.0;
  return g;
}

// One laser_scan stream of two scans, in the recording format.
recording::Recording TwoScans(const ScanGeometry& g) {
  recording::Recording rec;
  rec.platform.kind = "differential_drive";
  recording::Stream stream;
  stream.info.name = "laser_scan";
  stream.info.type = recording::StreamType::kLaserScan;
  stream.info.rate_hz = 10.0;
  stream.info.units = "rad,m";
  stream.info.columns = recording::LaserScanColumns(g.beams);
  stream.t = {Time::FromSeconds(0.0), Time::FromSeconds(0.1)};
  stream.values.resize(2, g.beams + 4);
  stream.values.row(0) = LaserScanRow(g, {1.0, kNaN, 2.0, 3.0, 3.5});
  stream.values.row(1) = LaserScanRow(g, {1.1, 1.2, 5.0, 0.05, 3.4});
  rec.streams.push_back(stream);
  return rec;
}

TEST(LaserScanTest, RowsRoundTripThroughTheRecording) {
  const ScanGeometry g = FiveBeams();
  roamlab::testing::TempDir dir;
  ASSERT_TRUE(recording::WriteRecording(TwoScans(g), dir.path()).ok());
  const auto read = recording::ReadRecording(dir.path());
  ASSERT_TRUE(read.ok()) << read.status().message();
  const recording::Stream& stream = *read.value().Find("laser_scan");
  EXPECT_EQ(stream.info.columns.front(), "angle_min_rad");
  EXPECT_EQ(stream.info.columns.back(), "range_4");
  EXPECT_EQ(stream.info.units, "rad,m");
  // The geometry comes back exactly; a missing return is written as 0 and read back as NaN, as is a range outside
  // [min, max].
  const ScanGeometry back = LaserScanGeometry(stream, 1);
  EXPECT_EQ(back.beams, 5);
  EXPECT_EQ(back.first_angle_rad, g.first_angle_rad);
  EXPECT_EQ(back.increment_rad, g.increment_rad);
  EXPECT_EQ(back.max_range_m, g.max_range_m);
  EXPECT_EQ(stream.values(0, 5), 0.0);
  const std::vector<double> first = LaserScanRanges(stream, 0);
  EXPECT_EQ(first[0], 1.0);
  EXPECT_TRUE(std::isnan(first[1]));
  const std::vector<double> second = LaserScanRanges(stream, 1);
  EXPECT_EQ(second[1], 1.2);
  EXPECT_TRUE(std::isnan(second[2]));  // beyond max_range_m
  EXPECT_TRUE(std::isnan(second[3]));  // below min_range_m
}

TEST(LaserScanTest, TheReaderRefusesBadGeometryAndColumns) {
  roamlab::testing::TempDir dir;
  recording::Recording rec = TwoScans(FiveBeams());
  rec.streams[0].values(1, 1) = 0.0;
  const Status zero_increment = recording::WriteRecording(rec, dir.path());
  ASSERT_FALSE(zero_increment.ok());
  EXPECT_THAT(zero_increment.message(), HasSubstr("angle_increment_rad is 0"));

  rec = TwoScans(FiveBeams());
  rec.streams[0].values(0, 3) = 0.05;
  const Status max_below_min = recording::WriteRecording(rec, dir.path());
  ASSERT_FALSE(max_below_min.ok());
  EXPECT_THAT(max_below_min.message(), HasSubstr("range_max_m is not above range_min_m"));

  rec = TwoScans(FiveBeams());
  ASSERT_TRUE(recording::WriteRecording(rec, dir.path()).ok());
  const std::string csv = dir.File("laser_scan.csv");
  std::string content = roamlab::testing::ReadFile(csv);
  content.replace(content.find(",0.5,"), 5, ",0,");
  roamlab::testing::WriteFile(csv, content);
  const auto read = recording::ReadRecording(dir.path());
  ASSERT_FALSE(read.ok());
  EXPECT_THAT(read.status().message(), HasSubstr("laser_scan.csv:2: angle_increment_rad is 0"));

  rec.streams[0].info.columns[5] = "range_x";
  const Status columns = recording::WriteRecording(rec, dir.path());
  ASSERT_FALSE(columns.ok());
  EXPECT_THAT(columns.message(), HasSubstr("laser_scan columns must be"));
}

}  // namespace
}  // namespace roamlab::frontend
