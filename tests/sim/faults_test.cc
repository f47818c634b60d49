#include "sim/faults.h"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace roamlab::sim {
namespace {

using ::testing::HasSubstr;

// A 10 s stream at `rate_hz` whose row k holds k in every column (gps: a fix near Milan moving north).
recording::Stream MakeStream(const std::string& name, recording::StreamType type, double rate_hz, int columns) {
  recording::Stream s;
  s.info.name = name;
  s.info.type = type;
  s.info.rate_hz = rate_hz;
  const int rows = static_cast<int>(10.0 * rate_hz) + 1;
  s.values.resize(rows, columns);
  for (int k = 0; k < rows; ++k) {
    s.t.push_back(Time::FromNanoseconds(static_cast<std::int64_t>(std::llround(k * 1e9 / rate_hz))));
    s.values.row(k).setConstant(k);
    if (type == recording::StreamType::kGps) s.values.row(k) << 45.0 + 1e-6 * k, 9.0, 120.0;
  }
  return s;
}

recording::Recording MakeRecording() {
  recording::Recording rec;
  rec.streams.push_back(MakeStream("imu", recording::StreamType::kImu, 100.0, 6));
  rec.streams.push_back(MakeStream("gps", recording::StreamType::kGps, 5.0, 3));
  return rec;
}

FaultOptions Fault(const std::string& type, const std::string& stream) {
  FaultOptions f;
  f.type = type;
  f.stream = stream;
  return f;
}

TEST(FaultsTest, GpsOutliersMoveTheChosenFixesBySizeMetres) {
  recording::Recording rec = MakeRecording();
  const recording::Stream clean = rec.streams[1];
  FaultOptions f = Fault("outliers", "gps");
  f.fraction = 0.3;
  f.size = 5.0;
  const auto lines = ApplyFaults({f}, 7, &rec);
  ASSERT_EQ(lines.size(), 1u);
  int moved = 0;
  for (Eigen::Index k = 0; k < clean.values.rows(); ++k) {
    const double north_m = (rec.streams[1].values(k, 0) - clean.values(k, 0)) * 111132.0;
    const double east_m = (rec.streams[1].values(k, 1) - clean.values(k, 1)) * 111132.0 * std::cos(45.0 * M_PI / 180);
    const double up_m = rec.streams[1].values(k, 2) - clean.values(k, 2);
    const double moved_m = std::sqrt(north_m * north_m + east_m * east_m + up_m * up_m);
    if (moved_m == 0.0) continue;
    ++moved;
    EXPECT_NEAR(moved_m, 5.0, 0.05) << "row " << k;  // the metre-per-degree figures above are approximate
  }
  // 51 rows at probability 0.3: 15.3 expected, std 3.3.
  EXPECT_GE(moved, 5);
  EXPECT_LE(moved, 26);
  EXPECT_THAT(lines[0], HasSubstr("gps: outliers on " + std::to_string(moved) + " of 51 rows"));
  EXPECT_EQ(rec.streams[0].values, MakeRecording().streams[0].values);  // other streams untouched
}

TEST(FaultsTest, OtherOutliersAddPlusOrMinusSizeToEveryColumn) {
  recording::Recording rec = MakeRecording();
  const recording::Stream clean = rec.streams[0];
  FaultOptions f = Fault("outliers", "imu");
  f.fraction = 0.1;
  f.size = 2.0;
  ApplyFaults({f}, 1, &rec);
  const Eigen::MatrixXd diff = rec.streams[0].values - clean.values;
  int moved = 0;
  for (Eigen::Index k = 0; k < diff.rows(); ++k) {
    if (diff.row(k).isZero()) continue;
    ++moved;
    for (Eigen::Index c = 0; c < diff.cols(); ++c) EXPECT_DOUBLE_EQ(std::abs(diff(k, c)), 2.0);
  }
  EXPECT_GT(moved, 0);
  EXPECT_LT(moved, 1001 / 5);
}

TEST(FaultsTest, OutageRemovesTheWindowAndClockJumpShiftsTheRest) {
  recording::Recording rec = MakeRecording();
  FaultOptions outage = Fault("outage", "gps");
  outage.start_s = 2.0;
  outage.duration_s = 3.0;
  FaultOptions jump = Fault("clock_jump", "imu");
  jump.at_s = 4.0;
  jump.jump_s = 0.5;
  ApplyFaults({outage, jump}, 1, &rec);
  const recording::Stream& gps = rec.streams[1];
  ASSERT_EQ(gps.t.size(), 51u - 15u);  // 2.0, 2.2, ..., 4.8
  EXPECT_EQ(gps.values.rows(), 36);
  EXPECT_EQ(gps.t[9].seconds(), 1.8);
  EXPECT_NEAR(gps.t[10].seconds(), 5.0, 1e-12);
  const recording::Stream& imu = rec.streams[0];
  EXPECT_EQ(imu.t.size(), 1001u);
  EXPECT_NEAR(imu.t[399].seconds(), 3.99, 1e-12);
  EXPECT_NEAR(imu.t[400].seconds(), 4.5, 1e-12);
  EXPECT_EQ(imu.values(400, 0), 400.0);  // the reading is the same, its stamp is late
}

TEST(FaultsTest, DuplicatesRepeatRowsAndFreezeRepeatsTheFirstReading) {
  recording::Recording rec = MakeRecording();
  FaultOptions dup = Fault("duplicates", "gps");
  dup.fraction = 0.5;
  FaultOptions freeze = Fault("freeze", "imu");
  freeze.start_s = 1.0;
  freeze.duration_s = 0.5;
  ApplyFaults({dup, freeze}, 3, &rec);
  const recording::Stream& gps = rec.streams[1];
  ASSERT_GT(gps.t.size(), 51u);
  int copies = 0;
  for (std::size_t i = 1; i < gps.t.size(); ++i) {
    ASSERT_GE(gps.t[i], gps.t[i - 1]);
    if (gps.t[i] != gps.t[i - 1]) continue;
    ++copies;
    EXPECT_EQ(gps.values.row(static_cast<Eigen::Index>(i)), gps.values.row(static_cast<Eigen::Index>(i) - 1));
  }
  EXPECT_EQ(static_cast<std::size_t>(copies), gps.t.size() - 51u);
  const recording::Stream& imu = rec.streams[0];
  for (int k = 100; k < 150; ++k) EXPECT_EQ(imu.values(k, 2), 100.0) << k;
  EXPECT_EQ(imu.values(99, 2), 99.0);
  EXPECT_EQ(imu.values(150, 2), 150.0);
}

TEST(FaultsTest, SameSeedSameFaults) {
  recording::Recording a = MakeRecording(), b = MakeRecording(), c = MakeRecording();
  FaultOptions f = Fault("outliers", "imu");
  f.fraction = 0.2;
  f.size = 1.0;
  ApplyFaults({f}, 5, &a);
  ApplyFaults({f}, 5, &b);
  ApplyFaults({f}, 6, &c);
  EXPECT_EQ(a.streams[0].values, b.streams[0].values);
  EXPECT_NE(a.streams[0].values, c.streams[0].values);
}

TEST(FaultsTest, CheckFaultNamesTheKey) {
  const std::vector<std::string> streams = {"imu", "gps"};
  FaultOptions f = Fault("stuck", "imu");
  EXPECT_EQ(CheckFault(f, 30.0, streams)->key, "type");
  f = Fault("outage", "lidar");
  EXPECT_EQ(CheckFault(f, 30.0, streams)->key, "stream");
  EXPECT_THAT(CheckFault(f, 30.0, streams)->message, HasSubstr("it writes imu, gps"));
  f = Fault("outliers", "gps");
  f.fraction = 1.5;
  f.size = 1.0;
  EXPECT_EQ(CheckFault(f, 30.0, streams)->key, "fraction");
  f.fraction = 0.1;
  f.size = 0.0;
  EXPECT_EQ(CheckFault(f, 30.0, streams)->key, "size");
  f = Fault("clock_jump", "gps");
  f.at_s = 10.0;
  f.jump_s = -1.0;
  EXPECT_THAT(CheckFault(f, 30.0, streams)->message, HasSubstr("backward jump"));
  f.jump_s = 1.0;
  f.at_s = 31.0;
  EXPECT_EQ(CheckFault(f, 30.0, streams)->key, "at_s");
  f = Fault("freeze", "imu");
  f.start_s = 5.0;
  f.duration_s = 0.0;
  EXPECT_EQ(CheckFault(f, 30.0, streams)->key, "duration_s");
  f.duration_s = 5.0;
  EXPECT_FALSE(CheckFault(f, 30.0, streams).has_value());
}

}  // namespace
}  // namespace roamlab::sim
