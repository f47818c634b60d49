#include "recording/calibration_file.h"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/recording/temp_dir.h"

namespace roamlab::recording {
namespace {

using ::roamlab::testing::TempDir;
using ::roamlab::testing::WriteFile;
using ::testing::HasSubstr;

TEST(CalibrationFileTest, ReadsParametersAndInformationWithNulls) {
  TempDir dir;
  const std::string path = dir.File("calibration.json");
  WriteFile(path, R"({"parameters": {"gps.lever_arm": {"estimate": [0.6, -0.5, 0.3], "std": [0.04, 0.04, null],
                                                       "manifold": "R3", "observability": "weak"},
                                     "k": {"estimate": [0.8]}},
                      "information": {"parameters": ["gps.lever_arm", "k"],
                                      "matrix": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, null, 0], [0, 0, 0, 2]]},
                      "solver": {"iterations": 3}})");
  const Result<CalibrationFile> file = ReadCalibrationFile(path);
  ASSERT_TRUE(file.ok()) << file.status().message();
  const CalibratedParameter& lever = file.value().parameters.at("gps.lever_arm");
  EXPECT_EQ(lever.estimate, (std::vector<double>{0.6, -0.5, 0.3}));
  ASSERT_EQ(lever.std.size(), 3u);
  EXPECT_TRUE(std::isnan(lever.std[2]));
  EXPECT_EQ(lever.manifold, "R3");
  EXPECT_EQ(lever.observability, "weak");
  const CalibratedParameter& k = file.value().parameters.at("k");
  EXPECT_TRUE(k.std.empty());
  EXPECT_TRUE(k.manifold.empty());
  EXPECT_TRUE(k.observability.empty());
  ASSERT_TRUE(file.value().information.has_value());
  EXPECT_EQ(file.value().information->parameters, (std::vector<std::string>{"gps.lever_arm", "k"}));
  EXPECT_EQ(file.value().information->matrix(3, 3), 2.0);
  EXPECT_TRUE(std::isnan(file.value().information->matrix(2, 2)));
}

TEST(CalibrationFileTest, InformationIsOptional) {
  TempDir dir;
  const std::string path = dir.File("calibration.json");
  WriteFile(path, R"({"parameters": {"k": {"estimate": [1]}}})");
  const Result<CalibrationFile> file = ReadCalibrationFile(path);
  ASSERT_TRUE(file.ok()) << file.status().message();
  EXPECT_FALSE(file.value().information.has_value());
}

TEST(CalibrationFileTest, BadFilesNameTheFileAndTheProblem) {
  TempDir dir;
  const std::string path = dir.File("calibration.json");
  const auto message = [&](const std::string& text) {
    WriteFile(path, text);
    const Result<CalibrationFile> file = ReadCalibrationFile(path);
    EXPECT_FALSE(file.ok()) << text;
    return file.ok() ? std::string() : file.status().message();
  };
  EXPECT_THAT(ReadCalibrationFile(dir.File("none.json")).status().message(), HasSubstr("none.json: cannot open"));
  EXPECT_THAT(message("{"), HasSubstr(path + ": not valid JSON"));
  EXPECT_THAT(message("[]"), HasSubstr(path + ": missing object 'parameters'"));
  EXPECT_THAT(message(R"({"parameters": {"a": {"estimate": [1, "x"]}}})"),
              HasSubstr(path + ": parameter 'a': 'estimate' must be an array of numbers"));
  EXPECT_THAT(message(R"({"parameters": {"a": {"estimate": [1], "std": ["x"]}}})"),
              HasSubstr("parameter 'a': 'std' must be an array of numbers or nulls"));
  EXPECT_THAT(message(R"({"parameters": {"a": {"estimate": [1], "manifold": 3}}})"),
              HasSubstr("parameter 'a': 'manifold' must be a string"));
  EXPECT_THAT(message(R"({"parameters": {"a": {"estimate": [1], "observability": 1}}})"),
              HasSubstr("parameter 'a': 'observability' must be a string"));
  EXPECT_THAT(message(R"({"parameters": {}, "information": {"parameters": [1], "matrix": [[1]]}})"),
              HasSubstr("information.parameters must be names"));
  EXPECT_THAT(message(R"({"parameters": {}, "information": {"parameters": ["a"], "matrix": [[1, 2]]}})"),
              HasSubstr("information.matrix must be square"));
}

}  // namespace
}  // namespace roamlab::recording
