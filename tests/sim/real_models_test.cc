// The nominal scenarios of the real robots (scenarios/real/): a short simulated drive of each reads like the imported
// real recording (platform kind, geometry keys, stream names, types, units and columns), its nominal wheel kinematics
// dead-reckon the simulated ground truth, and the OptiOdom omni3 twin agrees in sign with a real omni3 run.
//
// The layouts are written out below as documented (importers/optiodom.h, importers/rosbag.h); when the real data is
// present, the documented layouts are also checked against the real imports, so that the simulated recording and the
// real one are compared through them.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Dense>
#include <Eigen/Geometry>

#include "eval/velocity.h"
#include "importers/optiodom.h"
#include "importers/rosbag.h"
#include "recording/recording.h"
#include "recording/wheel_kinematics.h"
#include "sim/mujoco_model.h"
#include "sim/scenario.h"
#include "sim/simulator.h"
#include "sim/wheeled_robot.h"
#include "tests/support/husky_bag.h"
#include "tests/support/paths.h"
#include "tests/support/real_data.h"

namespace roamlab::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string Source(const std::string& relative) { return roamlab::testing::SourceDir() + "/" + relative; }

// A stream as the layout comparison sees it.
struct StreamLayout {
  std::string type;
  std::string units;
  std::vector<std::string> columns;
  std::set<std::string> attributes;
  bool operator==(const StreamLayout& o) const {
    return type == o.type && units == o.units && columns == o.columns && attributes == o.attributes;
  }
};

struct Layout {
  std::string kind;
  std::map<std::string, double> geometry;
  std::map<std::string, StreamLayout> streams;
};

std::ostream& operator<<(std::ostream& os, const StreamLayout& s) {
  os << s.type << " [" << s.units << "] (";
  for (const std::string& c : s.columns) os << c << " ";
  os << ") attributes {";
  for (const std::string& a : s.attributes) os << a << " ";
  return os << "}";
}

// The layout as recording.yaml states it: the recording written and read back (canonical units, fixed columns).
Layout LayoutOf(const recording::Recording& written) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / (std::string("roamlab_real_models_") + info->name());
  std::filesystem::remove_all(dir);
  Status status = recording::WriteRecording(written, dir.string());
  EXPECT_TRUE(status.ok()) << status.message();
  Result<recording::Recording> read = recording::ReadRecording(dir.string(), {{}, false});
  std::filesystem::remove_all(dir);
  EXPECT_TRUE(read.ok()) << read.status().message();
  if (!read.ok()) return {};
  const recording::Recording& rec = read.value();
  Layout l{rec.platform.kind, rec.platform.geometry, {}};
  for (const recording::Stream& s : rec.streams) {
    StreamLayout sl{recording::StreamTypeName(s.info.type), s.info.units, s.info.columns, {}};
    for (const auto& [key, value] : s.info.attributes) sl.attributes.insert(key);
    l.streams[s.info.name] = sl;
  }
  return l;
}

const std::vector<std::string> kPoseColumns = {"x", "y", "z", "qx", "qy", "qz", "qw"};

// The documented layouts (importers/optiodom.h; the Husky bag imported as tests/support/husky_bag.h does, the streams
// the scenario simulates).
Layout OptiOdomDiffLayout() {
  return {"differential_drive",
          {{"encoder_ticks_per_motor_revolution", 64},
           {"gear_ratio", 43.7},
           {"track_m", 0.2},
           {"wheel_radius_left_m", 0.042},
           {"wheel_radius_right_m", 0.042}},
          {{"wheel_encoders", {"wheel_encoders", "rad", {"right", "left"}, {"ticks_per_revolution"}}},
           {"mocap", {"pose", "m", kPoseColumns, {}}}}};
}

