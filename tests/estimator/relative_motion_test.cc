// The relative_motion attachment (problem.h): a velocity sample that stands for the mean velocity over [t - T/2,
// t + T/2] joins the master poses nearest the interval's ends through the odometer's eqs. 5-8.
#include <cmath>
#include <random>
#include <string>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "estimator/config.h"
#include "estimator/geometry.h"
#include "estimator/problem.h"
#include "estimator/solver.h"
#include "estimator/tracking.h"
#include "recording/recording.h"
#include "tests/estimator/factor_testing.h"

namespace roamlab::estimator {
namespace {

// A planar arc: forward speed kSpeed, yaw rate kYawRate, from the identity at t = 0.
constexpr double kSpeed = 0.5;
constexpr double kYawRate = 0.8;
constexpr double kDuration = 2.0;
const Eigen::Vector3d kLever(0.15, -0.05, 0.25);
const Eigen::Quaterniond kMisalignment(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()));

Pose<double> TruePose(double t) {
  Pose<double> pose;
  pose.p_world_body = Eigen::Vector3d(std::sin(kYawRate * t), 1.0 - std::cos(kYawRate * t), 0.0) * kSpeed / kYawRate;
  pose.q_world_body = Eigen::Quaterniond(Eigen::AngleAxisd(kYawRate * t, Eigen::Vector3d::UnitZ()));
  return pose;
}

// The velocities of O that eq. 7 turns into the true motion over [t0, t1] (the chord, as the scan matcher and the
// visual odometry report it).
void ChordVelocity(double t0, double t1, Eigen::Vector3d* v_body, Eigen::Vector3d* omega_body) {
  const Pose<double> a = TruePose(t0), b = TruePose(t1);
  const double dt = t1 - t0;
  *omega_body = QuaternionLog<double>(a.q_world_body.conjugate() * b.q_world_body) / dt;
  const Eigen::Vector3d omega_dt = -0.5 * dt * *omega_body;
  *v_body = QuaternionExp<double>(omega_dt) * (a.q_world_body.conjugate() * (b.p_world_body - a.p_world_body)) / dt;
}

// Eq. 5 inverted: what the sensor at (kLever, kMisalignment) reads when O moves at (v, omega).
Eigen::Matrix<double, 1, 6> SensorRow(const Eigen::Vector3d& v_body, const Eigen::Vector3d& omega_body) {
  const Eigen::Vector3d omega_s = kMisalignment.conjugate() * omega_body;
  const Eigen::Vector3d v_s = kMisalignment.conjugate() * (v_body + omega_body.cross(kLever));
  Eigen::Matrix<double, 1, 6> row;
  row << v_s.transpose(), omega_s.transpose();
  return row;
}

recording::Stream VelocityStream(const std::string& name, recording::StreamType type, double rate_hz) {
  recording::Stream s;
  s.info.name = name;
  s.info.type = type;
  s.info.rate_hz = rate_hz;
  s.info.columns = recording::FixedColumns(type);
  return s;
}

// Master: 100 Hz odometry of O whose speed reads `speed_scale` times the truth (slip). Sensor: `rate_hz` interval
// velocities of the mounted sensor, stamped at the middle of [k / rate, (k + 1) / rate], the ends rounded to 1 ms.
recording::Recording MakeRecording(double speed_scale, double rate_hz) {
  recording::Recording rec;
  rec.platform.kind = "test";
  recording::Stream odo = VelocityStream("odometry", recording::StreamType::kOdometry, 100.0);
  const int n = static_cast<int>(std::lround(kDuration * 100.0));
  odo.values.resize(n + 1, 6);
  for (int k = 0; k <= n; ++k) {
    Eigen::Vector3d v, w;
    ChordVelocity(0.01 * k, 0.01 * (k + 1), &v, &w);
    odo.t.push_back(Time::FromNanoseconds(10'000'000LL * k));
    odo.values.row(k) << speed_scale * v.transpose(), w.transpose();
  }
  odo.info.mounting = recording::Mounting{};
  rec.streams.push_back(odo);

  recording::Stream scan = VelocityStream("scan", recording::StreamType::kScanMatching, rate_hz);
  std::vector<Eigen::Matrix<double, 1, 6>> rows;
  for (int j = 0;; ++j) {
    const std::int64_t a_ns = std::llround(j / rate_hz * 1e3) * 1'000'000LL;
    const std::int64_t b_ns = std::llround((j + 1) / rate_hz * 1e3) * 1'000'000LL;
    if (b_ns > std::llround(kDuration * 1e9)) break;
    Eigen::Vector3d v, w;
    ChordVelocity(a_ns * 1e-9, b_ns * 1e-9, &v, &w);
    scan.t.push_back(Time::FromNanoseconds((a_ns + b_ns) / 2));
    rows.push_back(SensorRow(v, w));
  }
  scan.values.resize(static_cast<Eigen::Index>(rows.size()), 6);
  for (std::size_t i = 0; i < rows.size(); ++i) scan.values.row(static_cast<Eigen::Index>(i)) = rows[i];
  recording::Mounting mounting;
  mounting.p_body_sensor = kLever;
  mounting.q_body_sensor = kMisalignment;
  scan.info.mounting = mounting;
  rec.streams.push_back(scan);
  return rec;
}

EstimatorConfig Config(const std::string& scan_model) {
  const Eigen::Quaterniond& q = kMisalignment;
  const std::string yaml =
      "master: odometer\n"
      "solver: {method: levenberg_marquardt, max_iterations: 50}\n"
      "tracking: {window: 40, max_iterations: 5, time_budget_s: 10.0, initialization_s: 0.3}\n"
      "parameters:\n"
      "  scan.lever_arm: {value: [" +
      std::to_string(kLever.x()) + ", " + std::to_string(kLever.y()) + ", " + std::to_string(kLever.z()) +
      "]}\n"
      "  scan.misalignment: {value: [" +
      std::to_string(q.w()) + ", " + std::to_string(q.x()) + ", " + std::to_string(q.y()) + ", " +
      std::to_string(q.z()) +
      "]}\n"
      "streams:\n"
      "  odometer: {model: odometer, source: odometry, noise: {linear_mps: 0.1, angular_radps: 0.1}}\n"
      "  scan: {model: " +
      scan_model + ", source: scan, noise: {linear_mps: 0.001, angular_radps: 0.001}}\n";
  auto config = ParseEstimatorConfig(yaml, "test.yaml");
  EXPECT_TRUE(config.ok()) << config.status().message();
  EstimatorConfig c = config.value();
  // std::to_string keeps 6 decimals: renormalize the quaternion exactly.
  c.parameters["scan.misalignment"].value = testing::QuaternionVector(kMisalignment);
  return c;
}

std::unique_ptr<ProblemBuilder> Build(const EstimatorConfig& config, const recording::Recording& rec) {
  auto builder = ProblemBuilder::Create(config, rec);
  EXPECT_TRUE(builder.ok()) << builder.status().message();
  for (const MeasurementRef& m : builder.value()->Measurements()) builder.value()->Add(m);
  builder.value()->Finish();
  return std::move(builder).value();
}

// The graph's values of a factor's variables.
std::vector<Eigen::VectorXd> ValuesOf(const Graph& graph, const FactorEntry& entry) {
  std::vector<Eigen::VectorXd> values;
  for (VariableId id : entry.variables) values.push_back(graph.variable(id).value);
  return values;
}

TEST(RelativeMotionTest, JoinsThePosesAtTheIntervalEndsWithZeroErrorAtTheTruth) {
  const recording::Recording rec = MakeRecording(1.0, 10.0);
  auto builder = Build(Config("relative_motion"), rec);
  Graph& graph = builder->graph();
  // The poses at their true values.
  for (const PoseNode& node : builder->poses()) {
    const Pose<double> truth = TruePose(SecondsBetween(Time(), node.t));
    PoseToArray(truth, graph.mutable_variable(node.id).value.data());
  }
  int scan_factors = 0;
  for (const auto& [id, entry] : graph.factors()) {
    if (entry.stream != "scan") continue;
    ++scan_factors;
    const double t_a = SecondsBetween(Time(), *graph.variable(entry.variables[0]).stamp);
    const double t_b = SecondsBetween(Time(), *graph.variable(entry.variables[1]).stamp);
    const double t_mid = SecondsBetween(Time(), entry.stamp);
    EXPECT_NEAR(t_a, t_mid - 0.05, 1e-9);
    EXPECT_NEAR(t_b, t_mid + 0.05, 1e-9);
    const testing::Linearization lin = testing::Evaluate(*entry.factor, ValuesOf(graph, entry));
    EXPECT_LT(lin.error.norm(), 1e-9) << "at t = " << t_mid;
  }
  EXPECT_EQ(scan_factors, 20);
  EXPECT_EQ(builder->counts().at("scan").attached, 20);
  EXPECT_EQ(builder->ResidualDim("scan"), 6);
}

TEST(RelativeMotionTest, JacobiansOverTheIntervalMatchCentralDifferences) {
  const recording::Recording rec = MakeRecording(1.0, 10.0);
  auto builder = Build(Config("relative_motion"), rec);
  std::mt19937 rng(5);
  const Graph& graph = builder->graph();
  int checked = 0;
  for (const auto& [id, entry] : graph.factors()) {
    if (entry.stream != "scan" || ++checked > 3) continue;
    std::vector<Eigen::VectorXd> values = ValuesOf(graph, entry);
    values[0] = testing::Perturb(Manifold::Pose(), values[0], 0.1, &rng);
    values[1] = testing::Perturb(Manifold::Pose(), values[1], 0.1, &rng);
    testing::ExpectJacobiansMatchNumeric(*entry.factor, values);
  }
  EXPECT_GT(checked, 0);
}

TEST(RelativeMotionTest, FifteenHertzFramesAttachToTheNearestPoses) {
  // Frames on a 1 ms grid at 15 Hz: pairs of 66 or 67 ms, stamps at half milliseconds.
  const recording::Recording rec = MakeRecording(1.0, 15.0);
  auto builder = Build(Config("relative_motion"), rec);
  const Graph& graph = builder->graph();
  const recording::Stream& scan = *rec.Find("scan");
  int factors = 0;
  for (const auto& [id, entry] : graph.factors()) {
    if (entry.stream != "scan") continue;
    ++factors;
    const std::int64_t t_a = graph.variable(entry.variables[0]).stamp->nanoseconds();
    const std::int64_t t_b = graph.variable(entry.variables[1]).stamp->nanoseconds();
    const std::int64_t half = std::llround(0.5e9 / 15.0);
    EXPECT_LE(std::abs(t_a - (entry.stamp.nanoseconds() - half)), 5'000'000);
    EXPECT_LE(std::abs(t_b - (entry.stamp.nanoseconds() + half)), 5'000'000);
  }
  EXPECT_EQ(factors, static_cast<int>(scan.t.size()));
}

// Position error of the last pose of the batch solution.
double FinalPositionError(const std::string& scan_model) {
  const recording::Recording rec = MakeRecording(1.2, 10.0);  // the wheels read 20 % fast
  const EstimatorConfig config = Config(scan_model);
  auto builder = Build(config, rec);
  const SolverSummary summary = Solve(config.solver, &builder->graph());
  EXPECT_TRUE(summary.usable()) << summary.message;
  const PoseNode& last = builder->poses().back();
  const Pose<double> estimate = PoseFromArray(builder->graph().variable(last.id).value.data());
  return (estimate.p_world_body - TruePose(SecondsBetween(Time(), last.t)).p_world_body).norm();
}

TEST(RelativeMotionTest, SlippingOdometryIsCorrectedOverWholeIntervals) {
  // 1 m of path with a 20 % speed error: the master alone ends 0.2 m off. The odometer model pins one 10 ms interval
  // in ten (about 0.18 m left); the relative motion pins every 0.1 s displacement to 0.1 mm.
  const double odometer = FinalPositionError("odometer");
  const double relative = FinalPositionError("relative_motion");
  EXPECT_GT(odometer, 0.1);
  EXPECT_LT(relative, 0.005);
}

TEST(RelativeMotionTest, TrackingKeepsEverySampleAndFollowsTheTruth) {
  const recording::Recording rec = MakeRecording(1.2, 10.0);
  auto result = Track(Config("relative_motion"), rec, {}, TrackingOptions{});
  ASSERT_TRUE(result.ok()) << result.status().message();
  EXPECT_EQ(result.value().counts.at("scan").attached, 20);
  const StampedPose& last = result.value().trajectory.back();
  EXPECT_LT((last.p_world_body - TruePose(SecondsBetween(Time(), last.t)).p_world_body).norm(), 0.005);
}

TEST(RelativeMotionTest, ConfigurationErrors) {
  recording::Recording rec = MakeRecording(1.0, 10.0);
  EstimatorConfig config = Config("relative_motion");
  config.streams["scan"].options["row_covariance_scale"] = {2.0};
  auto builder = ProblemBuilder::Create(config, rec);
  ASSERT_FALSE(builder.ok());
  EXPECT_NE(builder.status().message().find("21 covariance columns"), std::string::npos);
  config.streams["scan"].options = {{"interval_s", {-1.0}}};
  builder = ProblemBuilder::Create(config, rec);
  ASSERT_FALSE(builder.ok());
  EXPECT_NE(builder.status().message().find("interval_s"), std::string::npos);
}

}  // namespace
}  // namespace roamlab::estimator
