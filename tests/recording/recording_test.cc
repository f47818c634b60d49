#include "recording/recording.h"

#include <sys/stat.h>

#include <cmath>
#include <filesystem>
#include <random>

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

constexpr double kPi = 3.14159265358979323846;

// A small valid recording, written by hand. Line numbers matter to the error tests:
//   6: "  - name: gps", 9: "  - name: imu", 11: "    rate_hz: 100".
constexpr const char* kYaml =
    "format_version: 1\n"
    "platform:\n"
    "  kind: ackermann\n"
    "origin: {latitude_deg: 45.47, longitude_deg: 9.23, altitude_m: 120.0}\n"
    "streams:\n"
    "  - name: gps\n"
    "    type: gps\n"
    "    rate_hz: 5\n"
    "  - name: imu\n"
    "    type: imu\n"
    "    rate_hz: 100\n";

constexpr const char* kGpsCsv =
    "t,latitude,longitude,altitude\n"
    "0.0,45.47,9.23,120.0\n"
    "0.2,45.4700001,9.2300001,120.1\n";

constexpr const char* kImuCsv =
    "t,wx,wy,wz,ax,ay,az\n"
    "0.00,0,0,0.1,0,0,9.81\n"
    "0.01,0,0,0.1,0,0,9.81\n"
    "0.02,0,0,0.1,0,0,9.81\n";

// `text` with the first occurrence of `from` replaced by `to` (which must occur).
std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// Writes the hand-made recording into `dir`, with optional replacements of its files.
void WriteFixture(const TempDir& dir, const std::string& yaml = kYaml, const std::string& gps = kGpsCsv,
                  const std::string& imu = kImuCsv) {
  WriteFile(dir.File("recording.yaml"), yaml);
  WriteFile(dir.File("gps.csv"), gps);
  WriteFile(dir.File("imu.csv"), imu);
}

// The error message of reading `dir`, or "" when it reads (which fails the calling test's expectations).
std::string ReadError(const TempDir& dir, const ReadOptions& options = {}) {
  const Result<Recording> result = ReadRecording(dir.path(), options);
  EXPECT_FALSE(result.ok()) << "expected an error reading " << dir.path();
  return result.ok() ? "" : result.status().message();
}

// The error message of writing `recording`, or "" when it is written (which fails the calling test's expectations).
std::string WriteError(const Recording& recording, const TempDir& dir) {
  const Status status = WriteRecording(recording, dir.path());
  EXPECT_FALSE(status.ok()) << "expected an error writing " << dir.path();
  return status.ok() ? "" : status.message();
}

// A stream with `rows` samples at irregular, nanosecond-exact times and seeded random values.
Stream MakeStream(const std::string& name, StreamType type, std::vector<std::string> columns, int rows,
                  std::mt19937* random) {
  Stream stream;
  stream.info.name = name;
  stream.info.type = type;
  stream.info.rate_hz = 100.0;
  stream.info.columns = std::move(columns);
  std::uniform_real_distribution<double> value(-50.0, 50.0);
  std::uniform_int_distribution<std::int64_t> step(1, 20000000);
  std::int64_t ns = 1431705823123456789;
  const Eigen::Index cols = type == StreamType::kCamera ? 0 : static_cast<Eigen::Index>(stream.info.columns.size());
  stream.values.resize(rows, cols);
  for (int i = 0; i < rows; ++i) {
    ns += step(*random);
    stream.t.push_back(Time::FromNanoseconds(ns));
    for (Eigen::Index c = 0; c < cols; ++c) stream.values(i, c) = value(*random);
    if (type == StreamType::kCamera) stream.text.push_back("frames/" + std::to_string(i) + ".png");
  }
  return stream;
}

// One stream of every type, with metadata in every optional field, and a ground truth.
Recording MakeFullRecording() {
  std::mt19937 random(7);
  Recording recording;
  recording.platform.kind = "ackermann";
  recording.platform.geometry = {{"wheelbase_m", 1.25}, {"track_m", 1.1}};
  recording.origin = GeodeticOrigin{45.47, 9.23, 120.0};
  recording.provenance = {"simulated", "scenarios/atv_hills.yaml", 1, "ATV on hills: \"quoted\", colon: yes"};
  // Every type, with its canonical columns (free ones for wheel_encoders and inputs).
  for (int i = 0; i <= static_cast<int>(StreamType::kInputs); ++i) {
    const auto type = static_cast<StreamType>(i);
    std::vector<std::string> columns = FixedColumns(type);
    if (type == StreamType::kWheelEncoders) columns = {"front_left", "front_right", "rear_left", "rear_right"};
    if (type == StreamType::kInputs) columns = {"speed_mps", "steering_rad"};
    recording.streams.push_back(MakeStream(StreamTypeName(type), type, columns, 20 + i, &random));
  }
  // Units, mounting, noise and attributes on a few of them.
  recording.streams[0].info.units = "rad/s,m/s^2";
  recording.streams[3].info.units = "uT";
  recording.streams[4].info.units = "deg";
  recording.streams[4].info.mounting =
      Mounting{Eigen::Vector3d(0.57, -0.46, 0.32), Eigen::Quaterniond(0.9, 0.1, -0.3, 0.2).normalized()};
  recording.streams[4].info.noise = {{"sigma_m", 0.33}};
  recording.streams[7].info.units = "rad/s";
  recording.streams[7].info.attributes = {{"ticks_per_revolution", 2048}, {"radius_m", 0.3}};
  recording.streams[12].info.attributes = {{"width_px", 640}, {"height_px", 480}, {"fx_px", 525.0},
                                           {"fy_px", 525.0},  {"cx_px", 319.5},   {"cy_px", 239.5}};
  // Ground truth.
  Trajectory truth;
  for (int i = 0; i < 5; ++i) {
    StampedPose pose;
    pose.t = Time::FromNanoseconds(1000000001LL * (i + 1));
    pose.p_world_body = Eigen::Vector3d(0.1 * i, -1.0 / 3.0, 2.0);
    pose.q_world_body = Eigen::Quaterniond(1.0, 0.01 * i, 0.02, -0.03).normalized();
    truth.push_back(pose);
  }
  recording.ground_truth = truth;
  return recording;
}