Layout OptiOdomOmni3Layout() {
  Layout l{"omni3",
           {{"encoder_ticks_per_motor_revolution", 1024}, {"gear_ratio", 12}, {"wheel_distance_m", 0.195}},
           {{"wheel_encoders", {"wheel_encoders", "rad", {"w1", "w2", "w3"}, {"ticks_per_revolution"}}},
            {"mocap", {"pose", "m", kPoseColumns, {}}}}};
  const double angle_deg[3] = {-60.0, 60.0, 180.0};
  for (int i = 0; i < 3; ++i) {
    const std::string w = "w" + std::to_string(i + 1);
    l.geometry["wheel_radius_" + w + "_m"] = 0.051;
    l.geometry["wheel_angle_" + w + "_rad"] = angle_deg[i] * kPi / 180.0;
    l.geometry["wheel_direction_" + w] = -1.0;
  }
  return l;
}

// The simulated wheel angles are counted ticks (attribute ticks_per_revolution); the imported ones are re-expressed
// from the controller's odometry (attribute derived_from_odometry instead), which the comparison with the import
// leaves out, as it does the import's further streams and columns.
Layout HuskyLayout() {
  return {"skid_steer",
          {{"wheel_radius_m", 0.1651}, {"baseline_m", 0.555}},
          {{"imu", {"imu", "rad/s,m/s^2", {"wx", "wy", "wz", "ax", "ay", "az"}, {}}},
           {"gps", {"gps", "deg", {"latitude", "longitude", "altitude"}, {}}},
           {"wheels", {"wheel_encoders", "rad", {"left", "right"}, {"ticks_per_revolution"}}}}};
}

// The simulated recording has every documented stream and geometry key, and no other; values to the micrometre.
void ExpectSameLayout(const Layout& expected, const Layout& actual, const std::string& what) {
  EXPECT_EQ(actual.kind, expected.kind) << what;
  std::set<std::string> expected_keys, actual_keys;
  for (const auto& [key, value] : expected.geometry) expected_keys.insert(key);
  for (const auto& [key, value] : actual.geometry) actual_keys.insert(key);
  EXPECT_EQ(actual_keys, expected_keys) << what << ": platform geometry keys";
  for (const auto& [key, value] : expected.geometry)
    if (actual.geometry.count(key)) {
      EXPECT_NEAR(actual.geometry.at(key), value, 1e-6) << what << ": " << key;
    }
  std::set<std::string> expected_streams, actual_streams;
  for (const auto& [name, s] : expected.streams) expected_streams.insert(name);
  for (const auto& [name, s] : actual.streams) actual_streams.insert(name);
  EXPECT_EQ(actual_streams, expected_streams) << what << ": streams";
  for (const auto& [name, s] : expected.streams)
    if (actual.streams.count(name)) {
      EXPECT_EQ(actual.streams.at(name), s) << what << ": stream " << name;
    }
}

Simulation SimulateReal(const std::string& scenario, double duration_s) {
  Result<Scenario> s = LoadScenario(Source(scenario));
  EXPECT_TRUE(s.ok()) << s.status().message();
  if (!s.ok()) return {};
  s.value().duration_s = duration_s;
  Result<Simulation> sim = Simulate(s.value());
  EXPECT_TRUE(sim.ok()) << sim.status().message();
  return sim.ok() ? std::move(sim).value() : Simulation{};
}

double Yaw(const Eigen::Quaterniond& q) {
  const Eigen::Vector3d x = q * Eigen::Vector3d::UnitX();
  return std::atan2(x.y(), x.x());
}
double Wrap(double a) { return std::atan2(std::sin(a), std::cos(a)); }

// The pose of b relative to a, planar: (x, y) in a's frame and the heading change.
Eigen::Vector3d Relative(const StampedPose& a, const StampedPose& b) {
  const double yaw = Yaw(a.q_world_body);
  const Eigen::Vector2d d = (b.p_world_body - a.p_world_body).head<2>();
  return Eigen::Vector3d(std::cos(yaw) * d.x() + std::sin(yaw) * d.y(), -std::sin(yaw) * d.x() + std::cos(yaw) * d.y(),
                         Wrap(Yaw(b.q_world_body) - yaw));
}

