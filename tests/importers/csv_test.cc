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

#include "tests/support/paths.h"
#include "tests/support/real_data.h"

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
  const std::string csv = ::roamlab::testing::RealData("xio_imu_mag/sensor_data.csv");
  if (!fs::exists(csv)) GTEST_SKIP() << "the x-io log is absent: " << csv;
  const std::string mapping = roamlab::testing::SourceDir() + "/configs/import/xio_imu_mag.yaml";
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

// --- Every unit against its definition.

struct UnitCase {
  std::string type;
  std::string units;           // as written in the mapping
  std::string columns;         // source columns
  std::vector<double> factor;  // canonical value per source value, per column, from the unit's definition
  std::string extra;           // more keys of the entry
};

TEST_F(CsvImportTest, EveryUnitConvertsByItsDefinition) {
  const double deg = kPi / 180.0;
  const double rpm = 2.0 * kPi / 60.0;
  const double kmh = 1000.0 / 3600.0, mph = 1609.344 / 3600.0, knot = 1852.0 / 3600.0, ft = 0.3048;
  const std::vector<UnitCase> cases = {
      {"steering", "rad", "[a]", {1.0}, ""},
      {"steering", "deg", "[a]", {deg}, ""},
      {"wheel_encoders",
       "ticks",
       "[a, b]",
       {2.0 * kPi / 4096.0, 2.0 * kPi / 4096.0},
       "names: [l, r], attributes: {ticks_per_revolution: 4096}"},
      {"wheel_encoders", "rad/s", "[a, b]", {1.0, 1.0}, "names: [l, r]"},
      {"gyroscope", "rad/s", "[a, b, c]", {1.0, 1.0, 1.0}, ""},
      {"gyroscope", "deg/s", "[a, b, c]", {deg, deg, deg}, ""},
      {"gyroscope", "rpm", "[a, b, c]", {rpm, rpm, rpm}, ""},
      {"accelerometer", "m/s^2", "[a, b, c]", {1.0, 1.0, 1.0}, ""},
      {"accelerometer", "g", "[a, b, c]", {kG, kG, kG}, ""},
      {"wheel_encoders", "[m/s, km/h, mph]", "[a, b, c]", {1.0, kmh, mph}, "names: [x, y, z]"},
      {"wheel_encoders", "[knots, ft/s]", "[a, b]", {knot, ft}, "names: [x, y]"},
      {"magnetometer", "[uT, nT, mT]", "[a, b, c]", {1.0, 1e-3, 1e3}, ""},
      {"magnetometer", "[T, gauss, mG]", "[a, b, c]", {1e6, 1e-4 * 1e6, 1e-7 * 1e6}, ""},
      {"magnetometer", "normalized", "[a, b, c]", {1.0, 1.0, 1.0}, ""},
      {"position", "[m, mm, cm]", "[a, b, c]", {1.0, 1e-3, 1e-2}, ""},
      {"position", "[km, ft, in]", "[a, b, c]", {1e3, ft, 0.0254}, ""},
      {"pose", "mm", "[a, b, c, a, b, c, a]", {1e-3, 1e-3, 1e-3, 1.0, 1.0, 1.0, 1.0}, ""},
      {"gps", "[rad, rad, ft]", "[a, b, c]", {1.0 / deg, 1.0 / deg, ft}, ""},
      {"odometry", "[km/h, mph, knots, deg/s, rpm, rad/s]", "[a, b, c, a, b, c]", {kmh, mph, knot, deg, rpm, 1.0}, ""},
  };
  std::string mapping =
      "time: {column: t, unit: s}\norigin: {latitude_deg: 0, longitude_deg: 0, altitude_m: 0}\n"
      "streams:\n";
  for (std::size_t i = 0; i < cases.size(); ++i) {
    mapping += "  s" + std::to_string(i) + ": {type: " + cases[i].type + ", columns: " + cases[i].columns +
               ", units: " + cases[i].units + (cases[i].extra.empty() ? "" : ", " + cases[i].extra) + "}\n";
  }
  const std::string csv = Write("units.csv", "t,a,b,c\n0,1.5,-2,3.25\n1,0.5,4e3,-8\n");
  const Result<Recording> result = ImportCsv({csv}, Write("map.yaml", mapping), &report_);
  ASSERT_TRUE(result.ok()) << result.status().message();
  const double raw[2][3] = {{1.5, -2.0, 3.25}, {0.5, 4e3, -8.0}};
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const Stream& s = Get(result.value(), "s" + std::to_string(i));
    ASSERT_EQ(s.values.cols(), static_cast<Eigen::Index>(cases[i].factor.size()));
    for (int row = 0; row < 2; ++row) {
      for (Eigen::Index c = 0; c < s.values.cols(); ++c) {
        const double expected = raw[row][c % 3] * cases[i].factor[static_cast<std::size_t>(c)];
        EXPECT_NEAR(s.values(row, c), expected, 1e-14 * std::abs(expected))
            << cases[i].type << " " << cases[i].units << " column " << c;
      }
    }
  }
  EXPECT_EQ(Get(result.value(), "s11").info.units, "uT");
  EXPECT_EQ(Get(result.value(), "s13").info.units, "normalized");
  EXPECT_EQ(Get(result.value(), "s2").info.units, "rad");
}

