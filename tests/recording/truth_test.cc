#include "recording/truth.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/recording/temp_dir.h"

namespace roamlab::recording {
namespace {

using ::roamlab::testing::ReadFile;
using ::roamlab::testing::TempDir;
using ::roamlab::testing::WriteFile;
using ::testing::AllOf;
using ::testing::HasSubstr;

constexpr const char* kTruthYaml =
    "calibration:\n"
    "  gps.lever_arm: [0.57, -0.46, 0.32]\n"
    "  imu.time_offset_s: 0.01\n"
    "effects:\n"
    "  - name: gps_latency\n"
    "    parameters: {latency_s: 0.12}\n"
    "  - name: wheel_radius_difference\n"
    "    parameters: {front_left_m: 0.301, front_right_m: 0.299}\n";

// The error message of reading truth.yaml in `dir`, or "" when it reads (which fails the calling test).
std::string ReadTruthError(const TempDir& dir) {
  const Result<Truth> result = ReadTruth(dir.path());
  EXPECT_FALSE(result.ok()) << "expected an error reading truth.yaml";
  return result.ok() ? "" : result.status().message();
}

TEST(TruthTest, ReadsTheDocumentedForm) {
  TempDir dir;
  WriteFile(dir.File("truth.yaml"), kTruthYaml);
  const Result<Truth> read = ReadTruth(dir.path());
  ASSERT_TRUE(read.ok()) << read.status().message();
  const Truth& truth = read.value();
  EXPECT_EQ(truth.calibration.at("gps.lever_arm"), (std::vector<double>{0.57, -0.46, 0.32}));
  EXPECT_EQ(truth.calibration.at("imu.time_offset_s"), std::vector<double>{0.01});
  ASSERT_EQ(truth.effects.size(), 2u);
  EXPECT_EQ(truth.effects[0].name, "gps_latency");
  EXPECT_EQ(truth.effects[0].parameters.at("latency_s"), 0.12);
  EXPECT_EQ(truth.effects[1].parameters.at("front_right_m"), 0.299);
}

TEST(TruthTest, RoundTripIsExactAndDeterministic) {
  TempDir dir;
  Truth truth;
  truth.calibration = {{"gps.lever_arm", {0.57, -0.46, 0.32}}, {"imu.gyro_scale", {1.0 / 3.0}}};
  truth.effects = {{"gps_latency", {{"latency_s", 0.12}}}, {"none_hidden", {}}};
  ASSERT_TRUE(WriteTruth(truth, dir.File("sub")).ok());
  const std::string bytes = ReadFile(dir.File("sub/truth.yaml"));
  const Result<Truth> read = ReadTruth(dir.File("sub"));
  ASSERT_TRUE(read.ok()) << read.status().message();
  EXPECT_EQ(read.value().calibration, truth.calibration);
  ASSERT_EQ(read.value().effects.size(), 2u);
  EXPECT_EQ(read.value().effects[0].name, "gps_latency");
  EXPECT_EQ(read.value().effects[0].parameters, truth.effects[0].parameters);
  EXPECT_TRUE(read.value().effects[1].parameters.empty());
  ASSERT_TRUE(WriteTruth(read.value(), dir.File("sub")).ok());
  EXPECT_EQ(ReadFile(dir.File("sub/truth.yaml")), bytes);
  EXPECT_THAT(bytes, HasSubstr("gps.lever_arm: [0.57, -0.46, 0.32]"));
}

TEST(TruthTest, UnknownKeys) {
  TempDir dir;
  WriteFile(dir.File("truth.yaml"), std::string(kTruthYaml) + "hidden: yes\n");
  EXPECT_THAT(ReadTruthError(dir), AllOf(HasSubstr("truth.yaml:9:"), HasSubstr("unknown key 'hidden'")));
  WriteFile(dir.File("truth.yaml"), "effects:\n  - name: slip\n    params: {k: 1}\n");
  EXPECT_THAT(ReadTruthError(dir), AllOf(HasSubstr("truth.yaml:3:"), HasSubstr("unknown key 'params'")));
}

TEST(TruthTest, BadValues) {
  TempDir dir;
  WriteFile(dir.File("truth.yaml"), "calibration:\n  gps.lever_arm: [0.5, abc, 0.3]\n");
  EXPECT_THAT(ReadTruthError(dir), AllOf(HasSubstr("truth.yaml:2:"), HasSubstr("not a number 'abc'")));
  WriteFile(dir.File("truth.yaml"), "effects:\n  - parameters: {k: 1}\n");
  EXPECT_THAT(ReadTruthError(dir), AllOf(HasSubstr("truth.yaml:2:"), HasSubstr("missing required key 'name'")));
}

TEST(TruthTest, MissingFile) {
  TempDir dir;
  EXPECT_THAT(ReadTruthError(dir), AllOf(HasSubstr("truth.yaml"), HasSubstr("cannot open")));
}

}  // namespace
}  // namespace roamlab::recording
