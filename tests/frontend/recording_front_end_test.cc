// The front ends over a recording give the simulator's own streams: a short simulation of the indoor scenario that
// stores its camera frames and laser scans, run through `roamlab frontend`'s core, must reproduce its
// visual_odometry and scan_matching streams byte for byte.
#include "frontend/recording_front_end.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "recording/recording.h"
#include "recording/truth.h"
#include "sim/simulator.h"
#include "tests/recording/temp_dir.h"
#include "tests/sim/sim_testing.h"

namespace roamlab::frontend {
namespace {

using roamlab::testing::ReadFile;
using roamlab::testing::TempDir;
using ::testing::HasSubstr;

// Simulates 3 s of scenarios/indoor_diffdrive_slip.yaml with stored frames and scans into `directory`; false when
// rendering is unavailable.
bool SimulateIndoor(const std::string& directory) {
  auto scenario = sim::LoadScenario(sim::testing::SourcePath("scenarios/indoor_diffdrive_slip.yaml"));
  EXPECT_TRUE(scenario.ok()) << scenario.status().message();
  sim::Scenario s = scenario.value();
  s.duration_s = 3.0;
  s.sensors.camera->store_images = true;
  s.sensors.laser->store_scans = true;
  sim::SimulateOptions options;
  options.image_directory = directory;
  auto simulation = sim::Simulate(s, options);
  if (!simulation.ok() && simulation.status().message().find("EGL:") != std::string::npos) return false;
  EXPECT_TRUE(simulation.ok()) << simulation.status().message();
  EXPECT_TRUE(recording::WriteRecording(simulation.value().recording, directory).ok());
  EXPECT_TRUE(recording::WriteTruth(simulation.value().truth, directory).ok());
  return true;
}

// The stream entry of `name` in a recording directory's recording.yaml, as text (from "- name: <name>" to the next
// entry).
std::string StreamEntry(const std::string& directory, const std::string& name) {
  const std::string yaml = ReadFile(directory + "/recording.yaml");
  const std::size_t begin = yaml.find("- name: " + name + "\n");
  if (begin == std::string::npos) return "";
  const std::size_t end = yaml.find("- name: ", begin + 1);
  return yaml.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
}

class RecordingFrontEndTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    simulated_ = new TempDir();
    rendered_ = SimulateIndoor(simulated_->path());
  }
  static void TearDownTestSuite() { delete simulated_; }
  void SetUp() override {
    if (!rendered_) GTEST_SKIP() << "no headless OpenGL";
  }
  static TempDir* simulated_;
  static bool rendered_;
};
TempDir* RecordingFrontEndTest::simulated_ = nullptr;
bool RecordingFrontEndTest::rendered_ = false;

TEST_F(RecordingFrontEndTest, StoredFramesGiveTheSimulatorsVisualOdometry) {
  const std::string in = simulated_->path();
  TempDir out;
  FrontEndOptions options;
  options.front_end = FrontEnd::kVisualOdometry;
  const auto run = RunFrontEnd(in, out.path(), options);
  ASSERT_TRUE(run.ok()) << run.status().message();
  EXPECT_EQ(run.value().input_stream, "visual_odometry_images");
  ASSERT_TRUE(run.value().visual_odometry.has_value());
  EXPECT_EQ(run.value().visual_odometry->frames, 46);  // 0 to 3 s at 15 Hz
  EXPECT_GT(run.value().stream.t.size(), 40u);
  // The derived stream replaces the simulator's own in place: the same data and the same entry.
  EXPECT_EQ(ReadFile(out.File("visual_odometry.csv")), ReadFile(simulated_->File("visual_odometry.csv")));
  EXPECT_EQ(StreamEntry(out.path(), "visual_odometry"), StreamEntry(in, "visual_odometry"));
  EXPECT_NE(StreamEntry(in, "visual_odometry"), "");
  // Everything else is carried over: the other streams and their entries, the ground truth, truth.yaml and the
  // frames.
  for (const char* name : {"wheel_encoders", "scan_matching", "laser_scan", "visual_odometry_images"}) {
    EXPECT_EQ(StreamEntry(out.path(), name), StreamEntry(in, name)) << name;
  }
  for (const char* file : {"imu.csv", "scan_matching.csv", "laser_scan.csv", "ground_truth.tum", "truth.yaml",
                           "visual_odometry_images.csv", "visual_odometry/000045.png"}) {
    EXPECT_EQ(ReadFile(out.File(file)), ReadFile(simulated_->File(file))) << file;
  }
}

TEST_F(RecordingFrontEndTest, StoredScansGiveTheSimulatorsScanMatching) {
  const std::string in = simulated_->path();
  TempDir out;
  FrontEndOptions options;
  options.front_end = FrontEnd::kScanMatching;
  const auto run = RunFrontEnd(in, out.path(), options);
  ASSERT_TRUE(run.ok()) << run.status().message();
  EXPECT_EQ(run.value().input_stream, "laser_scan");
  EXPECT_GT(run.value().stream.t.size(), 25u);  // 31 scans, 30 pairs
  EXPECT_EQ(ReadFile(out.File("scan_matching.csv")), ReadFile(simulated_->File("scan_matching.csv")));
  EXPECT_EQ(StreamEntry(out.path(), "scan_matching"), StreamEntry(in, "scan_matching"));
  EXPECT_NE(StreamEntry(in, "scan_matching"), "");
}

TEST_F(RecordingFrontEndTest, ANewNameIsAppendedAndAMissingInputIsAnError) {
  const std::string in = simulated_->path();
  TempDir out;
  FrontEndOptions options;
  options.front_end = FrontEnd::kScanMatching;
  options.output_stream = "scan_matching_again";
  const auto run = RunFrontEnd(in, out.path(), options);
  ASSERT_TRUE(run.ok()) << run.status().message();
  const auto read = recording::ReadRecording(out.path());
  ASSERT_TRUE(read.ok()) << read.status().message();
  EXPECT_EQ(read.value().streams.back().info.name, "scan_matching_again");
  EXPECT_EQ(ReadFile(out.File("scan_matching_again.csv")), ReadFile(simulated_->File("scan_matching.csv")));

  options.input_stream = "imu";
  const auto wrong_type = RunFrontEnd(in, out.path(), options);
  ASSERT_FALSE(wrong_type.ok());
  EXPECT_THAT(wrong_type.status().message(), HasSubstr("recording.yaml: stream 'imu' is not of type laser_scan"));
}

}  // namespace
}  // namespace roamlab::frontend
