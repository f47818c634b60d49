// `roamlab import csv` end to end: a good import exits 0, prints a line per file and per stream and writes a recording
// that reads back; a missing file, a mapping naming a column the file does not have and an unknown unit are each one
// line on stderr naming the file, and exit 2.
#include <algorithm>
#include <filesystem>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "recording/recording.h"
#include "tests/recording/temp_dir.h"

namespace roamlab {
namespace {

namespace fs = std::filesystem;

using testing::CommandRun;
using ::testing::HasSubstr;
using ::testing::StartsWith;

CommandRun Roamlab(const std::string& args, const fs::path& dir) {
  return testing::RunCommand(std::string(ROAMLAB_BINARY) + " " + args, dir.string());
}

// Five rows at 10 Hz: an IMU in deg/s and g, a GPS fix that changes on the third row.
constexpr const char* kLog =
    "time_s,gx,gy,gz,ax,ay,az,lat,lon,alt\n"
    "0.0,1.0,0.0,-1.0,0.0,0.0,1.0,45.0,9.0,120.0\n"
    "0.1,2.0,0.0,-1.0,0.0,0.1,1.0,45.0,9.0,120.0\n"
    "0.2,3.0,0.0,-1.0,0.0,0.2,1.0,45.00001,9.0,120.5\n"
    "0.3,4.0,0.0,-1.0,0.0,0.3,1.0,45.00001,9.0,120.5\n"
    "0.4,5.0,0.0,-1.0,0.0,0.4,1.0,45.00001,9.0,120.5\n";

std::string Mapping(const std::string& gyro_column, const std::string& gyro_unit) {
  return "time: {column: time_s, unit: s}\n"
         "streams:\n"
         "  imu: {type: imu, columns: [" +
         gyro_column + ", gy, gz, ax, ay, az], units: [" + gyro_unit +
         ", deg/s, deg/s, g, g, g]}\n"
         "  gps: {type: gps, columns: [lat, lon, alt], collapse: by_change}\n";
}

class ImportCsvCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    testing::WriteFile(log_, kLog);
    testing::WriteFile(map_, Mapping("gx", "deg/s"));
  }
  // `roamlab import csv CSV --map MAP --out rec`.
  CommandRun Import(const std::string& csv, const std::string& map) {
    return Roamlab("import csv " + csv + " --map " + map + " --out " + rec_, dir_);
  }
  testing::TempDir temp_;
  fs::path dir_{temp_.path()};
  std::string log_ = (dir_ / "log.csv").string();
  std::string map_ = (dir_ / "map.yaml").string();
  std::string rec_ = (dir_ / "rec").string();
};

TEST_F(ImportCsvCliTest, GoodImportPrintsEachFileAndStream) {
  const CommandRun r = Import(log_, map_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_THAT(r.out, HasSubstr(log_ + ": 5 rows read, 0 blank/comment/skip_rows lines"));
  EXPECT_THAT(r.out, HasSubstr("imu: 5 samples, 0.4 s, 10 Hz; 0 rows with empty cells, 0 rows collapsed\n"));
  EXPECT_THAT(r.out, HasSubstr("gps: 2 samples, 0.2 s,"));
  EXPECT_THAT(r.out, HasSubstr("; 0 rows with empty cells, 3 rows collapsed\n"));
  EXPECT_THAT(r.out, HasSubstr("imported into " + rec_ + "\n"));
  const Result<recording::Recording> back = recording::ReadRecording(rec_);
  ASSERT_TRUE(back.ok()) << back.status().message();
  ASSERT_NE(back.value().Find("imu"), nullptr);
  EXPECT_EQ(back.value().Find("imu")->t.size(), 5u);
  // 5 deg/s in rad/s.
  EXPECT_NEAR(back.value().Find("imu")->values(4, 0), 5.0 * 3.14159265358979 / 180.0, 1e-9);
}

// One line on stderr, naming `file`, and exit 2; no recording written.
void ExpectBadInput(const CommandRun& r, const std::string& file, const std::string& problem) {
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_THAT(r.err, StartsWith("roamlab import: "));
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_THAT(r.err, HasSubstr(file));
  EXPECT_THAT(r.err, HasSubstr(problem));
}

TEST_F(ImportCsvCliTest, MissingFileIsOneLineNamingItAndExitTwo) {
  const std::string none = (dir_ / "none.csv").string();
  ExpectBadInput(Import(none, map_), none, ": cannot open file");
  EXPECT_FALSE(fs::exists(rec_));
  const std::string no_map = (dir_ / "none.yaml").string();
  ExpectBadInput(Import(log_, no_map), no_map, ": cannot open file");
  EXPECT_FALSE(fs::exists(rec_));
}

TEST_F(ImportCsvCliTest, MissingColumnIsOneLineNamingTheFileAndColumn) {
  testing::WriteFile(map_, Mapping("gyro_x", "deg/s"));
  ExpectBadInput(Import(log_, map_), log_, "column 'gyro_x'");
  EXPECT_FALSE(fs::exists(rec_));
}

TEST_F(ImportCsvCliTest, UnknownUnitIsOneLineNamingTheMappingAndUnit) {
  testing::WriteFile(map_, Mapping("gx", "furlongs/s"));
  ExpectBadInput(Import(log_, map_), map_ + ":3:", "unknown unit 'furlongs/s'");
  EXPECT_FALSE(fs::exists(rec_));
}

}  // namespace
}  // namespace roamlab