void ExpectSameStream(const Stream& a, const Stream& b) {
  SCOPED_TRACE(a.info.name);
  EXPECT_EQ(a.info.name, b.info.name);
  EXPECT_EQ(a.info.type, b.info.type);
  EXPECT_EQ(a.info.rate_hz, b.info.rate_hz);
  EXPECT_EQ(a.info.columns, b.info.columns);
  EXPECT_EQ(a.info.units, b.info.units);
  ASSERT_EQ(a.info.mounting.has_value(), b.info.mounting.has_value());
  if (a.info.mounting) {
    EXPECT_EQ(a.info.mounting->p_body_sensor, b.info.mounting->p_body_sensor);
    EXPECT_EQ(a.info.mounting->q_body_sensor.coeffs(), b.info.mounting->q_body_sensor.coeffs());
  }
  EXPECT_EQ(a.info.noise, b.info.noise);
  EXPECT_EQ(a.info.attributes, b.info.attributes);
  EXPECT_EQ(a.t, b.t);
  ASSERT_EQ(a.values.rows(), b.values.rows());
  ASSERT_EQ(a.values.cols(), b.values.cols());
  EXPECT_EQ(a.values, b.values);  // exact: 17 significant digits round-trip
  EXPECT_EQ(a.text, b.text);
}

TEST(StreamTypeTest, NamesRoundTrip) {
  for (int i = 0; i <= static_cast<int>(StreamType::kInputs); ++i) {
    const auto type = static_cast<StreamType>(i);
    EXPECT_EQ(ParseStreamType(StreamTypeName(type)), type) << StreamTypeName(type);
  }
  EXPECT_STREQ(StreamTypeName(StreamType::kWheelEncoders), "wheel_encoders");
  EXPECT_FALSE(ParseStreamType("lidar").has_value());
  EXPECT_FALSE(ParseStreamType("IMU").has_value());
}

TEST(RecordingTest, RoundTripAllStreamTypes) {
  TempDir dir;
  const Recording written = MakeFullRecording();
  ASSERT_TRUE(WriteRecording(written, dir.path()).ok());
  const Result<Recording> read = ReadRecording(dir.path());
  ASSERT_TRUE(read.ok()) << read.status().message();
  const Recording& r = read.value();

  // Metadata.
  EXPECT_EQ(r.format_version, 1);
  EXPECT_EQ(r.platform.kind, "ackermann");
  EXPECT_EQ(r.platform.geometry, written.platform.geometry);
  ASSERT_TRUE(r.origin.has_value());
  EXPECT_EQ(r.origin->latitude_deg, 45.47);
  EXPECT_EQ(r.origin->longitude_deg, 9.23);
  EXPECT_EQ(r.origin->altitude_m, 120.0);
  EXPECT_EQ(r.provenance.source, "simulated");
  EXPECT_EQ(r.provenance.scenario, "scenarios/atv_hills.yaml");
  EXPECT_EQ(r.provenance.seed, std::optional<std::uint64_t>(1));
  EXPECT_EQ(r.provenance.description, written.provenance.description);

  // Streams, including camera text and named wheel columns. Units left empty come back canonical.
  ASSERT_EQ(r.streams.size(), written.streams.size());
  for (std::size_t i = 0; i < r.streams.size(); ++i) {
    Stream expected = written.streams[i];
    if (expected.info.type == StreamType::kGyroscope) expected.info.units = "rad/s";
    if (expected.info.type == StreamType::kAccelerometer) expected.info.units = "m/s^2";
    if (expected.info.type == StreamType::kPosition || expected.info.type == StreamType::kPose) {
      expected.info.units = "m";
    }
    if (expected.info.type == StreamType::kSteering) expected.info.units = "rad";
    if (expected.info.type == StreamType::kOdometry || expected.info.type == StreamType::kVisualOdometry ||
        expected.info.type == StreamType::kScanMatching) {
      expected.info.units = "m/s,rad/s";
    }
    ExpectSameStream(expected, r.streams[i]);
  }
  const Stream* camera = r.Find("camera");
  ASSERT_NE(camera, nullptr);
  EXPECT_EQ(camera->text.at(3), "frames/3.png");
  EXPECT_EQ(camera->values.cols(), 0);
  EXPECT_EQ(r.Find("wheel_encoders")->info.columns.at(3), "rear_right");
  EXPECT_EQ(r.Find("no_such_stream"), nullptr);

  // Ground truth.
  ASSERT_TRUE(r.ground_truth.has_value());
  ASSERT_EQ(r.ground_truth->size(), written.ground_truth->size());
  for (std::size_t i = 0; i < r.ground_truth->size(); ++i) {
    EXPECT_EQ((*r.ground_truth)[i].t, (*written.ground_truth)[i].t);
    EXPECT_EQ((*r.ground_truth)[i].p_world_body, (*written.ground_truth)[i].p_world_body);
    EXPECT_EQ((*r.ground_truth)[i].q_world_body.coeffs(), (*written.ground_truth)[i].q_world_body.coeffs());
  }
}

