// The CSV importer (importers/csv.h): the real x-io IMU/magnetometer log with its mapping, a wide epoch-millisecond
// CSV written from an in-memory recording, every unit against its definition, and each bad input's one-line error.
#include "importers/csv.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include <gtest/gtest.h>

namespace roamlab::importers {
namespace {

namespace fs = std::filesystem;
using recording::Recording;
using recording::Stream;

constexpr double kPi = 3.14159265358979323846;
constexpr double kG = 9.80665;

class CsvImportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / (std::string("roamlab_csv_") + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Write(const std::string& name, const std::string& content) const {
    const std::string path = (dir_ / name).string();
    std::ofstream(path, std::ios::binary) << content;
    return path;
  }

  // Imports one file with a mapping given as text; the error message, or "" on success.
  std::string ImportError(const std::string& csv_path, const std::string& mapping) {
    const Result<Recording> rec = ImportCsv({csv_path}, Write("map.yaml", mapping), &report_);
    return rec.ok() ? "" : rec.status().message();
  }

  fs::path dir_;
  CsvImportReport report_;
};

const Stream& Get(const Recording& rec, const std::string& name) {
  const Stream* stream = rec.Find(name);
  EXPECT_NE(stream, nullptr) << name;
  return *stream;
}

// --- The real log: x-io Technologies Fusion example (100 Hz IMU, slower magnetometer repeated on every row).

TEST_F(CsvImportTest, XioImuMagnetometerLog) {
  const std::string csv = std::string(ROAMLAB_SHARED_DIR) + "/data/xio_imu_mag/sensor_data.csv";
  if (!fs::exists(csv)) GTEST_SKIP() << "the x-io log is absent: " << csv;
  const std::string mapping = std::string(ROAMLAB_SOURCE_DIR) + "/configs/import/xio_imu_mag.yaml";
  CsvImportReport report;
  const Result<Recording> result = ImportCsv({csv}, mapping, &report);
  ASSERT_TRUE(result.ok()) << result.status().message();
  const Recording& rec = result.value();

  // Rows, read independently: the raw degrees per second and the repeats of the magnetometer triple.
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    std::vector<double> row;
    std::stringstream cells(line);
    std::string cell;
    while (std::getline(cells, cell, ',')) row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  std::int64_t repeats = 0;
  for (std::size_t i = 1; i < rows.size(); ++i) {
    repeats += std::equal(rows[i].begin() + 7, rows[i].end(), rows[i - 1].begin() + 7) ? 1 : 0;
  }
  ASSERT_EQ(report.files.size(), 1u);
  EXPECT_EQ(report.files[0].rows, static_cast<std::int64_t>(rows.size()));
  const Stream& imu = Get(rec, "imu");
  const Stream& mag = Get(rec, "magnetometer");
  EXPECT_EQ(imu.t.size(), rows.size());
  EXPECT_EQ(report.streams[1].collapsed, repeats);
  EXPECT_EQ(static_cast<std::int64_t>(mag.t.size()) + repeats, static_cast<std::int64_t>(rows.size()));
  EXPECT_EQ(mag.info.units, "uT");
  EXPECT_EQ(imu.t.front(), Time::FromNanoseconds(0));

  // Gyro from deg/s, row by row.
  for (std::size_t i = 0; i < rows.size(); i += 997) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(imu.values(static_cast<Eigen::Index>(i), k), rows[i][static_cast<std::size_t>(k + 1)] * kPi / 180.0,
                  1e-15);
    }
  }
  // At rest (the first second, gyro below 1 deg/s on every axis): |accel| near g, within 4 standard errors of
  // the mean plus the sensor's scale uncertainty (1 %).
  std::vector<double> norms;
  for (std::size_t i = 0; i < rows.size() && imu.t[i].seconds() < 1.0; ++i) {
    if (imu.values.row(static_cast<Eigen::Index>(i)).head<3>().cwiseAbs().maxCoeff() < kPi / 180.0) {
      norms.push_back(imu.values.row(static_cast<Eigen::Index>(i)).tail<3>().norm());
    }
  }
  ASSERT_GT(norms.size(), 20u);
  double mean = 0.0, var = 0.0;
  for (double n : norms) mean += n / static_cast<double>(norms.size());
  for (double n : norms) var += (n - mean) * (n - mean) / static_cast<double>(norms.size() - 1);
  EXPECT_NEAR(mean, kG, 4.0 * std::sqrt(var / static_cast<double>(norms.size())) + 0.01 * kG);
  // Field magnitude in the log's known 37-51 uT range: its 0.5 % and 99.5 % quantiles (a handful of samples reach
  // 51.2 uT while the sensor is swung), so the conversion and the by_change collapse kept the field as logged.
  const Eigen::VectorXd field = mag.values.rowwise().norm();
  std::vector<double> sorted(field.data(), field.data() + field.size());
  std::sort(sorted.begin(), sorted.end());
  EXPECT_GT(sorted[sorted.size() / 200], 37.0);
  EXPECT_LT(sorted[sorted.size() - 1 - sorted.size() / 200], 51.0);
  // The CLI's output reads back (ReadRecording is what every command uses).
  ASSERT_TRUE(recording::WriteRecording(rec, (dir_ / "rec").string()).ok());
  const Result<Recording> back = recording::ReadRecording((dir_ / "rec").string());
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(Get(back.value(), "magnetometer").t.size(), mag.t.size());
}

