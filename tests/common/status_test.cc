#include "common/status.h"

#include <string>

#include <gtest/gtest.h>

namespace roamlab {
namespace {

TEST(StatusTest, PlainMessageIsKept) {
  EXPECT_EQ(Status::Error("rec/gps.csv:12: timestamp not increasing").message(),
            "rec/gps.csv:12: timestamp not increasing");
}

TEST(StatusTest, ControlCharactersQuotedFromTheInputAreEscapedToKeepOneLine) {
  const std::string quoted = std::string("a\nb\rc\td") + '\0' + "\x19" + "\x7f" + "\xc3\xa9";
  EXPECT_EQ(Status::Error("map.yaml:3: unknown key '" + quoted + "'").message(),
            "map.yaml:3: unknown key 'a\\nb\\rc\\td\\x00\\x19\\x7f\xc3\xa9'");
}

}  // namespace
}  // namespace roamlab
