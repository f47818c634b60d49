#include "common/progress.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

namespace roamlab {
namespace {

int Lines(const std::string& text) { return static_cast<int>(std::count(text.begin(), text.end(), '\n')); }

TEST(FormatDuration, SecondsMinutesHours) {
  EXPECT_EQ(FormatDuration(0.4), "0s");
  EXPECT_EQ(FormatDuration(45.0), "45s");
  EXPECT_EQ(FormatDuration(190.0), "3m10s");
  EXPECT_EQ(FormatDuration(7500.0), "2h05m");
  EXPECT_EQ(FormatDuration(-1.0), "?");
}

TEST(SecondsLeft, AtTheRateSoFar) {
  EXPECT_DOUBLE_EQ(SecondsLeft(30.0, 0.25), 90.0);
  EXPECT_DOUBLE_EQ(SecondsLeft(30.0, 1.0), 0.0);
  EXPECT_TRUE(std::isnan(SecondsLeft(30.0, 0.0)));
  EXPECT_EQ(ElapsedAndLeft(63.0, 190.0), ", 1m03s elapsed, about 3m10s left");
  EXPECT_EQ(ElapsedAndLeft(63.0, 0.0), ", 1m03s elapsed");
}

TEST(ProgressMeter, OffATerminalOneLinePerStep) {
  std::ostringstream out;
  double now = 100.0;
  {
    ProgressMeter meter("mc", &out, false, [&now] { return now; });
    for (int done = 0; done <= 1000; ++done) {
      now += 0.1;
      meter.Update(done, 1000);
    }
  }
  // One line at 0 and at each 5 % after: 21, however many updates.
  EXPECT_EQ(Lines(out.str()), 21) << out.str();
  EXPECT_EQ(out.str().find('\r'), std::string::npos);
  EXPECT_NE(out.str().find("mc: 500/1000 (50%), 50s elapsed, about 50s left\n"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("mc: 1000/1000 (100%), 1m40s elapsed\n"), std::string::npos) << out.str();
}

TEST(ProgressMeter, TheTimeLeftStartsAtTheFirstUpdate) {
  std::ostringstream out;
  double now = 0.0;
  ProgressMeter meter("mc", &out, false, [&now] { return now; });
  now = 60.0;  // a calibration before the runs
  meter.Update(0, 10);
  now = 70.0;
  meter.Update(1, 10);
  EXPECT_NE(out.str().find("mc: 1/10 (10%), 1m10s elapsed, about 1m30s left\n"), std::string::npos) << out.str();
}

TEST(ProgressMeter, OnATerminalOneLineRewritten) {
  std::ostringstream out;
  double now = 0.0;
  {
    ProgressMeter meter("track", &out, true, [&now] { return now; });
    for (int i = 0; i <= 100; ++i) {
      now += 1.0;
      meter.Update(i / 100.0);
    }
    meter.Note("done");
  }
  const std::string text = out.str();
  EXPECT_EQ(std::count(text.begin(), text.end(), '\r'), 102);
  // Only the note ends a line: the progress line is cleared before it and nothing is left open.
  EXPECT_EQ(Lines(text), 1) << text;
  EXPECT_NE(text.find("track: done (1m41s)\n"), std::string::npos) << text;
}

}  // namespace
}  // namespace roamlab