// The ground-truth pose at the stamp of `pose` (the simulator writes truth at every encoder stamp).
const StampedPose& TruthAt(const Trajectory& truth, Time t) {
  for (const StampedPose& p : truth)
    if (p.t == t) return p;
  ADD_FAILURE() << "no ground truth at " << t.seconds() << " s";
  return truth.front();
}

struct DeadReckoningError {
  double position_m = 0.0;   // largest over the drive
  double heading_rad = 0.0;  // largest over the drive
  double distance_m = 0.0;   // travelled by the truth
  double turned_rad = 0.0;   // total |heading change| of the truth
};

// The recording's nominal wheel kinematics (eval::EncoderOnlyOdometry: recording::NominalWheelKinematics of the
// encoder stream's columns) against the ground truth, both from the first encoder stamp.
DeadReckoningError DeadReckon(const recording::Recording& rec) {
  DeadReckoningError e;
  Result<eval::EncoderOdometry> odo = eval::EncoderOnlyOdometry(rec);
  EXPECT_TRUE(odo.ok()) << odo.status().message();
  if (!odo.ok() || !rec.ground_truth) return e;
  const Trajectory& truth = *rec.ground_truth;
  const StampedPose& start = TruthAt(truth, odo.value().dead_reckoning.front().t);
  const StampedPose* previous = &start;
  for (const StampedPose& p : odo.value().dead_reckoning) {
    const StampedPose& t = TruthAt(truth, p.t);
    const Eigen::Vector3d want = Relative(start, t);
    const Eigen::Vector3d got = Relative(odo.value().dead_reckoning.front(), p);
    e.position_m = std::max(e.position_m, (got - want).head<2>().norm());
    e.heading_rad = std::max(e.heading_rad, std::abs(Wrap(got.z() - want.z())));
    const Eigen::Vector3d step = Relative(*previous, t);
    e.distance_m += step.head<2>().norm();
    e.turned_rad += std::abs(step.z());
    previous = &t;
  }
  return e;
}

// --- (a) the layout of the simulated recordings -------------------------------------------------------------------

TEST(RealModelsTest, OptiOdomDiffReadsLikeItsImport) {
  const Simulation sim = SimulateReal("scenarios/real/optiodom_diff.yaml", 2.0);
  ExpectSameLayout(OptiOdomDiffLayout(), LayoutOf(sim.recording), "simulated optiodom_diff");
  const recording::Stream* enc = sim.recording.Find("wheel_encoders");
  ASSERT_NE(enc, nullptr);
  EXPECT_NEAR(enc->info.attributes.at("ticks_per_revolution"), 43.7 * 64, 1e-9);
  EXPECT_NEAR(enc->info.rate_hz, 20.0, 1e-12);
}

TEST(RealModelsTest, OptiOdomOmni3ReadsLikeItsImport) {
  const Simulation sim = SimulateReal("scenarios/real/optiodom_omni3.yaml", 2.0);
  ExpectSameLayout(OptiOdomOmni3Layout(), LayoutOf(sim.recording), "simulated optiodom_omni3");
  const recording::Stream* enc = sim.recording.Find("wheel_encoders");
  ASSERT_NE(enc, nullptr);
  EXPECT_NEAR(enc->info.attributes.at("ticks_per_revolution"), 12.0 * 1024, 1e-9);
  EXPECT_NEAR(enc->info.rate_hz, 25.0, 1e-12);
}

TEST(RealModelsTest, HuskyReadsLikeItsImport) {
  const Simulation sim = SimulateReal("scenarios/real/husky.yaml", 2.0);
  ExpectSameLayout(HuskyLayout(), LayoutOf(sim.recording), "simulated husky");
}

