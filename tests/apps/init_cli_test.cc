// `roamlab init` end to end: on a short simulated differential drive, `calibrate` with the written configuration gives
// the values a hand-written configuration with the same choices gives; every key of the YAML has its comment line;
// bad inputs give one line and exit code 2; `diagnose` without --scenario and --config runs on init's configuration;
// on the real OptiOdom and Husky recordings (when present) the written configuration loads and calibrates.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "recording/recording.h"
#include "tests/recording/temp_dir.h"
#include "tests/support/paths.h"
#include "tests/support/real_data.h"

namespace roamlab {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string Source(const std::string& relative) { return roamlab::testing::SourceDir() + "/" + relative; }

using testing::CommandRun;

CommandRun Roamlab(const std::string& args, const testing::TempDir& dir) {
  return testing::RunCommand(std::string(ROAMLAB_BINARY) + " " + args, dir.path());
}

std::size_t Lines(const std::string& text) {
  std::size_t n = 0;
  for (char c : text) n += c == '\n' ? 1 : 0;
  return n;
}

// scenarios/indoor_diffdrive_gap.yaml (wheel encoders 2048 ticks at 100 Hz, IMU gyro 0.01 rad/s, accel 0.05 m/s^2)
// shortened to `duration_s`, simulated into dir/rec.
std::string SimulateDiffDrive(const testing::TempDir& dir, double duration_s) {
  std::string text = testing::ReadFile(Source("scenarios/indoor_diffdrive_gap.yaml"));
  for (const auto& [a, b] : std::vector<std::pair<std::string, std::string>>{
           {"model: ../models/diffdrive.xml", "model: " + Source("models/diffdrive.xml")},
           {"duration_s: 30.0", "duration_s: " + std::to_string(duration_s)}}) {
    const std::size_t at = text.find(a);
    EXPECT_NE(at, std::string::npos) << a;
    if (at != std::string::npos) text.replace(at, a.size(), b);
  }
  testing::WriteFile(dir.File("scenario.yaml"), text);
  const CommandRun run =
      Roamlab("simulate " + dir.File("scenario.yaml") + " --out " + dir.File("rec") + " --quiet", dir);
  EXPECT_EQ(run.exit_code, 0) << run.err;
  return dir.File("rec");
}

nlohmann::json ReadJson(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  return in.good() ? nlohmann::json::parse(in) : nlohmann::json();
}

// Every line that holds a key or a list item has a comment line right above it, at the same indentation.
void ExpectEveryKeyCommented(const std::string& yaml) {
  std::istringstream in(yaml);
  std::string line, previous;
  int keys = 0;
  while (std::getline(in, line)) {
    const std::size_t indent = line.find_first_not_of(' ');
    if (indent == std::string::npos || line[indent] == '#') {
      previous = line;
      continue;
    }
    ++keys;
    EXPECT_EQ(previous.find_first_not_of(' '), indent) << "no comment line above: " << line;
    EXPECT_EQ(previous.compare(indent, 2, "# "), 0) << "no comment line above: " << line;
    previous = line;
  }
  EXPECT_GT(keys, 20);
}

TEST(InitCliTest, CalibratesAsTheHandWrittenConfigurationWithTheSameChoices) {
  testing::TempDir dir;
  const std::string rec = SimulateDiffDrive(dir, 8.0);
  CommandRun run = Roamlab("init " + rec + " --out " + dir.File("est.yaml"), dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::string yaml = testing::ReadFile(dir.File("est.yaml"));
  ExpectEveryKeyCommented(yaml);
  EXPECT_NE(yaml.find("noise from " + rec + "/recording.yaml imu.noise.gyro_sigma_radps"), std::string::npos);
  EXPECT_NE(yaml.find("from " + rec + "/recording.yaml platform.geometry.wheel_radius_m"), std::string::npos);

  // The same choices by hand: one radius free, the baseline fixed, the IMU misalignment and gyroscope bias free, the
  // stated gyroscope noise, the accelerometer at the vehicle floor of 0.5 m/s^2, the wheel noise of one tick of
  // quantization per 10 ms sample on each end, staged alike.
  const double wheel_radps = 2.0 * kPi / 2048.0 * 100.0 / std::sqrt(6.0);
  testing::WriteFile(dir.File("hand.yaml"), R"(master: odometer
solver: {method: levenberg_marquardt, max_iterations: 100, function_tolerance: 1.0e-10}
parameters:
  odometer.radius: {free: true}
  imu.misalignment: {value: [1, 0, 0, 0], free: true}
  gyro.bias: {free: true}
streams:
  odometer:
    model: differential_drive
    source: wheel_encoders
    noise: {wheel_radps: )" + std::to_string(wheel_radps) +
                                                R"(, lateral_mps: 0.02, vertical_mps: 0.02, tilt_radps: 0.1}
    parameters: {radius_left: odometer.radius, radius_right: odometer.radius}
  gyro: {model: gyroscope, source: imu, noise: {sigma_radps: 0.01}, parameters: {misalignment: imu.misalignment}}
  accel: {model: accelerometer, source: imu, noise: {sigma_mps2: 0.5}, parameters: {misalignment: imu.misalignment}}
stages:
  - [imu.misalignment]
  - [odometer.radius, gyro.bias]
  - [imu.misalignment, odometer.radius, gyro.bias]
)");
  run = Roamlab(
      "calibrate " + rec + " --config " + dir.File("est.yaml") + " --out " + dir.File("init_cal") + " --quiet", dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  run = Roamlab(
      "calibrate " + rec + " --config " + dir.File("hand.yaml") + " --out " + dir.File("hand_cal") + " --quiet", dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json init = ReadJson(dir.File("init_cal/calibration.json"))["parameters"];
  const nlohmann::json hand = ReadJson(dir.File("hand_cal/calibration.json"))["parameters"];
  ASSERT_EQ(init.size(), 3u);
  // Equal to a small fraction of each estimate's own uncertainty (its smallest printed std: a quaternion's std is per
  // tangent component; the wheel noise above is rounded to six digits by std::to_string).
  for (const auto& [mine, theirs] :
       std::vector<std::pair<std::string, std::string>>{{"wheel_encoders.radius", "odometer.radius"},
                                                        {"imu.misalignment", "imu.misalignment"},
                                                        {"gyroscope.bias", "gyro.bias"}}) {
    ASSERT_TRUE(init.contains(mine)) << mine;
    ASSERT_TRUE(hand.contains(theirs)) << theirs;
    const nlohmann::json& a = init[mine]["estimate"];
    const nlohmann::json& b = hand[theirs]["estimate"];
    double smallest_std = 1.0;
    for (const nlohmann::json& s : init[mine]["std"])
      if (s.is_number() && s.get<double>() > 0.0) smallest_std = std::min(smallest_std, s.get<double>());
    ASSERT_LT(smallest_std, 1.0) << mine << ": no finite std";
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i)
      EXPECT_NEAR(a[i].get<double>(), b[i].get<double>(), 1e-3 * smallest_std) << mine << "[" << i << "]";
  }

  // diagnose without --scenario and --config: init's configuration, no baseline, said in one line.
  run = Roamlab("diagnose --real " + rec + " --out " + dir.File("gap") + " --no-plots", dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("the nominal model is roamlab init's configuration of " + rec), std::string::npos) << run.out;
  EXPECT_EQ(testing::ReadFile(dir.File("gap/nominal_config.yaml")), yaml);
}

TEST(InitCliTest, BadInputsGiveOneLineAndExitCodeTwo) {
  testing::TempDir dir;
  CommandRun run = Roamlab("init " + dir.File("missing") + " --out " + dir.File("est.yaml"), dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_EQ(Lines(run.err), 1u) << run.err;
  EXPECT_NE(run.err.find(dir.File("missing")), std::string::npos) << run.err;

  // A recording with an IMU only: the IMU master; with a GPS only: nothing makes the poses.
  recording::Recording imu_only;
  imu_only.platform.kind = "differential_drive";
  recording::Stream imu;
  imu.info.name = "imu";
  imu.info.type = recording::StreamType::kImu;
  imu.info.rate_hz = 100.0;
  imu.info.columns = recording::FixedColumns(recording::StreamType::kImu);
  for (int k = 0; k < 3; ++k) imu.t.push_back(Time::FromSeconds(0.01 * k));
  imu.values = Eigen::MatrixXd::Zero(3, 6);
  imu_only.streams.push_back(imu);
  ASSERT_TRUE(recording::WriteRecording(imu_only, dir.File("imu_only")).ok());
  run = Roamlab("init " + dir.File("imu_only") + " --out " + dir.File("imu_est.yaml") + " --quiet", dir);
  EXPECT_EQ(run.exit_code, 0) << run.err;
  const std::string imu_yaml = testing::ReadFile(dir.File("imu_est.yaml"));
  EXPECT_NE(imu_yaml.find("master: gyroscope\n"), std::string::npos) << imu_yaml;
  EXPECT_NE(imu_yaml.find("# fixed: with the IMU the only motion sensor its attitude on the body is a gauge freedom\n"
                          "    free: false"),
            std::string::npos)
      << imu_yaml;
  recording::Recording gps_only;
  gps_only.platform.kind = "differential_drive";
  gps_only.origin = recording::GeodeticOrigin{45.0, 9.0, 100.0};
  recording::Stream gps;
  gps.info.name = "gps";
  gps.info.type = recording::StreamType::kGps;
  gps.info.rate_hz = 1.0;
  gps.info.columns = recording::FixedColumns(recording::StreamType::kGps);
  for (int k = 0; k < 3; ++k) gps.t.push_back(Time::FromSeconds(1.0 * k));
  gps.values = Eigen::MatrixXd::Constant(3, 3, 45.0);
  gps_only.streams.push_back(gps);
  const Status written = recording::WriteRecording(gps_only, dir.File("gps_only"));
  ASSERT_TRUE(written.ok()) << written.message();
  run = Roamlab("init " + dir.File("gps_only") + " --out " + dir.File("est.yaml"), dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_EQ(Lines(run.err), 1u) << run.err;
  EXPECT_NE(run.err.find("no stream can make the poses"), std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(dir.File("est.yaml")));

  run = Roamlab("init " + dir.File("imu_only") + " --out " + dir.File("est.yaml") + " --platform tank", dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_EQ(Lines(run.err), 1u) << run.err;
  EXPECT_NE(run.err.find("--platform 'tank': unknown platform kind"), std::string::npos) << run.err;
}

// --platform overrides the recording's kind: the simulated differential drive read as a skid steer takes the
// skid-steer defaults, as an omni3 it is refused for its two wheels, and a kind without a wheel model is refused
// unless --platform names one.
TEST(InitCliTest, PlatformOverridesTheRecordingsKind) {
  testing::TempDir dir;
  const std::string rec = SimulateDiffDrive(dir, 2.0);
  CommandRun run = Roamlab("init " + rec + " --out " + dir.File("skid.yaml") + " --platform skid_steer --quiet", dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::string yaml = testing::ReadFile(dir.File("skid.yaml"));
  EXPECT_NE(yaml.find("platform kind 'skid_steer' (from --platform)"), std::string::npos);
  EXPECT_NE(yaml.find("lateral_mps: 0.1\n"), std::string::npos);
  run = Roamlab("init " + rec + " --out " + dir.File("omni.yaml") + " --platform omni3", dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_EQ(Lines(run.err), 1u) << run.err;
  EXPECT_NE(run.err.find("needs 3 wheel angle columns"), std::string::npos) << run.err;

  // A kind without a wheel model: refused, naming the kind, unless --platform gives one.
  std::string text = testing::ReadFile(rec + "/recording.yaml");
  const std::size_t at = text.find("kind: differential_drive");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 24, "kind: walker");
  testing::WriteFile(rec + "/recording.yaml", text);
  run = Roamlab("init " + rec + " --out " + dir.File("walker.yaml"), dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_EQ(Lines(run.err), 1u) << run.err;
  EXPECT_NE(run.err.find("no wheel model for platform kind 'walker'"), std::string::npos) << run.err;
  run = Roamlab("init " + rec + " --out " + dir.File("walker.yaml") + " --platform differential_drive --quiet", dir);
  EXPECT_EQ(run.exit_code, 0) << run.err;
}

// The OptiOdom differential drive: init's configuration calibrates the radius as configs/real's hand-written one
// (the same free parameter; the noise differs), within their uncertainty.
TEST(InitCliTest, OptiOdomRadiusAgreesWithTheHandWrittenNominal) {
  const std::string run_csv =
      ::roamlab::testing::RealData("optiodom/data/diff/circular/231220200146/231220200146_run-01.csv");
  if (!std::filesystem::exists(run_csv)) GTEST_SKIP() << "OptiOdom data not found: " << run_csv;
  testing::TempDir dir;
  CommandRun run = Roamlab("import optiodom " + run_csv + " --out " + dir.File("rec") + " --quiet", dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  run = Roamlab("init " + dir.File("rec") + " --out " + dir.File("est.yaml") + " --quiet", dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  run = Roamlab(
      "calibrate " + dir.File("rec") + " --config " + dir.File("est.yaml") + " --out " + dir.File("a") + " --quiet",
      dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  run = Roamlab("calibrate " + dir.File("rec") + " --config " + Source("configs/real/optiodom_diff_nominal.yaml") +
                    " --out " + dir.File("b") + " --quiet",
                dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json a = ReadJson(dir.File("a/calibration.json"))["parameters"]["wheel_encoders.radius"];
  const nlohmann::json b = ReadJson(dir.File("b/calibration.json"))["parameters"]["wheels.radius"];
  const double std_ab = std::hypot(a["std"][0].get<double>(), b["std"][0].get<double>());
  EXPECT_NEAR(a["estimate"][0].get<double>(), b["estimate"][0].get<double>(), 3.0 * std_ab);
}

// The OptiOdom tricycle and four-wheel omni robots: init picks their wheel models, and its configurations calibrate
// to a radius near the maker's (the tricycle's steering offset free and negative, as its hand-written configuration
// finds it on this robot).
TEST(InitCliTest, OptiOdomTricycleAndOmni4Calibrate) {
  const std::vector<std::pair<std::string, std::string>> runs = {
      {"optiodom/data/tricyc/circular/140120211415/140120211415_run-01.csv", "tricycle_drive"},
      {"optiodom/data/omni4/circular", "omni4_drive"}};
  for (const auto& [path, model] : runs) {
    std::string run_csv = ::roamlab::testing::RealData(path);
    if (std::filesystem::is_directory(run_csv)) {
      for (const auto& entry : std::filesystem::recursive_directory_iterator(run_csv)) {
        if (entry.path().filename().string().find("_run-01.csv") != std::string::npos) {
          run_csv = entry.path().string();
          break;
        }
      }
    }
    if (!std::filesystem::is_regular_file(run_csv)) GTEST_SKIP() << "OptiOdom data not found: " << run_csv;
    testing::TempDir dir;
    CommandRun run = Roamlab("import optiodom " + run_csv + " --out " + dir.File("rec") + " --quiet", dir);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    run = Roamlab("init " + dir.File("rec") + " --out " + dir.File("est.yaml") + " --quiet", dir);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    EXPECT_NE(testing::ReadFile(dir.File("est.yaml")).find("model: " + model + "\n"), std::string::npos) << model;
    run = Roamlab(
        "calibrate " + dir.File("rec") + " --config " + dir.File("est.yaml") + " --out " + dir.File("a") + " --quiet",
        dir);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const nlohmann::json p = ReadJson(dir.File("a/calibration.json"))["parameters"];
    const double radius = p["wheel_encoders.radius"]["estimate"][0].get<double>();
    const double nominal = model == "tricycle_drive" ? 0.0325 : 0.03;
    EXPECT_GT(radius, 0.7 * nominal) << model;
    EXPECT_LT(radius, 1.1 * nominal) << model;
    if (model == "tricycle_drive") {
      const nlohmann::json offset = p["wheel_encoders.steering_offset"];
      EXPECT_LT(offset["estimate"][0].get<double>() + 3.0 * offset["std"][0].get<double>(), 0.0);
    }
  }
}

// The Husky bag with wheels re-expressed from its odometry: the odometry and its pose are left out (the same
// information twice; a dead-reckoned pose is no reference) and said so; the configuration loads and binds (init
// validates it against the recording before writing).
TEST(InitCliTest, HuskyLeavesOutTheOdometryItsWheelsCameFrom) {
  const std::string bag = ::roamlab::testing::RealData("husky_test1/test1.bag");
  if (!std::filesystem::exists(bag)) GTEST_SKIP() << "Husky bag not found: " << bag;
  testing::TempDir dir;
  CommandRun run =
      Roamlab("import rosbag " + bag +
                  " --platform skid_steer --geometry wheel_radius_m=0.1651 --geometry baseline_m=0.555 "
                  "--imu-mounting 0.7071067811865476 0.7071067811865476 0 0 --wheels-from-odometry --out " +
                  dir.File("rec") + " --quiet",
              dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  run = Roamlab("init " + dir.File("rec") + " --out " + dir.File("est.yaml"), dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find(" (odometry): the master 'wheels' was derived from it"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("_pose (pose): the pose of the odometry"), std::string::npos) << run.out;
  const std::string yaml = testing::ReadFile(dir.File("est.yaml"));
  ExpectEveryKeyCommented(yaml);
  EXPECT_NE(yaml.find("noise from " + dir.File("rec") + "/recording.yaml fix.noise.sigma_m"), std::string::npos);
  EXPECT_EQ(yaml.find("model: absolute_pose"), std::string::npos);
}

}  // namespace
}  // namespace roamlab