TEST_F(CsvImportTest, TimeUnitsAreExactNanoseconds) {
  const std::string csv = Write("t.csv", "t,x\n1712345678.123456789,1\n1712345678.5,2\n");
  const char* units[] = {"s", "ms", "us", "ns"};
  for (int k = 0; k < 4; ++k) {
    const std::string mapping = std::string("time: {column: t, unit: ") + units[k] +
                                ", clock: epoch, offset_s: 0.25}\nstreams: {x: {type: steering, columns: [x]}}\n";
    const Result<Recording> result = ImportCsv({csv}, Write("map.yaml", mapping), &report_);
    ASSERT_TRUE(result.ok()) << result.status().message();
    // 1712345678.123456789 units of 10^-3k s, in ns (rounded half up at the nanosecond), plus the 0.25 s offset.
    std::int64_t whole = 1712345678, fraction = 123456789;
    std::int64_t ns = 0;
    if (k == 0) ns = whole * 1000000000 + fraction;
    if (k == 1) ns = whole * 1000000 + fraction / 1000 + (fraction % 1000 >= 500 ? 1 : 0);
    if (k == 2) ns = whole * 1000 + fraction / 1000000 + (fraction % 1000000 >= 500000 ? 1 : 0);
    if (k == 3) ns = whole + (fraction >= 500000000 ? 1 : 0);
    EXPECT_EQ(Get(result.value(), "x").t.front().nanoseconds(), ns + 250000000) << units[k];
  }
}

// --- Sensor axes, formats and the counts of what is not a sample.

TEST_F(CsvImportTest, AxesRotateEachVectorTriple) {
  const std::string csv = Write("imu.tsv", "t\twx\twy\twz\tax\tay\taz\n0\t1\t2\t3\t4\t5\t6\n0.01\t1\t2\t3\t4\t5\t6\n");
  const std::string mapping = Write("map.yaml", R"(
csv: {delimiter: "\t"}
time: {column: t}
streams:
  a: {type: imu, columns: [wx, wy, wz, ax, ay, az], axes: [x, -z, y]}
  q: {type: imu, columns: [wx, wy, wz, ax, ay, az], rotation_wxyz: [0.7071067811865476, 0, 0, 0.7071067811865476]}
  m: {type: magnetometer, columns: [wx, wy, wz], rotation_matrix: [[0, 1, 0], [-1, 0, 0], [0, 0, 1]]}
)");
  const Result<Recording> result = ImportCsv({csv}, mapping, &report_);
  ASSERT_TRUE(result.ok()) << result.status().message();
  Eigen::VectorXd a(6), q(6), m(3);
  a << 1, -3, 2, 4, -6, 5;  // x, -z, y of each triple
  q << -2, 1, 3, -5, 4, 6;  // +90 deg about z
  m << 2, -1, 3;            // the matrix rows
  EXPECT_LE((Get(result.value(), "a").values.row(1).transpose() - a).norm(), 1e-15);
  EXPECT_LE((Get(result.value(), "q").values.row(1).transpose() - q).norm(), 1e-14);
  EXPECT_LE((Get(result.value(), "m").values.row(1).transpose() - m).norm(), 1e-15);
}

