#include "common/time.h"

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

}  // namespace
}  // namespace roamlab
