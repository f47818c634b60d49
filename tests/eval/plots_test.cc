#include "eval/plots.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "tests/recording/temp_dir.h"

namespace roamlab::eval {
namespace {

using ::roamlab::testing::ReadFile;
using ::roamlab::testing::TempDir;
using ::roamlab::testing::WriteFile;
using ::testing::HasSubstr;

namespace fs = std::filesystem;

// PATH replaced for the lifetime of the object.
class ScopedPath {
 public:
  explicit ScopedPath(const char* path) {
    const char* old = std::getenv("PATH");
    had_ = old != nullptr;
    if (had_) old_ = old;
    ::setenv("PATH", path, 1);
  }
  ~ScopedPath() {
    if (had_) {
      ::setenv("PATH", old_.c_str(), 1);
    } else {
      ::unsetenv("PATH");
    }
  }

 private:
  bool had_ = false;
  std::string old_;
};

Trajectory Line(int poses) {
  Trajectory t(poses);
  for (int i = 0; i < poses; ++i) {
    t[i].t = Time::FromSeconds(0.1 * i);
    t[i].p_world_body = Eigen::Vector3d(i, 0.5 * i, 0.0);
  }
  return t;
}

// True when `path` starts with the PNG signature.
bool IsPng(const std::string& path) { return ReadFile(path).rfind("\x89PNG\r\n\x1a\n", 0) == 0; }

TEST(PlotsTest, TrajectoryPlotWritesDataAndAScriptThatReadsThem) {
  TempDir dir;
  PositionFixes gps{
      "gps", "GPS fixes (gps)", {Time::FromSeconds(0.0), Time::FromSeconds(0.2)}, {{0.1, 0.0, 0.0}, {2.0, 1.1, 0.0}}};
  const Result<PlotFiles> files = WriteTrajectoryPlot(dir.path(), "Trajectory", Time(), {"ground truth", Line(10)},
                                                      {{"estimate", Line(10)}}, {gps});
  ASSERT_TRUE(files.ok()) << files.status().message();
  ASSERT_EQ(files.value().data.size(), 3u);
  const std::string script = ReadFile(dir.File(files.value().script));
  for (const std::string& data : files.value().data) {
    EXPECT_TRUE(fs::exists(dir.File(data))) << data;
    EXPECT_THAT(script, HasSubstr("\"" + data + "\""));
  }
  EXPECT_THAT(script, HasSubstr("set xlabel 'East [m]'"));
  EXPECT_THAT(script, HasSubstr("set ylabel 'North [m]'"));
  EXPECT_THAT(script, HasSubstr("title \"GPS fixes (gps)\""));
  EXPECT_EQ(files.value().data[2], "trajectory_fixes_gps.dat");
  EXPECT_THAT(ReadFile(dir.File("trajectory_estimate.dat")), HasSubstr("\n0.9 9 4.5 0\n"));
}

TEST(PlotsTest, PositionErrorPlotDrawsTheEnvelopeOnlyWithSigmas) {
  TempDir dir;
  const std::vector<Time> t = {Time::FromSeconds(1.0), Time::FromSeconds(2.0)};
  const std::vector<Eigen::Vector3d> e = {{0.1, -0.1, 0.0}, {0.2, 0.0, 0.05}};
  ASSERT_TRUE(WritePositionErrorPlot(dir.path(), "err", Time::FromSeconds(1.0), t, e, {}).ok());
  EXPECT_THAT(ReadFile(dir.File("position_error.gp")), ::testing::Not(HasSubstr("filledcurves")));
  ASSERT_TRUE(
      WritePositionErrorPlot(dir.path(), "err", Time::FromSeconds(1.0), t, e, {{0.1, 0.1, 0.1}, {0.2, 0.2, 0.2}}).ok());
  const std::string script = ReadFile(dir.File("position_error.gp"));
  EXPECT_THAT(script, HasSubstr("filledcurves"));
  EXPECT_THAT(script, HasSubstr("'East error [m]'"));
  EXPECT_THAT(ReadFile(dir.File("position_error.dat")), HasSubstr("\n1 0.2 0 0.05 0.2 0.2 0.2\n"));
}

TEST(PlotsTest, NeesPlotShowsTheBand) {
  TempDir dir;
  const MonteCarloNees nees = AggregateNees({Time::FromSeconds(0.0), Time::FromSeconds(1.0)}, {{3.0, 3.0}}, 3, 0.5);
  ASSERT_TRUE(WriteNeesPlot(dir.path(), "NEES", nees, "fig4").ok());
  const std::string script = ReadFile(dir.File("fig4.gp"));
  EXPECT_THAT(script, HasSubstr("lo = 0.2157952"));
  EXPECT_THAT(script, HasSubstr("hi = 9.348403"));
  EXPECT_THAT(script, HasSubstr("set output \"fig4.png\""));
}

// One data row per run and component, one coverage row per component with its label as a tic; gnuplot draws it.
TEST(PlotsTest, ConsistencyPlotHasEveryRunAndTheCoverage) {
  TempDir dir;
  const std::vector<NormalizedErrors> components = {{"gps.lever_arm[0]", {0.5, -2.5}, {0.5, 0.5, 1.0}},
                                                    {"odometer.k_theta[0]", {1.0, NAN}, {1.0, 1.0, 1.0}}};
  const Result<PlotFiles> files = WriteConsistencyPlot(dir.path(), "Calibration errors", components);
  ASSERT_TRUE(files.ok()) << files.status().message();
  EXPECT_EQ(ReadFile(dir.File("consistency_errors.dat")),
            "# component error_over_std (one row per run)\n0 0.5\n0 -2.5\n1 1\n1 NaN\n");
  EXPECT_THAT(ReadFile(dir.File("consistency_coverage.dat")), HasSubstr("\n0 50 50 100 gps.lever_arm[0]\n"));
  const std::string script = ReadFile(dir.File("consistency.gp"));
  EXPECT_THAT(script, HasSubstr("\"odometer.k_theta[0]\" 1"));
  EXPECT_THAT(script, HasSubstr("2 with lines"));
  EXPECT_THAT(script, HasSubstr("95.45 with lines"));
  if (!GnuplotAvailable()) GTEST_SKIP() << "gnuplot not installed";
  ASSERT_TRUE(RunGnuplot(dir.path(), files.value().script).ok());
  EXPECT_TRUE(IsPng(dir.File("consistency.png")));
}

TEST(PlotsTest, GnuplotDrawsThePngs) {
  if (!GnuplotAvailable()) GTEST_SKIP() << "gnuplot not installed";
  TempDir dir;
  const Result<PlotFiles> files =
      WriteTrajectoryPlot(dir.path(), "T", Time(), {"ground truth", Line(10)}, {{"estimate", Line(10)}}, {});
  ASSERT_TRUE(files.ok());
  ASSERT_TRUE(RunGnuplot(dir.path(), files.value().script).ok());
  EXPECT_TRUE(IsPng(dir.File("trajectory.png")));
  EXPECT_FALSE(fs::exists(dir.File("trajectory.log")));  // nothing to say, no log left behind
}

TEST(PlotsTest, GnuplotErrorsAndAbsenceAreReported) {
  TempDir dir;
  WriteFile(dir.File("broken.gp"), "plot 'no_such_file.dat' using 1:2\n");
  if (GnuplotAvailable()) {
    const Status status = RunGnuplot(dir.path(), "broken.gp");
    ASSERT_FALSE(status.ok());
    EXPECT_THAT(status.message(), HasSubstr("broken.gp: gnuplot failed"));
  }
  const ScopedPath empty("/nonexistent");
  EXPECT_FALSE(GnuplotAvailable());
  EXPECT_THAT(RunGnuplot(dir.path(), "broken.gp").message(), HasSubstr("gnuplot not found"));
}

}  // namespace
}  // namespace roamlab::eval