// --- A wide CSV written from an in-memory recording: Unix-epoch milliseconds, gyro in deg/s, accel in g, wheel
// speeds in km/h, the 10 Hz GPS fix repeated on every 50 Hz row.

struct Synthetic {
  Recording rec;
  std::string csv;
};

Synthetic MakeWideCsv(std::int64_t t0_ms, int imu_samples) {
  std::mt19937 rng(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  Stream imu, gps, wheels;
  imu.info.name = "imu";
  imu.info.type = recording::StreamType::kImu;
  imu.values.resize(imu_samples, 6);
  wheels.info.name = "wheels";
  wheels.info.type = recording::StreamType::kWheelEncoders;
  wheels.info.units = "m/s";
  wheels.values.resize(imu_samples, 2);
  gps.info.name = "gps";
  gps.info.type = recording::StreamType::kGps;
  gps.values.resize((imu_samples + 4) / 5, 3);
  std::ostringstream csv;
  csv.precision(17);
  csv << "time_ms,gx_dps,gy_dps,gz_dps,ax_g,ay_g,az_g,lat,lon,alt,gps_time_ms,speed_left_kmh,speed_right_kmh\n";
  for (int i = 0; i < imu_samples; ++i) {
    const std::int64_t t_ms = t0_ms + 20 * i;
    imu.t.push_back(Time::FromNanoseconds(t_ms * 1000000));
    wheels.t.push_back(imu.t.back());
    for (int k = 0; k < 6; ++k) imu.values(i, k) = (k < 3 ? 0.3 : 2.0) * normal(rng) + (k == 5 ? kG : 0.0);
    for (int k = 0; k < 2; ++k) wheels.values(i, k) = 3.0 + 0.5 * normal(rng);
    if (i % 5 == 0) {
      gps.t.push_back(imu.t.back());
      const int j = i / 5;
      gps.values.row(j) << 45.0 + 1e-5 * j + 1e-7 * normal(rng), 9.0 + 2e-5 * j, 120.0 + 0.5 * normal(rng);
    }
    const int j = i / 5;
    csv << t_ms;
    for (int k = 0; k < 6; ++k) csv << "," << imu.values(i, k) / (k < 3 ? kPi / 180.0 : kG);
    csv << "," << gps.values(j, 0) << "," << gps.values(j, 1) << "," << gps.values(j, 2) << "," << t0_ms + 100 * j;
    for (int k = 0; k < 2; ++k) csv << "," << wheels.values(i, k) * 3.6;
    csv << "\n";
  }
  Synthetic out;
  out.rec.streams = {imu, gps, wheels};
  out.csv = csv.str();
  return out;
}

constexpr const char* kWideMapping = R"(
time: {column: time_ms, unit: ms, clock: epoch}
platform: {kind: ackermann, geometry: {wheelbase_m: 1.2}}
streams:
  imu:
    type: imu
    columns: [gx_dps, gy_dps, gz_dps, ax_g, ay_g, az_g]
    units: [deg/s, deg/s, deg/s, g, g, g]
    rate_hz: 50
    noise: {sigma_radps: 0.01}
  gps:
    type: gps
    columns: [lat, lon, alt]
    collapse: by_change
  gps_fix:
    type: gps
    columns: [lat, lon, alt]
    collapse: {by_column: gps_time_ms, unit: ms}
  wheels:
    type: wheel_encoders
    columns: [speed_left_kmh, speed_right_kmh]
    names: [left, right]
    units: km/h
)";

