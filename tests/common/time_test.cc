#include "common/time.h"

#include <cstdint>
#include <limits>

#include <gtest/gtest.h>

namespace roamlab {
namespace {

TEST(TimeTest, ParsesDecimalSecondsExactly) {
  EXPECT_EQ(ParseSeconds("12.000000001")->nanoseconds(), 12000000001);
  EXPECT_EQ(ParseSeconds("0.1")->nanoseconds(), 100000000);
  EXPECT_EQ(ParseSeconds("-1.5")->nanoseconds(), -1500000000);
  EXPECT_EQ(ParseSeconds("1431705823.123456789")->nanoseconds(), 1431705823123456789);
  EXPECT_EQ(ParseSeconds("3")->nanoseconds(), 3000000000);
  EXPECT_EQ(ParseSeconds("1e-3")->nanoseconds(), 1000000);
}

TEST(TimeTest, RoundsTheTenthFractionalDigit) {
  EXPECT_EQ(ParseSeconds("0.0000000015")->nanoseconds(), 2);
  EXPECT_EQ(ParseSeconds("0.0000000014")->nanoseconds(), 1);
}

TEST(TimeTest, RejectsNonNumbers) {
  EXPECT_FALSE(ParseSeconds("").has_value());
  EXPECT_FALSE(ParseSeconds("nan").has_value());
  EXPECT_FALSE(ParseSeconds("inf").has_value());
  EXPECT_FALSE(ParseSeconds("1.2.3").has_value());
  EXPECT_FALSE(ParseSeconds("12s").has_value());
  EXPECT_FALSE(ParseSeconds(".").has_value());
}

TEST(TimeTest, FormatRoundTrips) {
  for (const char* text : {"0.000000000", "12.000000001", "-1.500000000", "1431705823.123456789"}) {
    EXPECT_EQ(FormatSeconds(*ParseSeconds(text)), text);
  }
}

TEST(TimeTest, RefusesStampsBeyondTheRange) {
  // 9.22e9 s would overflow int64 nanoseconds; the reader refuses anything past kMaxSeconds.
  EXPECT_FALSE(ParseSeconds("9223372036.854775808").has_value());
  EXPECT_FALSE(ParseSeconds("9223372039.999999999").has_value());
  EXPECT_FALSE(ParseSeconds("-9300000000").has_value());
  EXPECT_FALSE(ParseSeconds("9.3e9").has_value());
  EXPECT_FALSE(ParseSeconds("99999999999999999999").has_value());
  EXPECT_EQ(ParseSeconds("9000000000.000000000")->nanoseconds(), 9000000000000000000);
  EXPECT_EQ(ParseSeconds("-9000000000")->nanoseconds(), -9000000000000000000);
  EXPECT_FALSE(ParseSeconds("9000000000.000000001").has_value());
}

TEST(TimeTest, CheckedConversionRefusesWhatDoesNotFit) {
  EXPECT_FALSE(Time::FromSecondsChecked(9.3e9).has_value());
  EXPECT_FALSE(Time::FromSecondsChecked(-1e300).has_value());
  EXPECT_FALSE(Time::FromSecondsChecked(std::numeric_limits<double>::quiet_NaN()).has_value());
  EXPECT_FALSE(Time::FromSecondsChecked(std::numeric_limits<double>::infinity()).has_value());
  EXPECT_EQ(Time::FromSecondsChecked(1.5)->nanoseconds(), 1500000000);
  // The unchecked conversion saturates instead of overflowing.
  EXPECT_EQ(Time::FromSeconds(1e300).seconds(), kMaxSeconds);
  EXPECT_EQ(Time::FromSeconds(-1e300).seconds(), -kMaxSeconds);
  EXPECT_EQ(Time::FromSeconds(std::numeric_limits<double>::quiet_NaN()).nanoseconds(), 0);
}

TEST(TimeTest, FormatsEveryInt64) {
  EXPECT_EQ(FormatSeconds(Time::FromNanoseconds(std::numeric_limits<std::int64_t>::min())), "-9223372036.854775808");
  EXPECT_EQ(FormatSeconds(Time::FromNanoseconds(std::numeric_limits<std::int64_t>::max())), "9223372036.854775807");
  EXPECT_EQ(FormatSeconds(Time::FromNanoseconds(-1)), "-0.000000001");
}

}  // namespace
}  // namespace roamlab