TEST(RecordingTest, WritingIsByteIdentical) {
  TempDir first;
  TempDir second;
  // Units as the reader reports them, so that read -> write reproduces recording.yaml too.
  Recording recording = MakeFullRecording();
  {
    TempDir scratch;
    ASSERT_TRUE(WriteRecording(recording, scratch.path()).ok());
    const Result<Recording> canonical = ReadRecording(scratch.path());
    ASSERT_TRUE(canonical.ok()) << canonical.status().message();
    for (std::size_t i = 0; i < recording.streams.size(); ++i) {
      recording.streams[i].info.units = canonical.value().streams[i].info.units;
    }
  }
  ASSERT_TRUE(WriteRecording(recording, first.path()).ok());
  const std::string yaml = ReadFile(first.File("recording.yaml"));
  const std::string imu = ReadFile(first.File("imu.csv"));
  // Write again into the same directory, and read -> write into another one: the same bytes every time.
  ASSERT_TRUE(WriteRecording(recording, first.path()).ok());
  const Result<Recording> read = ReadRecording(first.path());
  ASSERT_TRUE(read.ok()) << read.status().message();
  ASSERT_TRUE(WriteRecording(read.value(), second.path()).ok());
  EXPECT_EQ(ReadFile(first.File("recording.yaml")), yaml);
  EXPECT_EQ(ReadFile(first.File("imu.csv")), imu);
  std::size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(first.path())) {
    const std::string name = entry.path().filename().string();
    EXPECT_EQ(ReadFile(first.File(name)), ReadFile(second.File(name))) << name;
    ++files;
  }
  EXPECT_EQ(files, recording.streams.size() + 2);  // + recording.yaml + ground_truth.tum
  // The schema keys come out in the documented order.
  EXPECT_EQ(yaml.rfind("format_version: 1\nplatform:\n  kind: ackermann\n", 0), 0u) << yaml;
  EXPECT_LT(yaml.find("origin:"), yaml.find("provenance:"));
  EXPECT_LT(yaml.find("provenance:"), yaml.find("streams:"));
  EXPECT_THAT(yaml, HasSubstr("wheelbase_m: 1.25"));
}

TEST(RecordingTest, ReadsHandWrittenFixture) {
  TempDir dir;
  WriteFixture(dir, kYaml, kGpsCsv, std::string(kImuCsv) + "\n\n");  // trailing blank lines are fine
  const Result<Recording> read = ReadRecording(dir.path(), ReadOptions{{"gps", "imu"}, true});
  ASSERT_TRUE(read.ok()) << read.status().message();
  const Stream* imu = read.value().Find("imu");
  ASSERT_NE(imu, nullptr);
  ASSERT_EQ(imu->t.size(), 3u);
  EXPECT_EQ(imu->t[1].nanoseconds(), 10000000);
  EXPECT_EQ(imu->values(2, 5), 9.81);
  EXPECT_EQ(imu->info.units, "rad/s,m/s^2");
  EXPECT_EQ(read.value().Find("gps")->values(1, 0), 45.4700001);
  EXPECT_FALSE(read.value().ground_truth.has_value());
}

TEST(RecordingTest, ConvertsDegreesPerSecondAndG) {
  TempDir dir;
  const std::string yaml = Replace(kYaml, "    type: imu\n", "    type: imu\n    units: deg/s,g\n") +
                           "  - name: gyro\n    type: gyroscope\n    rate_hz: 200\n    units: deg/s\n";
  WriteFixture(dir, yaml);
  WriteFile(dir.File("gyro.csv"), "t,wx,wy,wz\n1.5,180,-90,0\n");
  const Result<Recording> read = ReadRecording(dir.path());
  ASSERT_TRUE(read.ok()) << read.status().message();
  const Stream& gyro = *read.value().Find("gyro");
  EXPECT_EQ(gyro.info.units, "rad/s");
  EXPECT_NEAR(gyro.values(0, 0), kPi, 1e-15);
  EXPECT_NEAR(gyro.values(0, 1), -kPi / 2, 1e-15);
  const Stream& imu = *read.value().Find("imu");
  EXPECT_EQ(imu.info.units, "rad/s,m/s^2");
  EXPECT_NEAR(imu.values(0, 2), 0.1 * kPi / 180.0, 1e-15);  // deg/s -> rad/s
  EXPECT_NEAR(imu.values(0, 5), 9.81 * 9.80665, 1e-12);     // g -> m/s^2
}