// The documented layouts are those of the real imports (the simulated recordings were compared with them above).
TEST(RealModelsTest, DocumentedLayoutsAreTheRealImports) {
  const std::string diff = testing::RealData("optiodom/data/diff/circular/231220200121/231220200121_run-01.csv");
  const std::string omni3 = testing::RealData("optiodom/data/omni3/circular/221220201643/221220201643_run-01.csv");
  const std::string bag = testing::RealData("husky_test1/test1.bag");
  if (!std::filesystem::exists(diff) || !std::filesystem::exists(omni3) || !std::filesystem::exists(bag))
    GTEST_SKIP() << "real data absent under " << testing::RealDataDir();
  auto real_diff = importers::ImportOptiOdom(diff, importers::OptiOdomMetadataPath(diff));
  ASSERT_TRUE(real_diff.ok()) << real_diff.status().message();
  ExpectSameLayout(OptiOdomDiffLayout(), LayoutOf(real_diff.value()), "imported OptiOdom diff");
  auto real_omni3 = importers::ImportOptiOdom(omni3, importers::OptiOdomMetadataPath(omni3));
  ASSERT_TRUE(real_omni3.ok()) << real_omni3.status().message();
  ExpectSameLayout(OptiOdomOmni3Layout(), LayoutOf(real_omni3.value()), "imported OptiOdom omni3");
  auto real_husky = importers::ImportRosbag(bag, testing::HuskyImportOptions());
  ASSERT_TRUE(real_husky.ok()) << real_husky.status().message();
  // The bag has more than the scenario simulates (the controller's odometry, the GPS covariances, the wheels'
  // derived_from_odometry attribute): each simulated stream is in the import with its type and units, its columns
  // the import's first ones.
  Layout real = LayoutOf(real_husky.value());
  const Layout documented = HuskyLayout();
  EXPECT_EQ(real.kind, documented.kind);
  EXPECT_EQ(real.geometry, documented.geometry);
  for (const auto& [name, s] : documented.streams) {
    ASSERT_TRUE(real.streams.count(name)) << name;
    StreamLayout r = real.streams.at(name);
    EXPECT_EQ(r.type, s.type) << name;
    EXPECT_EQ(r.units, s.units) << name;
    ASSERT_GE(r.columns.size(), s.columns.size()) << name;
    EXPECT_EQ(std::vector<std::string>(r.columns.begin(), r.columns.begin() + s.columns.size()), s.columns) << name;
  }
  // The IMU's mounting: the import states R_x(+90 deg); the scenario's true misalignment is the same rotation.
  Result<Scenario> husky = LoadScenario(Source("scenarios/real/husky.yaml"));
  ASSERT_TRUE(husky.ok()) << husky.status().message();
  const Eigen::Quaterniond q_real = real_husky.value().Find("imu")->info.mounting->q_body_sensor;
  EXPECT_GT(std::abs(q_real.dot(husky.value().sensors.imu->misalignment.normalized())), 1.0 - 1e-12);
}

// The rows the driver uses, measured on each model (sim/wheeled_robot.h), are those recording::NominalWheelKinematics
// reads off the simulated recording's geometry keys for its encoder columns: the sign conventions agree.
TEST(RealModelsTest, RecordedGeometryGivesTheModelsWheelRows) {
  for (const std::string file : {"optiodom_diff", "optiodom_omni3", "husky"}) {
    Result<Scenario> scenario = LoadScenario(Source("scenarios/real/" + file + ".yaml"));
    ASSERT_TRUE(scenario.ok()) << scenario.status().message();
    std::ifstream in(scenario.value().robot.model_file);
    std::stringstream xml;
    xml << in.rdbuf();
    auto model = LoadModelFromString(xml.str(), file);
    ASSERT_TRUE(model.ok()) << model.status().message();
    auto robot = WheeledRobot::Bind(model.value().get(), scenario.value().robot.kind, file);
    ASSERT_TRUE(robot.ok()) << robot.status().message();
    const Simulation sim = SimulateReal("scenarios/real/" + file + ".yaml", 0.5);
    const recording::Stream* enc = nullptr;
    for (const recording::Stream& st : sim.recording.streams)
      if (st.info.type == recording::StreamType::kWheelEncoders) enc = &st;
    ASSERT_NE(enc, nullptr) << file;
    auto nominal = recording::NominalWheelKinematics(sim.recording.platform, enc->info.columns);
    ASSERT_TRUE(nominal.ok()) << nominal.status().message();
    const std::vector<EncoderColumn>& columns = scenario.value().robot.encoder_columns;
    ASSERT_EQ(static_cast<int>(columns.size()), nominal.value().wheels()) << file;
    for (std::size_t k = 0; k < columns.size(); ++k) {
      const Eigen::RowVector3d measured = robot.value().J_rates_twist().row(columns[k].wheel);
      const Eigen::RowVector3d stated = nominal.value().J_rates_twist.row(static_cast<Eigen::Index>(k));
      EXPECT_LT((measured - stated).cwiseAbs().maxCoeff(), 1e-4)
          << file << " column " << columns[k].name << ": measured " << measured << ", stated " << stated;
    }
  }
}

