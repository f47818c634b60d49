// The experiment steps: what they write, and how a failure is classified (bad input before anything runs, or a
// failure at run time).
#include "experiment/steps.h"

#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "estimator/calibration_io.h"
#include "experiment/montecarlo.h"
#include "recording/recording.h"
#include "tests/recording/temp_dir.h"
#include "tests/support/paths.h"
#include "tests/support/synthetic.h"

namespace roamlab::experiment {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::string Config(const std::string& name) { return roamlab::testing::SourceDir() + "/configs/" + name; }

// Calibrating writes calibration.json (read back by the estimator's reader) and trajectory.tum; tracking with it
// writes its three files.
TEST(StepsTest, CalibrateThenTrackWriteTheirFiles) {
  testing::TempDir dir;
  testing::SyntheticOptions options;
  options.duration_s = 5.0;
  ASSERT_TRUE(recording::WriteRecording(testing::MakeAtvRecording(options).recording, dir.File("rec")).ok());
  CalibrateRequest calibrate;
  calibrate.recording = dir.File("rec");
  calibrate.config = Config("atv_calibration.yaml");
  calibrate.out = dir.File("cal");
  estimator::CalibrationResult result;
  const Outcome calibrated = CalibrateToDirectory(calibrate, &result);
  ASSERT_TRUE(calibrated.ok()) << calibrated.status.message();
  const auto values = estimator::ReadCalibrationValues(dir.File("cal/calibration.json"));
  ASSERT_TRUE(values.ok()) << values.status().message();
  EXPECT_EQ(values.value().size(), result.parameters.size());
  EXPECT_TRUE(fs::exists(dir.File("cal/trajectory.tum")));

  TrackRequest track;
  track.recording = dir.File("rec");
  track.config = Config("atv_tracking.yaml");
  track.calibration = dir.File("cal/calibration.json");
  track.out = dir.File("track");
  track.no_time_budget = true;
  const Outcome tracked = TrackToDirectory(track);
  ASSERT_TRUE(tracked.ok()) << tracked.status.message();
  for (const char* file : {"trajectory.tum", "covariance.csv", "summary.json"})
    EXPECT_TRUE(fs::exists(dir.File(std::string("track/") + file))) << file;
  std::ifstream in(dir.File("track/summary.json"));
  const nlohmann::json summary = nlohmann::json::parse(in);
  EXPECT_GT(summary["poses"].get<int>(), 10);
}

// Inputs that do not load are bad input, named in the message; nothing runs.
TEST(StepsTest, InputsThatDoNotLoadAreBadInput) {
  testing::TempDir dir;
  SimulateRequest simulate;
  simulate.scenario = dir.File("missing.yaml");
  simulate.out = dir.File("rec");
  const Outcome simulated = SimulateToDirectory(simulate);
  EXPECT_FALSE(simulated.ok());
  EXPECT_TRUE(simulated.bad_input);
  EXPECT_THAT(simulated.status.message(), HasSubstr("missing.yaml"));

  TrackRequest track;
  track.recording = dir.File("no_recording");
  track.config = Config("atv_tracking.yaml");
  track.out = dir.File("track");
  const Outcome tracked = TrackToDirectory(track);
  EXPECT_TRUE(tracked.bad_input);
  EXPECT_FALSE(fs::exists(dir.File("track")));

  const Outcome imported = ImportOptiOdomToDirectory(dir.File("not_a_run.csv"), "", dir.File("imported"));
  EXPECT_TRUE(imported.bad_input);
  EXPECT_THAT(imported.status.message(), HasSubstr("cannot find the metadata file"));
}

TEST(MonteCarloTest, OptionsAreValidatedBeforeAnythingRuns) {
  MonteCarloOptions options;
  options.runs = 0;
  EXPECT_EQ(options.Validate(), "--runs must be at least 1");
  options.runs = 1;
  options.jobs = -1;
  EXPECT_EQ(options.Validate(), "--jobs must be >= 0");
  const Outcome outcome = RunMonteCarlo(options);
  EXPECT_TRUE(outcome.bad_input);
}

}  // namespace
}  // namespace roamlab::experiment