TEST(RecordingTest, ConvertsTicksToRadians) {
  TempDir dir;
  const std::string yaml = std::string(kYaml) +
                           "  - name: wheels\n"
                           "    type: wheel_encoders\n"
                           "    rate_hz: 50\n"
                           "    units: ticks\n"
                           "    columns: [left, right]\n"
                           "    attributes: {ticks_per_revolution: 2048}\n";
  WriteFixture(dir, yaml);
  WriteFile(dir.File("wheels.csv"), "t,left,right\n0.0,0,0\n0.02,1024,-512\n");
  const Result<Recording> read = ReadRecording(dir.path());
  ASSERT_TRUE(read.ok()) << read.status().message();
  const Stream& wheels = *read.value().Find("wheels");
  EXPECT_EQ(wheels.info.units, "rad");
  EXPECT_EQ(wheels.info.columns, (std::vector<std::string>{"left", "right"}));
  EXPECT_NEAR(wheels.values(1, 0), kPi, 1e-15);
  EXPECT_NEAR(wheels.values(1, 1), -kPi / 2, 1e-15);

  // Without the resolution the ticks cannot be converted.
  WriteFixture(dir, Replace(yaml, "    attributes: {ticks_per_revolution: 2048}\n", ""));
  EXPECT_THAT(ReadError(dir), AllOf(HasSubstr("recording.yaml:15:"), HasSubstr("ticks_per_revolution")));
}

TEST(RecordingTest, GroundTruthIsOptional) {
  TempDir dir;
  ASSERT_TRUE(WriteRecording(MakeFullRecording(), dir.path()).ok());
  ReadOptions options;
  options.load_ground_truth = false;
  const Result<Recording> read = ReadRecording(dir.path(), options);
  ASSERT_TRUE(read.ok()) << read.status().message();
  EXPECT_FALSE(read.value().ground_truth.has_value());
  // Writing a recording without truth removes the stale file.
  Recording without_truth = MakeFullRecording();
  without_truth.ground_truth.reset();
  ASSERT_TRUE(WriteRecording(without_truth, dir.path()).ok());
  EXPECT_FALSE(std::filesystem::exists(dir.File("ground_truth.tum")));
  EXPECT_FALSE(ReadRecording(dir.path()).value().ground_truth.has_value());
}

// A recording written over an earlier one: the stream CSVs the earlier recording.yaml names and the new recording
// does not have are removed, with its truth.yaml; files that are not the earlier recording's stay. No temporary file
// is left.
TEST(RecordingTest, RewriteRemovesTheEarlierRecordingsStaleFiles) {
  TempDir dir;
  const Recording full = MakeFullRecording();
  ASSERT_GE(full.streams.size(), 2u);
  ASSERT_TRUE(WriteRecording(full, dir.path()).ok());
  WriteFile(dir.File("truth.yaml"), "calibration: {}\n");
  WriteFile(dir.File("notes.csv"), "not a stream of the recording\n");
  const std::string dropped = full.streams.back().info.name + ".csv";
  ASSERT_TRUE(std::filesystem::exists(dir.File(dropped)));

  Recording fewer = full;
  fewer.streams.pop_back();
  ASSERT_TRUE(WriteRecording(fewer, dir.path()).ok());
  EXPECT_FALSE(std::filesystem::exists(dir.File(dropped)));
  EXPECT_FALSE(std::filesystem::exists(dir.File("truth.yaml")));
  EXPECT_EQ(ReadFile(dir.File("notes.csv")), "not a stream of the recording\n");
  for (const Stream& stream : fewer.streams) EXPECT_TRUE(std::filesystem::exists(dir.File(stream.info.name + ".csv")));
  for (const auto& entry : std::filesystem::directory_iterator(dir.path()))
    EXPECT_EQ(entry.path().filename().string().find(".tmp-"), std::string::npos) << entry.path();
  const Result<Recording> read = ReadRecording(dir.path());
  ASSERT_TRUE(read.ok()) << read.status().message();
  EXPECT_EQ(read.value().streams.size(), fewer.streams.size());
}

TEST(RecordingTest, NeverOpensTruthYaml) {
  TempDir dir;
  WriteFixture(dir);
  WriteFile(dir.File("truth.yaml"), "calibration: [this is {not: valid\n\t: yaml");
  ASSERT_EQ(::chmod(dir.File("truth.yaml").c_str(), 0), 0);
  const Result<Recording> read = ReadRecording(dir.path());
  EXPECT_TRUE(read.ok()) << read.status().message();
}

// CSV errors: each names the file, the line and the problem.

TEST(RecordingCsvTest, TimestampGoingBackwards) {
  TempDir dir;
  WriteFixture(dir, kYaml, kGpsCsv, Replace(kImuCsv, "0.02,", "0.005,"));
  EXPECT_THAT(ReadError(dir), AllOf(HasSubstr("imu.csv:4:"), HasSubstr("goes backwards"), HasSubstr("0.005000000")));
}

TEST(RecordingCsvTest, RepeatedStampWithOtherValuesIsRefused) {
  TempDir dir;
  WriteFixture(dir, kYaml, kGpsCsv, Replace(kImuCsv, "0.02,0,0,0.1", "0.010,0,0,0.2"));
  EXPECT_THAT(ReadError(dir), AllOf(HasSubstr("imu.csv:4:"), HasSubstr("repeats the previous row's with other values"),
                                    HasSubstr("0.010000000")));
}