// What only the bound model can tell is refused when the simulator is created, in one line naming the key.
TEST(RealModelsTest, NamingThatDoesNotFitTheModelIsRefused) {
  Result<Scenario> omni3 = LoadScenario(Source("scenarios/real/optiodom_omni3.yaml"));
  ASSERT_TRUE(omni3.ok()) << omni3.status().message();
  const auto refused = [](Scenario s, const std::string& key, const std::string& problem) {
    auto sim = Simulator::Create(s);
    ASSERT_FALSE(sim.ok()) << key;
    const std::string& message = sim.status().message();
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_NE(message.find(key), std::string::npos) << message;
    EXPECT_NE(message.find(problem), std::string::npos) << message;
  };
  Scenario s = omni3.value();
  s.robot.encoder_columns[2].wheel = 3;
  refused(s, "robot.encoder_columns[2].wheel", "wheels 0 to 2");
  s = omni3.value();
  s.robot.encoder_columns.pop_back();
  refused(s, "robot.geometry_keys", "every wheel");
  // The OptiOdom layout (-60, 60, 180 deg, clockwise) is not what the nominal omni3 keys describe.
  s = omni3.value();
  s.robot.per_wheel_geometry = false;
  refused(s, "robot.geometry_keys", "use per_wheel");
  s = omni3.value();
  s.robot.stated_geometry["wheel_distance_m"] = 0.2;
  refused(s, "robot.geometry.wheel_distance_m", "measured on the model");
}

// A skid steer without robot.encoder_columns records every wheel (front_left ... rear_right); the nominal kinematics
// read each column's side from its name, and the four rows are the driver's.
TEST(RealModelsTest, SkidSteerWithAnEncoderPerWheel) {
  Result<Scenario> husky = LoadScenario(Source("scenarios/real/husky.yaml"));
  ASSERT_TRUE(husky.ok()) << husky.status().message();
  husky.value().robot.encoder_columns.clear();
  husky.value().duration_s = 0.5;
  Result<Simulation> sim = Simulate(husky.value());
  ASSERT_TRUE(sim.ok()) << sim.status().message();
  const recording::Stream* wheels = sim.value().recording.Find("wheels");
  ASSERT_NE(wheels, nullptr);
  EXPECT_EQ(wheels->info.columns, (std::vector<std::string>{"front_left", "front_right", "rear_left", "rear_right"}));
  auto nominal = recording::NominalWheelKinematics(sim.value().recording.platform, wheels->info.columns);
  ASSERT_TRUE(nominal.ok()) << nominal.status().message();
  const double r = 0.1651, half_track = 0.555 / 2.0;
  Eigen::MatrixXd expected(4, 3);
  expected << 1 / r, 0, -half_track / r, 1 / r, 0, half_track / r, 1 / r, 0, -half_track / r, 1 / r, 0, half_track / r;
  EXPECT_LT((nominal.value().J_rates_twist - expected).cwiseAbs().maxCoeff(), 1e-4) << nominal.value().J_rates_twist;
  // A differential drive needs exactly its two columns.
  recording::Platform diff = sim.value().recording.platform;
  diff.kind = "differential_drive";
  EXPECT_FALSE(recording::NominalWheelKinematics(diff, wheels->info.columns).ok());
}