TEST_F(CsvImportTest, EmptyCellsDuplicateTimesAndSkippedRowsAreCounted) {
  const std::string csv = Write("c.csv",
                                "# preamble line\n"
                                "t x y\n"
                                "0.0 1 5\n"
                                "\n"
                                "0.1 \"\" 6\n"  // empty x: no x sample
                                "0.1 3 7\n"     // duplicate time
                                "0.2 abc 8\n"   // non-numeric: row skipped
                                "0.3 4 8\n"
                                "0.4 4 8\n");  // y repeats: collapsed
  const std::string mapping = Write("map.yaml", R"(
csv: {delimiter: whitespace, skip_rows: 1, non_numeric: skip_row}
time: {column: t}
streams:
  x: {type: steering, columns: [x]}
  y: {type: steering, columns: [y], collapse: by_change}
)");
  const Result<Recording> result = ImportCsv({csv}, mapping, &report_);
  ASSERT_TRUE(result.ok()) << result.status().message();
  const CsvFileReport& f = report_.files[0];
  EXPECT_EQ(f.rows, 6);
  EXPECT_EQ(f.ignored_lines, 2);
  EXPECT_EQ(f.skipped_duplicate_time, 1);
  EXPECT_EQ(f.skipped_non_numeric, 1);
  EXPECT_EQ(report_.streams[0].samples, 3);
  EXPECT_EQ(report_.streams[0].empty_cells, 1);
  EXPECT_EQ(report_.streams[1].samples, 3);    // 5, 6, 8
  EXPECT_EQ(report_.streams[1].collapsed, 1);  // the 8 at 0.4 s
  for (const CsvStreamReport& r : report_.streams) {
    EXPECT_EQ(r.samples + r.empty_cells + r.collapsed, f.rows - f.skipped_duplicate_time - f.skipped_non_numeric);
  }
}

// --- Bad input: one line naming the file and the row, key or column.

TEST_F(CsvImportTest, BadFilesGiveOneLineNamingFileAndRow) {
  const std::string mapping = "time: {column: t}\nstreams: {x: {type: steering, columns: [x]}}\n";
  const std::string missing = (dir_ / "missing.csv").string();
  EXPECT_EQ(ImportError(missing, mapping), missing + ": cannot open file");
  const std::string empty = Write("empty.csv", "");
  EXPECT_EQ(ImportError(empty, mapping), empty + ": empty file");
  const std::string header_only = Write("header.csv", "t,x\n");
  EXPECT_EQ(ImportError(header_only, mapping), header_only + ": no data rows");
  const std::string binary = Write("binary.csv", std::string("t,x\n0,1\n\x01\x00\x7f", 11));
  EXPECT_EQ(ImportError(binary, mapping), binary + ": binary file (NUL byte at offset 9), expected CSV text");
  const std::string truncated = Write("truncated.csv", "t,x\n0,1\n0.1,2\n0.2");
  EXPECT_EQ(ImportError(truncated, mapping), truncated + ":4: truncated last line: 1 cells, expected 2");
  // All its cells but no line end: "2.5" may be "2.57" cut short.
  const std::string cut = Write("cut.csv", "t,x\n0,1\n0.1,2\n0.2,2.5");
  EXPECT_EQ(ImportError(cut, mapping), cut + ":4: truncated last line: no line end (a number may be cut short)");
  const std::string short_row = Write("short.csv", "t,x\n0,1\n0.1\n0.2,3\n");
  EXPECT_EQ(ImportError(short_row, mapping), short_row + ":3: 1 cells, expected 2");
  const std::string backwards = Write("backwards.csv", "t,x\n0,1\n0.2,2\n0.1,3\n");
  EXPECT_EQ(ImportError(backwards, mapping), backwards + ":4: time '0.1' goes backwards (previous row '0.2')");
  const std::string text = Write("text.csv", "t,x\n0,1\n0.1,one\n");
  EXPECT_EQ(ImportError(text, mapping), text + ":3: column 'x' (stream 'x'): 'one' is not a number");
  const std::string bad_time = Write("bad_time.csv", "t,x\n0,1\nnan,2\n");
  EXPECT_EQ(ImportError(bad_time, mapping), bad_time + ":3: column 't': 'nan' is not a number");
  const std::string other = Write("other.csv", "time,x\n0,1\n");
  EXPECT_EQ(ImportError(other, mapping), other + ": column 't' (time) is not in the header (time, x)");
  const std::string no_header =
      "csv: {header: false}\ntime: {column: 0}\nstreams: {x: {type: steering, columns: [2]}}\n";
  EXPECT_EQ(ImportError(other, no_header), other + ": column 2 (stream 'x') is beyond the 2 columns of the file");
  const std::string all_empty = Write("all_empty.csv", "t,x\n0,\n");
  EXPECT_EQ(ImportError(all_empty, mapping),
            all_empty + ": stream 'x' has no samples (1 rows with empty cells, 0 collapsed)");
}