// A message delivered twice (the same stamp and values) is dropped and counted, not refused and not kept.
TEST(RecordingCsvTest, IdenticalRepeatedRowsAreDroppedAndCounted) {
  TempDir dir;
  WriteFixture(dir, kYaml, kGpsCsv,
               Replace(kImuCsv, "0.01,0,0,0.1,0,0,9.81\n",
                       "0.01,0,0,0.1,0,0,9.81\n0.010,0,0,0.1,0,0,9.81\n"
                       "0.01,0,0,0.1,0,0,9.81\n"));
  const Result<Recording> rec = ReadRecording(dir.path());
  ASSERT_TRUE(rec.ok()) << rec.status().message();
  const Stream& imu = *rec.value().Find("imu");
  EXPECT_EQ(imu.t.size(), 3u);
  EXPECT_EQ(imu.values.rows(), 3);
  EXPECT_EQ(imu.duplicate_rows_dropped, 2);
  EXPECT_EQ(rec.value().Find("gps")->duplicate_rows_dropped, 0);
  EXPECT_EQ(imu.t[2], Time::FromNanoseconds(20'000'000));
}

TEST(RecordingCsvTest, NaN) {
  TempDir dir;
  WriteFixture(dir, kYaml, kGpsCsv, Replace(kImuCsv, "0.01,0,0,0.1", "0.01,0,0,nan"));
  EXPECT_THAT(ReadError(dir), AllOf(HasSubstr("imu.csv:3:"), HasSubstr("column 'wz'"), HasSubstr("NaN")));
}

TEST(RecordingCsvTest, Inf) {
  TempDir dir;
  WriteFixture(dir, kYaml, kGpsCsv, Replace(kImuCsv, "0.01,0,0,0.1,0,0,9.81", "0.01,0,0,0.1,0,0,-inf"));
  EXPECT_THAT(ReadError(dir), AllOf(HasSubstr("imu.csv:3:"), HasSubstr("column 'az'"), HasSubstr("Inf")));
}

TEST(RecordingCsvTest, NotANumber) {
  TempDir dir;
  WriteFixture(dir, kYaml, kGpsCsv, Replace(kImuCsv, "0.01,0,0,0.1", "0.01,0,0,0.1abc"));
  EXPECT_THAT(ReadError(dir), AllOf(HasSubstr("imu.csv:3:"), HasSubstr("column 'wz'"), HasSubstr("not a number")));
}

TEST(RecordingCsvTest, WrongColumnCount) {
  TempDir dir;
  WriteFixture(dir, kYaml, "t,latitude,longitude,altitude\n0.0,45.47,9.23,120.0\n0.2,45.47,9.23\n");
  EXPECT_THAT(ReadError(dir), AllOf(HasSubstr("gps.csv:3:"), HasSubstr("expected 4 columns, found 3")));
}

TEST(RecordingCsvTest, WrongHeader) {
  TempDir dir;
  WriteFixture(dir, kYaml, Replace(kGpsCsv, "t,latitude,longitude", "t,lat,lon"));
  EXPECT_THAT(ReadError(dir),
              AllOf(HasSubstr("gps.csv:1:"), HasSubstr("header"), HasSubstr("t,latitude,longitude,altitude")));
}

TEST(RecordingCsvTest, EmptyFile) {
  TempDir dir;
  WriteFixture(dir, kYaml, "");
  EXPECT_THAT(ReadError(dir), AllOf(HasSubstr("gps.csv:1:"), HasSubstr("empty file")));
}

TEST(RecordingCsvTest, BlankLineInTheMiddle) {
  TempDir dir;
  WriteFixture(dir, kYaml, kGpsCsv, Replace(kImuCsv, "0.01,", "\n0.01,"));
  EXPECT_THAT(ReadError(dir), AllOf(HasSubstr("imu.csv:3:"), HasSubstr("blank line")));
}

// A file cut inside its last number ("9.8" of "9.81") without a line end is refused as truncated, with its line.
TEST(RecordingCsvTest, LastRowWithoutLineEndIsTruncated) {
  TempDir dir;
  WriteFixture(dir, kYaml, kGpsCsv, "t,wx,wy,wz,ax,ay,az\n0.00,0,0,0.1,0,0,9.81\n0.01,0,0,0.1,0,0,9.8");
  EXPECT_THAT(ReadError(dir), AllOf(HasSubstr("imu.csv:3:"), HasSubstr("no line end"), HasSubstr("truncated")));
  // With its line end (and blank lines after it) the same rows read.
  WriteFixture(dir, kYaml, kGpsCsv, "t,wx,wy,wz,ax,ay,az\n0.00,0,0,0.1,0,0,9.81\n0.01,0,0,0.1,0,0,9.8\r\n\n");
  EXPECT_TRUE(ReadRecording(dir.path()).ok());
  // A header alone needs none: there is no row to cut.
  WriteFixture(dir, kYaml, kGpsCsv, "t,wx,wy,wz,ax,ay,az");
  EXPECT_TRUE(ReadRecording(dir.path()).ok());
}

// Stamps past +-9e9 s would overflow the int64 nanoseconds; values past 1e15 are corruption, not measurements.
TEST(RecordingCsvTest, StampsAndValuesOutsideTheRange) {
  TempDir dir;
  WriteFixture(dir, kYaml, kGpsCsv, Replace(kImuCsv, "0.02,", "9223372036.900000000,"));
  EXPECT_THAT(ReadError(dir), AllOf(HasSubstr("imu.csv:4:"), HasSubstr("not a time")));
  WriteFixture(dir, kYaml, kGpsCsv, Replace(kImuCsv, "0.02,0,0,0.1", "0.02,0,0,4.75e301"));
  EXPECT_THAT(ReadError(dir), AllOf(HasSubstr("imu.csv:4:"), HasSubstr("column 'wz'"), HasSubstr("beyond")));
}