// --- (b) the nominal wheel kinematics dead-reckon the simulated truth ---------------------------------------------
// Bounds: the encoders count whole ticks (2 pi / 2796.8 rad: 0.09 mm of rim travel, 1 mrad of heading on the 0.2 m
// track), and the tires roll on a soft contact whose deflection shortens the rolling radius (under 1 % of the 42 mm
// radius: the contact's penetration under the robot's weight is a fraction of a millimetre). So the heading may be
// off by 1 % of the angle turned plus 2 mrad, the position by 1 % of the distance plus what the heading error does
// over it (the mean heading error times the distance) plus 1 mm.
TEST(RealModelsTest, OptiOdomDiffNominalKinematicsDeadReckonTheTruth) {
  const Simulation sim = SimulateReal("scenarios/real/optiodom_diff.yaml", 20.0);
  const DeadReckoningError e = DeadReckon(sim.recording);
  std::cout << "optiodom_diff: distance " << e.distance_m << " m, turned " << e.turned_rad << " rad; dead-reckoning "
            << "error up to " << e.position_m << " m, " << e.heading_rad << " rad\n";
  ASSERT_GT(e.distance_m, 1.5);  // the drive happened: 20 s at 0.1 m/s
  const double heading_bound = 0.01 * e.turned_rad + 0.002;
  EXPECT_LT(e.heading_rad, heading_bound);
  EXPECT_LT(e.position_m, 0.01 * e.distance_m + heading_bound * e.distance_m + 0.001);
}

// The omni wheels roll on 12 rollers each: between two rollers the axle dips by 1.2 mm (of 51 mm), so the mean rolling
// radius is up to 2.4 % short of the envelope's, and the rollers' own friction drags a little across the rolling
// direction; bounds as above with 3 % in place of 1 %, the ticks finer (2 pi / 12288 rad).
TEST(RealModelsTest, OptiOdomOmni3NominalKinematicsDeadReckonTheTruth) {
  const Simulation sim = SimulateReal("scenarios/real/optiodom_omni3.yaml", 20.0);
  const DeadReckoningError e = DeadReckon(sim.recording);
  std::cout << "optiodom_omni3: distance " << e.distance_m << " m, turned " << e.turned_rad
            << " rad; dead-reckoning error up to " << e.position_m << " m, " << e.heading_rad << " rad\n";
  ASSERT_GT(e.distance_m, 1.0);
  const double heading_bound = 0.03 * e.turned_rad + 0.002;
  EXPECT_LT(e.heading_rad, heading_bound);
  EXPECT_LT(e.position_m, 0.03 * e.distance_m + heading_bound * e.distance_m + 0.001);
}

// Least-squares ratio of the wheel odometry's heading change to the gyroscope's over 5 s windows in which the
// gyroscope turns more than 0.5 rad (as the real bag's test measures it): the gyroscope's yaw is its reading turned
// into O by the true mounting.
double YawRatioInTurns(const eval::EncoderOdometry& odo, const recording::Stream& imu, const Eigen::Quaterniond& q) {
  const auto integral = [](const std::vector<std::pair<double, double>>& rate, double a, double b) {
    double sum = 0.0;
    for (std::size_t i = 0; i + 1 < rate.size(); ++i) {
      const double t0 = std::max(a, rate[i].first), t1 = std::min(b, rate[i + 1].first);
      if (t1 > t0) sum += rate[i].second * (t1 - t0);
    }
    return sum;
  };
  std::vector<std::pair<double, double>> gyro, wheels;
  for (std::size_t k = 0; k < imu.t.size(); ++k) {
    const Eigen::Vector3d w = imu.values.row(static_cast<Eigen::Index>(k)).head<3>().transpose();
    gyro.emplace_back(imu.t[k].seconds(), (q * w).z());
  }
  for (const eval::StampedTwist& s : odo.twists) wheels.emplace_back(s.t_begin.seconds(), s.omega_body.z());
  double og = 0.0, gg = 0.0;
  for (double a = 0.0; a + 5.0 <= imu.t.back().seconds(); a += 5.0) {
    const double g = integral(gyro, a, a + 5.0), o = integral(wheels, a, a + 5.0);
    if (std::abs(g) < 0.5) continue;
    og += o * g;
    gg += g * g;
  }
  return gg > 0.0 ? og / gg : 0.0;
}