void ExpectValuesNear(const Stream& actual, const Stream& expected, double tolerance) {
  ASSERT_EQ(actual.t.size(), expected.t.size()) << actual.info.name;
  for (std::size_t i = 0; i < actual.t.size(); ++i) ASSERT_EQ(actual.t[i], expected.t[i]) << actual.info.name << i;
  ASSERT_EQ(actual.values.cols(), expected.values.cols());
  EXPECT_LE((actual.values - expected.values).cwiseAbs().maxCoeff(), tolerance) << actual.info.name;
}

TEST_F(CsvImportTest, WideEpochCsvFromARecordingComesBack) {
  const int n = 501;  // 10 s at 50 Hz: 101 GPS fixes
  const Synthetic synthetic = MakeWideCsv(1700000000000, n);
  const std::string csv = Write("wide.csv", synthetic.csv);
  const Result<Recording> result = ImportCsv({csv}, Write("map.yaml", kWideMapping), &report_);
  ASSERT_TRUE(result.ok()) << result.status().message();
  const Recording& rec = result.value();
  // Unit conversion of a 17-digit text: a few ulps of each value.
  ExpectValuesNear(Get(rec, "imu"), synthetic.rec.streams[0], 1e-13);
  ExpectValuesNear(Get(rec, "gps"), synthetic.rec.streams[1], 0.0);
  ExpectValuesNear(Get(rec, "gps_fix"), synthetic.rec.streams[1], 0.0);
  ExpectValuesNear(Get(rec, "wheels"), synthetic.rec.streams[2], 1e-14);
  EXPECT_EQ(Get(rec, "wheels").info.units, "m/s");
  EXPECT_EQ(Get(rec, "imu").info.noise.at("sigma_radps"), 0.01);
  EXPECT_NEAR(Get(rec, "gps").info.rate_hz, 10.0, 1e-9);
  EXPECT_EQ(rec.platform.kind, "ackermann");
  // Collapse: exactly the 10 Hz updates, the other rows counted.
  ASSERT_EQ(report_.streams.size(), 4u);
  EXPECT_EQ(report_.files[0].rows, n);
  EXPECT_EQ(report_.streams[1].name, "gps");
  EXPECT_EQ(report_.streams[1].samples, 101);
  EXPECT_EQ(report_.streams[1].collapsed, n - 101);
  EXPECT_EQ(report_.streams[2].collapsed, n - 101);
  EXPECT_EQ(report_.streams[0].collapsed, 0);
  // Origin: the first kept fix; the recording writes and reads back.
  ASSERT_TRUE(rec.origin.has_value());
  EXPECT_EQ(rec.origin->latitude_deg, synthetic.rec.streams[1].values(0, 0));
  const std::string out = (dir_ / "rec").string();
  ASSERT_TRUE(recording::WriteRecording(rec, out).ok());
  const Result<Recording> back = recording::ReadRecording(out);
  ASSERT_TRUE(back.ok()) << back.status().message();
  ExpectValuesNear(Get(back.value(), "imu"), synthetic.rec.streams[0], 1e-13);
}

TEST_F(CsvImportTest, RelativeClockAndSeveralFilesShareOneClock) {
  // File a: seconds from a device clock starting at 1000 s; file b: milliseconds of the same clock, 0.5 s later,
  // semicolon-separated without header, after two comment lines.
  const std::string a = Write("a.csv", "t,x\n1000.0,1\n1000.1,2\n1000.2,3\n");
  const std::string b = Write("b.csv", "# gyro log\n# t_ms;w\n1000500;10\n1000600;20\n");
  const std::string mapping = Write("map.yaml", R"(
time: {column: t, unit: s}
files:
  - {}
  - {delimiter: ";", header: false, comment: "#", time: {column: 0, unit: ms}}
streams:
  steer: {type: steering, columns: [x], units: deg}
  yaw: {type: gyroscope, file: 1, columns: [1, 1, 1], units: rpm}
)");
  const Result<Recording> result = ImportCsv({a, b}, mapping, &report_);
  ASSERT_TRUE(result.ok()) << result.status().message();
  const Stream& steer = Get(result.value(), "steer");
  const Stream& yaw = Get(result.value(), "yaw");
  EXPECT_EQ(steer.t.front(), Time::FromNanoseconds(0));
  EXPECT_EQ(steer.t.back(), Time::FromNanoseconds(200000000));
  EXPECT_EQ(yaw.t.front(), Time::FromNanoseconds(500000000));
  EXPECT_EQ(report_.files[1].ignored_lines, 2);
  EXPECT_EQ(report_.files[1].rows, 2);
  EXPECT_DOUBLE_EQ(yaw.values(1, 2), 20.0 * 2.0 * kPi / 60.0);
}

}  // namespace
}  // namespace roamlab::importers