TEST(RecordingYamlTest, ValuesOutsideThePhysicalRange) {
  TempDir dir;
  WriteFixture(
      dir, Replace(kYaml, "    rate_hz: 100\n", "    rate_hz: 100\n    mounting: {p_body_sensor_m: [9.2e18, 0, 0]}\n"));
  EXPECT_THAT(ReadError(dir), AllOf(HasSubstr("recording.yaml:12:"), HasSubstr("p_body_sensor_m of stream 'imu'"),
                                    HasSubstr("physical range")));
  WriteFixture(dir, Replace(kYaml, "    rate_hz: 100\n", "    rate_hz: 100\n    noise: {sigma_radps: 1e300}\n"));
  EXPECT_THAT(ReadError(dir),
              AllOf(HasSubstr("recording.yaml:12:"), HasSubstr("sigma_radps 1e+300"), HasSubstr("(|value| <= 1e+09)")));
  WriteFixture(dir, Replace(kYaml, "rate_hz: 100", "rate_hz: 1e300"));
  EXPECT_THAT(ReadError(dir), AllOf(HasSubstr("recording.yaml:"), HasSubstr("at most 1e6")));
  WriteFixture(dir, Replace(kYaml, "rate_hz: 5\n", "rate_hz: 5\n    rate_hz: 6\n"));
  EXPECT_THAT(ReadError(dir), AllOf(HasSubstr("recording.yaml:"), HasSubstr("duplicate key 'rate_hz'")));
}

TEST(RecordingCsvTest, MissingFile) {
  TempDir dir;
  WriteFixture(dir);
  std::filesystem::remove(dir.File("gps.csv"));
  EXPECT_THAT(ReadError(dir), AllOf(HasSubstr("gps.csv"), HasSubstr("cannot open")));
}

// recording.yaml errors: each names the file, the line and the key or value.

TEST(RecordingYamlTest, UnknownStreamType) {
  TempDir dir;
  WriteFixture(dir, Replace(kYaml, "type: imu", "type: lidar"));
  EXPECT_THAT(ReadError(dir), AllOf(HasSubstr("recording.yaml:10:"), HasSubstr("unknown stream type 'lidar'"),
                                    HasSubstr("stream 'imu'")));
}

TEST(RecordingYamlTest, UnknownKeyAtTopLevel) {
  TempDir dir;
  WriteFixture(dir, Replace(kYaml, "platform:\n", "colour: red\nplatform:\n"));
  EXPECT_THAT(ReadError(dir), AllOf(HasSubstr("recording.yaml:2:"), HasSubstr("unknown key 'colour'")));
}

TEST(RecordingYamlTest, UnknownKeyInStream) {
  TempDir dir;
  WriteFixture(dir, Replace(kYaml, "    rate_hz: 100\n", "    rate_hz: 100\n    sigma: 3\n"));
  EXPECT_THAT(ReadError(dir), AllOf(HasSubstr("recording.yaml:12:"), HasSubstr("unknown key 'sigma' in stream 'imu'")));
}

TEST(RecordingYamlTest, UnknownKeyInMounting) {
  TempDir dir;
  WriteFixture(dir, Replace(kYaml, "    rate_hz: 5\n", "    rate_hz: 5\n    mounting: {lever_arm: [0, 0, 1]}\n"));
  EXPECT_THAT(ReadError(dir), AllOf(HasSubstr("recording.yaml:9:"), HasSubstr("unknown key 'lever_arm'"),
                                    HasSubstr("mounting of stream 'gps'")));
}

TEST(RecordingYamlTest, UnknownUnits) {
  TempDir dir;
  WriteFixture(dir, Replace(kYaml, "    rate_hz: 5\n", "    rate_hz: 5\n    units: furlong\n"));
  EXPECT_THAT(ReadError(dir),
              AllOf(HasSubstr("recording.yaml:9:"), HasSubstr("unknown units 'furlong' for stream 'gps' of type gps")));
}

TEST(RecordingYamlTest, MissingRequiredKey) {
  TempDir dir;
  WriteFixture(dir, Replace(kYaml, "    rate_hz: 100\n", ""));
  EXPECT_THAT(ReadError(dir), AllOf(HasSubstr("recording.yaml:9:"), HasSubstr("missing required key 'rate_hz'"),
                                    HasSubstr("stream 'imu'")));
}

TEST(RecordingYamlTest, MissingRequiredStream) {
  TempDir dir;
  WriteFixture(dir);
  ReadOptions options;
  options.required_streams = {"imu", "wheels"};
  EXPECT_THAT(ReadError(dir, options),
              AllOf(HasSubstr(dir.File("recording.yaml")), HasSubstr("required stream 'wheels' missing")));
}

TEST(RecordingYamlTest, GpsWithoutOrigin) {
  TempDir dir;
  WriteFixture(dir, Replace(kYaml, "origin: {latitude_deg: 45.47, longitude_deg: 9.23, altitude_m: 120.0}\n", ""));
  EXPECT_THAT(ReadError(dir), AllOf(HasSubstr("recording.yaml"), HasSubstr("stream 'gps'"), HasSubstr("no origin")));
}

