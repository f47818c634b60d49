#include "recording/stream_health.h"

#include <cmath>

#include <gtest/gtest.h>

namespace roamlab::recording {
namespace {

// A stream at `rate_hz` over 10 s with distinct rows (row k holds k + 0.1 c in column c).
Stream Distinct(StreamType type, double rate_hz) {
  Stream s;
  s.info.name = "s";
  s.info.type = type;
  s.info.rate_hz = rate_hz;
  const int rows = static_cast<int>(10.0 * rate_hz) + 1;
  s.values.resize(rows, 3);
  for (int k = 0; k < rows; ++k) {
    s.t.push_back(Time::FromNanoseconds(static_cast<std::int64_t>(std::llround(k * 1e9 / rate_hz))));
    for (int c = 0; c < 3; ++c) s.values(k, c) = k + 0.1 * c;
  }
  return s;
}

TEST(StreamHealthTest, CleanStreamHasNoFinding) {
  const StreamHealth health = CheckStreamHealth(Distinct(StreamType::kImu, 100.0));
  EXPECT_TRUE(health.gaps.empty());
  EXPECT_TRUE(health.frozen.empty());
  EXPECT_EQ(health.FrozenRepeats(), 0);
}

TEST(StreamHealthTest, GapLongerThanFivePeriodsIsFound) {
  Stream s = Distinct(StreamType::kGps, 5.0);
  // Remove rows 10..14 (2.0 to 2.8 s): 1.2 s between 1.8 and 3.0, six periods.
  Stream cut = s;
  cut.t.erase(cut.t.begin() + 10, cut.t.begin() + 15);
  cut.values = Eigen::MatrixXd(static_cast<Eigen::Index>(cut.t.size()), 3).setZero();
  for (Eigen::Index k = 0; k < cut.values.rows(); ++k) cut.values.row(k).setConstant(static_cast<double>(k));
  const StreamHealth health = CheckStreamHealth(cut);
  ASSERT_EQ(health.gaps.size(), 1u);
  EXPECT_NEAR(health.gaps[0].after.seconds(), 1.8, 1e-12);
  EXPECT_NEAR(health.gaps[0].length_s, 1.2, 1e-12);
  // Four rows missing (five periods) is not yet a gap.
  Stream shorter = s;
  shorter.t.erase(shorter.t.begin() + 10, shorter.t.begin() + 14);
  shorter.values.conservativeResize(static_cast<Eigen::Index>(shorter.t.size()), 3);
  EXPECT_TRUE(CheckStreamHealth(shorter).gaps.empty());
}

TEST(StreamHealthTest, FrozenRunIsFoundInNoisyTypesOnly) {
  Stream s = Distinct(StreamType::kImu, 100.0);
  for (int k = 201; k < 300; ++k) s.values.row(k) = s.values.row(200);  // 100 rows over 0.99 s
  const StreamHealth health = CheckStreamHealth(s);
  ASSERT_EQ(health.frozen.size(), 1u);
  EXPECT_EQ(health.frozen[0].rows, 100);
  EXPECT_NEAR(health.frozen[0].first.seconds(), 2.0, 1e-12);
  EXPECT_NEAR(health.frozen[0].last.seconds(), 2.99, 1e-12);
  EXPECT_EQ(health.FrozenRepeats(), 99);
  // A wheel encoder at rest repeats its angle legitimately.
  s.info.type = StreamType::kWheelEncoders;
  EXPECT_TRUE(CheckStreamHealth(s).frozen.empty());
  // Shorter than kFrozenMinSeconds: not frozen.
  Stream brief = Distinct(StreamType::kImu, 100.0);
  for (int k = 201; k < 240; ++k) brief.values.row(k) = brief.values.row(200);
  EXPECT_TRUE(CheckStreamHealth(brief).frozen.empty());
}

TEST(StreamHealthTest, DropDuplicateRowsKeepsOneOfEachAndCounts) {
  Recording rec;
  Stream s = Distinct(StreamType::kImu, 100.0);
  Stream doubled = s;
  doubled.t.insert(doubled.t.begin() + 5, s.t[4]);
  doubled.values.resize(s.values.rows() + 1, 3);
  doubled.values << s.values.topRows(5), s.values.row(4), s.values.bottomRows(s.values.rows() - 5);
  rec.streams.push_back(doubled);
  DropDuplicateRows(&rec);
  EXPECT_EQ(rec.streams[0].t, s.t);
  EXPECT_EQ(rec.streams[0].values, s.values);
  EXPECT_EQ(rec.streams[0].duplicate_rows_dropped, 1);
}

}  // namespace
}  // namespace roamlab::recording