TEST_F(CsvImportTest, BadMappingsNameTheKey) {
  const std::string csv = Write("ok.csv", "t,x\n0,1\n1,2\n");
  const std::string map = (dir_ / "map.yaml").string();
  EXPECT_EQ(ImportError(csv, "time: {column: t}\nstreams: {x: {type: steering, colums: [x]}}\n"),
            map + ":2: unknown key 'colums' in stream 'x'");
  EXPECT_EQ(ImportError(csv, "time: {column: t}\nstream: {}\n"), map + ":2: unknown key 'stream' in the mapping file");
  EXPECT_EQ(ImportError(csv, "time: {column: t}\nstreams: {x: {type: steering, columns: [x], units: furlong}}\n"),
            map +
                ":2: unknown unit 'furlong' in stream 'x' (known: 1, normalized, rad, deg, ticks, rad/s, deg/s, rpm, "
                "m/s^2, g, m/s, km/h, mph, knots, ft/s, uT, nT, mT, T, gauss, mG, m, mm, cm, km, ft, in, s, ms, us, "
                "ns)");
  EXPECT_EQ(ImportError(csv, "time: {column: t}\nstreams: {x: {type: steering, columns: [x], units: km/h}}\n"),
            map + ":2: unit 'km/h' (a speed) fits no column of stream 'x'");
  EXPECT_EQ(ImportError(csv, "time: {column: t, unit: min}\nstreams: {x: {type: steering, columns: [x]}}\n"),
            map + ":1: unknown unit 'min' for time (s, ms, us, ns)");
  EXPECT_EQ(ImportError(csv, "time: {column: t}\nstreams: {x: {type: imu, columns: [x], units: g}}\n"),
            map + ":2: columns of stream 'x' must list 6 source columns, one for each of [wx, wy, wz, ax, ay, az]");
  EXPECT_EQ(ImportError(csv, "streams: {x: {type: steering, columns: [x]}}\n"),
            map + ":1: missing required key 'time' (at the top or in files[0])");
  EXPECT_EQ(ImportError(csv, "time: {column: t}\nstreams: {x: {type: steering, columns: [x], axes: [x, y, z]}}\n"),
            map + ":2: stream 'x': its type has no sensor-axis vectors to rotate");
  EXPECT_EQ(
      ImportError(csv, "time: {column: t}\nstreams: {x: {type: gyroscope, columns: [x, x, x], axes: [x, x, z]}}\n"),
      map + ":2: axes of stream 'x' must name x, y, z once each, with optional signs");
  EXPECT_EQ(ImportError(csv, "time: {column: t}\nstreams: {x: {type: camera, columns: [x]}}\n"),
            map + ":2: type 'camera' of stream 'x' cannot be imported from CSV");
  EXPECT_EQ(ImportError(csv, "time: {column: t}\nstreams: {x: {type: steering, columns: [x], file: 1}}\n"),
            map + ":2: stream 'x' reads file 1 but 1 input file(s) were given");
}

// Found by csv_fuzz: yaml-cpp names the character it cannot read, here a line break, in its message.
TEST_F(CsvImportTest, UnreadableMappingIsOneLineNamingTheMapping) {
  const std::string csv = Write("a.csv", "t,x\n0,1\n");
  const std::string error = ImportError(csv, std::string("\xff\0\n", 3));
  EXPECT_EQ(error.rfind((dir_ / "map.yaml").string() + ":", 0), 0u) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
}

}  // namespace
}  // namespace roamlab::importers