TEST(RecordingYamlTest, BadFormatVersion) {
  TempDir dir;
  WriteFixture(dir, Replace(kYaml, "format_version: 1", "format_version: 2"));
  EXPECT_THAT(ReadError(dir), AllOf(HasSubstr("recording.yaml:1:"), HasSubstr("unsupported format_version 2")));
}

TEST(RecordingYamlTest, FixedColumnsMustMatch) {
  TempDir dir;
  WriteFixture(dir, Replace(kYaml, "    rate_hz: 5\n", "    rate_hz: 5\n    columns: [lat, lon, alt]\n"));
  EXPECT_THAT(ReadError(dir), AllOf(HasSubstr("recording.yaml:9:"), HasSubstr("do not match type gps")));
}

TEST(RecordingYamlTest, SyntaxError) {
  TempDir dir;
  WriteFixture(dir, Replace(kYaml, "  kind: ackermann\n", "  kind: [ackermann\n"));
  EXPECT_THAT(ReadError(dir), HasSubstr("recording.yaml:"));
}

// The writer refuses what the reader would refuse.

TEST(RecordingWriteTest, RejectsInvalidRecordings) {
  TempDir dir;
  const Recording valid = MakeFullRecording();
  ASSERT_TRUE(WriteRecording(valid, dir.path()).ok());

  Recording duplicate = valid;
  duplicate.streams[1].info.name = duplicate.streams[0].info.name;
  EXPECT_THAT(WriteError(duplicate, dir), HasSubstr("duplicate stream name 'imu'"));

  Recording columns = valid;
  columns.streams[0].values.conservativeResize(Eigen::NoChange, 5);
  EXPECT_THAT(WriteError(columns, dir), HasSubstr("values have 5 columns, expected 6"));

  Recording rows = valid;
  rows.streams[1].t.pop_back();
  EXPECT_THAT(WriteError(rows, dir), HasSubstr("rows for"));

  Recording order = valid;
  order.streams[2].t[4] = order.streams[2].t[3];
  EXPECT_THAT(WriteError(order, dir), AllOf(HasSubstr("sample 4"), HasSubstr("duplicate")));
  // An identical row (a duplicated message) is written as it is; the reader drops it.
  Recording twice = valid;
  twice.streams[2].t[4] = twice.streams[2].t[3];
  twice.streams[2].values.row(4) = twice.streams[2].values.row(3);
  if (!twice.streams[2].text.empty()) twice.streams[2].text[4] = twice.streams[2].text[3];
  ASSERT_TRUE(WriteRecording(twice, dir.path()).ok());
  const Result<Recording> reread = ReadRecording(dir.path());
  ASSERT_TRUE(reread.ok()) << reread.status().message();
  EXPECT_EQ(reread.value().streams[2].duplicate_rows_dropped, 1);
  EXPECT_EQ(reread.value().streams[2].t.size(), valid.streams[2].t.size() - 1);

  Recording nan = valid;
  nan.streams[2].values(0, 0) = std::nan("");
  EXPECT_THAT(WriteError(nan, dir), HasSubstr("NaN"));

  Recording ticks = valid;
  ticks.streams[7].info.units = "ticks";
  EXPECT_THAT(WriteError(ticks, dir), HasSubstr("not canonical"));

  Recording no_origin = valid;
  no_origin.origin.reset();
  EXPECT_THAT(WriteError(no_origin, dir), HasSubstr("needs an origin"));
}

// Velocity streams may carry their covariance; camera and visual_odometry streams their intrinsics.

// A visual_odometry stream with the covariance columns and the intrinsics: two samples.
Recording MakeVisualOdometryRecording() {
  Recording recording;
  recording.platform.kind = "differential_drive";
  Stream stream;
  stream.info.name = "vo";
  stream.info.type = StreamType::kVisualOdometry;
  stream.info.rate_hz = 15.0;
  stream.info.columns = FixedColumns(StreamType::kVisualOdometry);
  for (const std::string& c : CovarianceColumns(StreamType::kVisualOdometry)) stream.info.columns.push_back(c);
  stream.info.attributes = {{"width_px", 320}, {"height_px", 240}, {"fx_px", 207.8},
                            {"fy_px", 207.8},  {"cx_px", 159.5},   {"cy_px", 119.5}};
  stream.t = {Time::FromSeconds(0.1), Time::FromSeconds(0.2)};
  stream.values = Eigen::MatrixXd::Constant(2, 27, 1e-4);
  stream.values.leftCols(6).setConstant(0.5);
  recording.streams.push_back(stream);
  return recording;
}

TEST(RecordingCovarianceTest, ColumnsNameTheUpperTriangle) {
  const std::vector<std::string>& c = CovarianceColumns(StreamType::kVisualOdometry);
  ASSERT_EQ(c.size(), 21u);
  EXPECT_EQ(c[0], "cov_vx_vx");
  EXPECT_EQ(c[5], "cov_vx_wz");
  EXPECT_EQ(c[6], "cov_vy_vy");
  EXPECT_EQ(c[20], "cov_wz_wz");
  EXPECT_EQ(CovarianceColumns(StreamType::kScanMatching), c);
  EXPECT_TRUE(CovarianceColumns(StreamType::kImu).empty());
}