// A skid steer turns by scrubbing its tires sideways: the body turns slower than the wheel speeds say through the
// nominal track, by a skid factor k (the effective track is k times the nominal one; Coulomb friction at four equal
// contacts gives k = 1 + (L / B)^2 within 10 %). Measured here as the ratio of
// the wheel odometry's heading change to the gyroscope's; with it, the wheel odometry's heading follows the truth
// within 1 % of the angle turned (the rolling radius on the soft contact) plus 10 mrad (the ticks, and the turns'
// starts and ends, where the scrub differs from its mean), closer than without it.
TEST(RealModelsTest, HuskySkidSteerTurnsSlowerThanItsWheels) {
  Result<Scenario> scenario = LoadScenario(Source("scenarios/real/husky.yaml"));
  ASSERT_TRUE(scenario.ok()) << scenario.status().message();
  const Simulation sim = SimulateReal("scenarios/real/husky.yaml", 30.0);
  const recording::Recording& rec = sim.recording;
  Result<eval::EncoderOdometry> odo = eval::EncoderOnlyOdometry(rec);
  ASSERT_TRUE(odo.ok()) << odo.status().message();
  const double k = YawRatioInTurns(odo.value(), *rec.Find("imu"), scenario.value().sensors.imu->misalignment);
  const DeadReckoningError e = DeadReckon(rec);
  std::cout << "husky: simulated yaw-rate ratio wheel-odometry / gyro = " << k << "; effective track "
            << k * rec.platform.geometry.at("baseline_m") << " m; distance " << e.distance_m << " m, turned "
            << e.turned_rad << " rad; nominal dead-reckoning "
            << "error up to " << e.position_m << " m, " << e.heading_rad << " rad\n";
  ASSERT_GT(e.turned_rad, 2.0);
  // Four equally loaded Coulomb contacts at (+-L/2, +-B/2) turn with the effective track B + L^2 / B
  // (models/husky.xml).
  const double coulomb = 1.0 + (0.512 / 0.555) * (0.512 / 0.555);
  std::cout << "husky: four-contact Coulomb ratio B_eff / B = " << coulomb << "\n";
  EXPECT_NEAR(k, coulomb, 0.1 * coulomb);
  // The heading with the effective track: the odometry's yaw rate divided by k.
  recording::Recording effective = rec;
  effective.platform.geometry["baseline_m"] *= k;
  const DeadReckoningError f = DeadReckon(effective);
  std::cout << "husky with the effective track: error up to " << f.position_m << " m, " << f.heading_rad << " rad\n";
  EXPECT_LT(f.heading_rad, 0.01 * f.turned_rad + 0.01);
  EXPECT_LT(f.heading_rad, e.heading_rad);
}

// --- (c) the OptiOdom omni3 twin and a real run agree in sign ------------------------------------------------------