TEST(RecordingCovarianceTest, RoundTripWithIntrinsics) {
  TempDir dir;
  const Recording recording = MakeVisualOdometryRecording();
  ASSERT_TRUE(WriteRecording(recording, dir.path()).ok());
  const Result<Recording> read = ReadRecording(dir.path());
  ASSERT_TRUE(read.ok()) << read.status().message();
  const Stream& stream = read.value().streams.at(0);
  EXPECT_EQ(stream.info.columns, recording.streams[0].info.columns);
  EXPECT_EQ(stream.values, recording.streams[0].values);
  EXPECT_EQ(stream.info.attributes, recording.streams[0].info.attributes);
  EXPECT_THAT(ReadFile(dir.File("vo.csv")), HasSubstr("t,vx,vy,vz,wx,wy,wz,cov_vx_vx,cov_vx_vy,"));
}

TEST(RecordingCovarianceTest, NegativeVarianceIsRefusedWithItsLine) {
  TempDir dir;
  Recording recording = MakeVisualOdometryRecording();
  ASSERT_TRUE(WriteRecording(recording, dir.path()).ok());
  // Second sample (line 3), cov_vy_vy (index 6 + 6).
  std::string csv = ReadFile(dir.File("vo.csv"));
  const std::size_t line3 = csv.find('\n', csv.find('\n') + 1) + 1;
  std::size_t at = line3;
  for (int comma = 0; comma < 13; ++comma) at = csv.find(',', at) + 1;
  csv.insert(at, "-");
  WriteFile(dir.File("vo.csv"), csv);
  EXPECT_THAT(ReadError(dir), AllOf(HasSubstr("vo.csv:3:"), HasSubstr("cov_vy_vy is negative")));
  recording.streams[0].values(1, 12) = -1.0;
  EXPECT_THAT(WriteError(recording, dir), AllOf(HasSubstr("row 3"), HasSubstr("cov_vy_vy is negative")));
}

// A covariance that is not positive semi-definite (|cov_vx_vy| above sqrt(cov_vx_vx cov_vy_vy)), or with an entry
// beyond 1e12, would reach the estimator as a noise model it cannot factor: refused with its line.
TEST(RecordingCovarianceTest, NotPositiveSemiDefiniteOrHugeIsRefused) {
  TempDir dir;
  Recording recording = MakeVisualOdometryRecording();
  recording.streams[0].values(1, 7) = 1e308;  // cov_vx_vy
  EXPECT_THAT(WriteError(recording, dir), HasSubstr("beyond the physical range"));
  recording = MakeVisualOdometryRecording();
  const double vx = recording.streams[0].values(1, 6), vy = recording.streams[0].values(1, 12);
  recording.streams[0].values(1, 7) = 2.0 * std::sqrt(vx * vy) + 1.0;  // cov_vx_vy
  EXPECT_THAT(WriteError(recording, dir), HasSubstr("not positive semi-definite"));
  recording = MakeVisualOdometryRecording();
  ASSERT_TRUE(WriteRecording(recording, dir.path()).ok());
  std::string csv = ReadFile(dir.File("vo.csv"));
  // Line 3, cov_vx_vy (column 8 after t): a large off-diagonal.
  const std::size_t line3 = csv.find('\n', csv.find('\n') + 1) + 1;
  std::size_t at = line3;
  for (int comma = 0; comma < 8; ++comma) at = csv.find(',', at) + 1;
  csv.replace(at, csv.find(',', at) - at, "1e6");
  WriteFile(dir.File("vo.csv"), csv);
  EXPECT_THAT(ReadError(dir), AllOf(HasSubstr("vo.csv:3:"), HasSubstr("not positive semi-definite")));
}

TEST(RecordingCovarianceTest, IntrinsicsAreAllOrNoneAndSane) {
  TempDir dir;
  Recording partial = MakeVisualOdometryRecording();
  partial.streams[0].info.attributes.erase("cy_px");
  EXPECT_THAT(WriteError(partial, dir), HasSubstr("cy_px is missing"));
  Recording outside = MakeVisualOdometryRecording();
  outside.streams[0].info.attributes["cx_px"] = 320.0;
  EXPECT_THAT(WriteError(outside, dir), HasSubstr("principal point"));
  // The reader says the same, with the line of the attributes.
  ASSERT_TRUE(WriteRecording(MakeVisualOdometryRecording(), dir.path()).ok());
  const std::string yaml = ReadFile(dir.File("recording.yaml"));
  WriteFile(dir.File("recording.yaml"), Replace(yaml, "fy_px: 207.8", "fy_px: 0"));
  EXPECT_THAT(ReadError(dir), AllOf(HasSubstr("recording.yaml:"), HasSubstr("fx_px and fy_px must be positive")));
}

TEST(RecordingCovarianceTest, OtherColumnsStillMustMatch) {
  TempDir dir;
  Recording recording = MakeVisualOdometryRecording();
  recording.streams[0].info.columns.pop_back();
  EXPECT_THAT(WriteError(recording, dir), HasSubstr("optionally followed by the 21 covariance columns"));
}

// Found by recording_fuzz's kind of input (csv_fuzz on a YAML file): the parser's message quotes a line break.
TEST(RecordingTest, UnreadableRecordingYamlIsOneLineNamingTheFile) {
  TempDir dir;
  WriteFile(dir.File("recording.yaml"), std::string("\xff\0\n", 3));
  const std::string error = ReadError(dir);
  EXPECT_THAT(error, HasSubstr(dir.File("recording.yaml")));
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
}

}  // namespace
}  // namespace roamlab::recording