// Least-squares fit of the body-frame displacements (dx, dy, dtheta) over steps of `rows` samples of the pose stream
// on the wheel-angle increments of the encoder stream at the same stamps: displacement = increments^T M; M's row i is
// the body motion per radian of wheel i.
Eigen::Matrix3d FitMotionOnWheels(const recording::Recording& rec, int rows) {
  const recording::Stream* pose = rec.Find("mocap");
  const recording::Stream* enc = rec.Find("wheel_encoders");
  EXPECT_TRUE(pose != nullptr && enc != nullptr);
  if (pose == nullptr || enc == nullptr) return Eigen::Matrix3d::Zero();
  std::map<std::int64_t, Eigen::Index> enc_row;
  for (std::size_t k = 0; k < enc->t.size(); ++k) enc_row[enc->t[k].nanoseconds()] = static_cast<Eigen::Index>(k);
  const auto pose_at = [pose](std::size_t k) {
    const Eigen::Matrix<double, 1, 7> v = pose->values.row(static_cast<Eigen::Index>(k));
    return StampedPose{pose->t[k], v.head<3>().transpose(), Eigen::Quaterniond(v(6), v(3), v(4), v(5)).normalized()};
  };
  std::vector<Eigen::Vector3d> d, a;
  for (std::size_t k = 0; k + static_cast<std::size_t>(rows) < pose->t.size(); k += static_cast<std::size_t>(rows)) {
    const std::size_t j = k + static_cast<std::size_t>(rows);
    const auto e0 = enc_row.find(pose->t[k].nanoseconds()), e1 = enc_row.find(pose->t[j].nanoseconds());
    if (e0 == enc_row.end() || e1 == enc_row.end()) continue;
    d.push_back(Relative(pose_at(k), pose_at(j)));
    a.push_back((enc->values.row(e1->second) - enc->values.row(e0->second)).transpose());
  }
  Eigen::MatrixXd A(static_cast<Eigen::Index>(a.size()), 3), D(static_cast<Eigen::Index>(d.size()), 3);
  for (std::size_t i = 0; i < a.size(); ++i) {
    A.row(static_cast<Eigen::Index>(i)) = a[i].transpose();
    D.row(static_cast<Eigen::Index>(i)) = d[i].transpose();
  }
  return A.colPivHouseholderQr().solve(D);
}

// The signs of M's entries that matter (a quarter of their column's largest or more): the same on the simulated and
// the real robot, so that the twin's wheel angles turn into body motion the same way. 0.2 s steps (5 samples at 25 Hz).
TEST(RealModelsTest, OptiOdomOmni3TwinAgreesInSignWithARealRun) {
  const std::string run = testing::RealData("optiodom/data/omni3/circular/221220201643/221220201643_run-01.csv");
  if (!std::filesystem::exists(run)) GTEST_SKIP() << "real data absent: " << run;
  auto real = importers::ImportOptiOdom(run, importers::OptiOdomMetadataPath(run));
  ASSERT_TRUE(real.ok()) << real.status().message();
  const Simulation sim = SimulateReal("scenarios/real/optiodom_omni3.yaml", 20.0);
  const Eigen::Matrix3d m_real = FitMotionOnWheels(real.value(), 5);
  const Eigen::Matrix3d m_sim = FitMotionOnWheels(sim.recording, 5);
  std::cout << "body motion (dx, dy, dtheta) per radian of w1, w2, w3:\nreal\n"
            << m_real << "\nsimulated\n"
            << m_sim << "\n";
  int compared = 0;
  for (int j = 0; j < 3; ++j) {
    const double scale = std::max(m_real.col(j).cwiseAbs().maxCoeff(), m_sim.col(j).cwiseAbs().maxCoeff());
    for (int i = 0; i < 3; ++i) {
      if (std::abs(m_real(i, j)) < 0.25 * scale && std::abs(m_sim(i, j)) < 0.25 * scale) continue;
      ++compared;
      EXPECT_GT(m_real(i, j) * m_sim(i, j), 0.0) << "wheel w" << i + 1 << ", component " << j;
    }
  }
  // Every wheel turns the robot (clockwise for a positive angle) and moves it: the three yaw entries, two
  // translations of w1 and w2 each, and w3's sideways one (at 180 deg it pushes along y only).
  EXPECT_GE(compared, 8);
  for (int i = 0; i < 3; ++i) EXPECT_LT(m_sim(i, 2), 0.0) << "a positive w" << i + 1 << " turns the robot clockwise";
}

}  // namespace
}  // namespace roamlab::sim
