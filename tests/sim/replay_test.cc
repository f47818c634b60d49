// The replay (sim/replay.h): the twin follows the recorded drive, not the nominal schedule; it holds the recording's
// streams at the recording's stamps; a recording without drive inputs is refused; the same replay gives the same
// bytes; and, on a real OptiOdom run when the data is present, how far the nominal twin drifts from motion capture.
#include "sim/replay.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "importers/optiodom.h"
#include "importers/rosbag.h"
#include "recording/truth.h"
#include "sim/simulator.h"
#include "sim_testing.h"
#include "tests/recording/temp_dir.h"
#include "tests/support/husky_bag.h"
#include "tests/support/real_data.h"

namespace roamlab::sim {
namespace {

using recording::Recording;
using recording::Stream;
using ::roamlab::Trajectory;
using ::testing::HasSubstr;

constexpr double kPi = 3.14159265358979323846;

ProfileTerm Sine(double amplitude, double period_s) {
  ProfileTerm term;
  term.type = ProfileTerm::Type::kSine;
  term.amplitude = amplitude;
  term.period_s = period_s;
  return term;
}

// From 0 at t = 0 to `to` at 1 s.
ProfileTerm RampTo(double to) {
  ProfileTerm term;
  term.type = ProfileTerm::Type::kRamp;
  term.end_s = 1.0;
  term.to = to;
  return term;
}

// scenarios/indoor_diffdrive_slip.yaml without laser, camera and room, with a gentle drive of sines from rest (no
// wheel slip: the encoders tell the drive) over `duration_s`.
Scenario GentleDiffDrive(double duration_s) {
  auto loaded = LoadScenario(testing::SourcePath("scenarios/indoor_diffdrive_slip.yaml"));
  EXPECT_TRUE(loaded.ok()) << loaded.status().message();
  Scenario s = loaded.value();
  s.duration_s = duration_s;
  s.sensors.laser.reset();
  s.sensors.camera.reset();
  s.world_model_file.clear();
  s.driver.linear_mps.terms = {RampTo(0.2), Sine(0.3, 6.0)};
  s.driver.angular_radps.terms = {Sine(0.8, 4.0)};
  return s;
}

// The same robot driven by another schedule.
Scenario OtherDrive(double duration_s) {
  Scenario s = GentleDiffDrive(duration_s);
  s.driver.linear_mps.terms = {Sine(0.25, 3.0)};
  s.driver.angular_radps.terms = {RampTo(-0.6), Sine(0.5, 2.5)};
  return s;
}

struct TrackError {
  double max_position_m = 0.0;
  double max_heading_rad = 0.0;
};

double Yaw(const Eigen::Quaterniond& q) {
  const Eigen::Vector3d x = q * Eigen::Vector3d::UnitX();
  return std::atan2(x.y(), x.x());
}

double AngleDifference(double a, double b) { return std::remainder(a - b, 2.0 * kPi); }

// Largest planar distance and heading difference between two trajectories at their common stamps.
TrackError Compare(const Trajectory& a, const Trajectory& b) {
  TrackError e;
  std::size_t j = 0;
  for (const auto& pa : a) {
    while (j < b.size() && b[j].t < pa.t) ++j;
    if (j == b.size()) break;
    if (b[j].t != pa.t) continue;
    e.max_position_m = std::max(e.max_position_m, (pa.p_world_body - b[j].p_world_body).head<2>().norm());
    e.max_heading_rad =
        std::max(e.max_heading_rad, std::abs(AngleDifference(Yaw(pa.q_world_body), Yaw(b[j].q_world_body))));
  }
  return e;
}

// `a` moved rigidly (in the plane) so that its first pose is `b`'s: the drive's fidelity apart from the start.
Trajectory AlignedStart(Trajectory a, const Trajectory& b) {
  const double turn = AngleDifference(Yaw(b.front().q_world_body), Yaw(a.front().q_world_body));
  const Eigen::Quaterniond q(Eigen::AngleAxisd(turn, Eigen::Vector3d::UnitZ()));
  const Eigen::Vector3d p0 = a.front().p_world_body;
  for (auto& pose : a) {
    pose.p_world_body = b.front().p_world_body + q * (pose.p_world_body - p0);
    pose.q_world_body = q * pose.q_world_body;
  }
  return a;
}

// The longest straight distance covered, as the trajectory's scale.
double Extent(const Trajectory& t) {
  double extent = 0.0;
  for (const auto& p : t) extent = std::max(extent, (p.p_world_body - t.front().p_world_body).head<2>().norm());
  return extent;
}

Simulation SimulateOk(const Scenario& s) {
  auto sim = Simulate(s);
  EXPECT_TRUE(sim.ok()) << sim.status().message();
  return std::move(sim).value();
}

Simulation ReplayOk(const Scenario& nominal, const Recording& real, const ReplayOptions& options = {}) {
  auto twin = Replay(nominal, real, options);
  EXPECT_TRUE(twin.ok()) << twin.status().message();
  return std::move(twin).value();
}

// The bound on a twin driven by the encoders. The encoders truncate each wheel's angle to whole ticks (2 pi / 2048
// rad), so a measured angle increment is off by less than one tick; the replay's rates (the mean over
// 2 kRateHalfWindowS) are then off by up to one tick per window, and the angle tracking, whose time constant
// kAngleTrackingS equals the window here, follows such a rate error with a lag of one more tick. Each twin wheel
// therefore turns within 2 ticks of the recorded wheel: its rim within 2 r tick, the heading within
// (2 + 2) r tick / B (the two wheels off in opposite senses), and the position within the heading bound times the
// distance from the start plus 2 r tick. The velocity servos' own steady-state error (load torque / gain) is what the
// angle tracking removes (sim/replay_schedule.h); without it this drive's heading drifted by 0.03 rad in 12 s.
struct Bound {
  double heading_rad = 0.0;
  double position_m = 0.0;
};
Bound EncoderBound(const Recording& r, double extent_m) {
  const double tick_rad = 2.0 * kPi / r.Find("wheel_encoders")->info.attributes.at("ticks_per_revolution");
  const double rim_m = 2.0 * r.platform.geometry.at("wheel_radius_m") * tick_rad;
  const double heading = 2.0 * rim_m / r.platform.geometry.at("baseline_m");
  return {heading, heading * extent_m + rim_m};
}

TEST(ReplayTest, OwnDriveReproducesTheTruth) {
  const Scenario s = GentleDiffDrive(12.0);
  const Simulation real = SimulateOk(s);
  const Simulation twin = ReplayOk(s, real.recording);
  ASSERT_TRUE(twin.recording.ground_truth.has_value());
  const TrackError e = Compare(*twin.recording.ground_truth, *real.recording.ground_truth);
  const double extent = Extent(*real.recording.ground_truth);
  std::printf("own drive: extent %.2f m, twin error <= %.4f m, %.4f rad; %.1fx real time\n", extent, e.max_position_m,
              e.max_heading_rad, twin.stats.realtime_factor);
  EXPECT_GT(extent, 1.0);
  const Bound bound = EncoderBound(real.recording, extent);
  EXPECT_LT(e.max_heading_rad, bound.heading_rad);
  EXPECT_LT(e.max_position_m, bound.position_m);
  ASSERT_TRUE(twin.truth.replay.has_value());
  EXPECT_THAT(twin.truth.replay->drive, HasSubstr("wheel_encoders"));
}

TEST(ReplayTest, InputsNotTheScheduleDriveTheTwin) {
  const Scenario nominal = GentleDiffDrive(12.0);
  const Simulation other = SimulateOk(OtherDrive(12.0));
  const Simulation own = SimulateOk(nominal);
  const Simulation twin = ReplayOk(nominal, other.recording);
  const TrackError follows = Compare(*twin.recording.ground_truth, *other.recording.ground_truth);
  const TrackError schedule = Compare(*own.recording.ground_truth, *other.recording.ground_truth);
  const double extent = Extent(*other.recording.ground_truth);
  std::printf("other drive: twin error <= %.4f m, %.4f rad; the nominal schedule's %.3f m, %.3f rad\n",
              follows.max_position_m, follows.max_heading_rad, schedule.max_position_m, schedule.max_heading_rad);
  const Bound bound = EncoderBound(other.recording, extent);
  EXPECT_LT(follows.max_heading_rad, bound.heading_rad);
  EXPECT_LT(follows.max_position_m, bound.position_m);
  EXPECT_GT(schedule.max_position_m, 10.0 * follows.max_position_m);
}

// The replays of `restamped` (real's recording with its encoders' stamps moved) by `patched` and by `nominal`, each
// against real's ground truth, printed after `what`; and the bound of a replay of the right stamps.
struct RestampedReplays {
  TrackError patched, nominal;
  Bound bound;
};

RestampedReplays ReplayRestamped(const Scenario& nominal, const Scenario& patched, const Simulation& real,
                                 const Recording& restamped, const char* what) {
  RestampedReplays out;
  out.patched = Compare(*ReplayOk(patched, restamped).recording.ground_truth, *real.recording.ground_truth);
  out.nominal = Compare(*ReplayOk(nominal, restamped).recording.ground_truth, *real.recording.ground_truth);
  std::printf("%s: replay with the effect <= %.4f m, %.4f rad; without %.4f m, %.4f rad\n", what,
              out.patched.max_position_m, out.patched.max_heading_rad, out.nominal.max_position_m,
              out.nominal.max_heading_rad);
  out.bound = EncoderBound(real.recording, Extent(*real.recording.ground_truth));
  return out;
}

// drive_time_offset: the encoder rows stamped 0.2 s early (offset -0.2 s). A replay patched with the offset reads at
// t the inputs stamped t - 0.2 s and reproduces the truth as a replay of the right stamps does; the nominal replay
// runs the drive 0.2 s ahead. (Early, not late: the replay starts at the first encoder row, and inputs stamped late
// would start the twin 0.2 s into the drive with a step of the wheel rates, on this slippery floor a spin.) A
// simulation of the scenario's own drive refuses the effect.
TEST(ReplayTest, ADriveTimeOffsetReadsTheInputsThatMuchLater) {
  constexpr double kOffsetS = -0.2;
  const Scenario nominal = GentleDiffDrive(12.0);
  const Simulation real = SimulateOk(nominal);
  Recording early = real.recording;
  for (Stream& s : early.streams)
    if (s.info.name == "wheel_encoders")
      for (Time& t : s.t) t = Time::FromNanoseconds(t.nanoseconds() + std::llround(kOffsetS * 1e9));
  Scenario patched = nominal;
  patched.effects = {{"drive_time_offset", {{"offset_s", kOffsetS}}}};
  const RestampedReplays r = ReplayRestamped(nominal, patched, real, early, "encoders 0.2 s early");
  // The shifted twin starts at rest 0.2 s before the recorded drive: its wheels may settle a tick further from the
  // recorded angles, twice the heading bound of the right stamps' replay.
  EXPECT_LT(r.patched.max_heading_rad, 2.0 * r.bound.heading_rad);
  EXPECT_LT(r.patched.max_position_m, r.bound.position_m);
  EXPECT_GT(r.nominal.max_position_m, 5.0 * r.patched.max_position_m);
  EXPECT_GT(r.nominal.max_heading_rad, 5.0 * r.patched.max_heading_rad);
  auto refused = Simulate(patched);
  ASSERT_FALSE(refused.ok());
  EXPECT_THAT(refused.status().message(), HasSubstr("drive_time_offset"));
}

// drive_time_offset's drift: the encoders' clock running 5000 ppm fast (each encoder row stamped t0 + 1.005 (t - t0),
// t0 the first row's; 60 ms ahead at the end of the 12 s drive). A replay patched with the drift reads at t0 + t the
// inputs stamped t0 + 1.005 t, at 1.005 times their rates, and reproduces the truth as a replay of the right stamps
// does; the nominal replay falls behind. A simulation of the scenario's own drive refuses the drift.
TEST(ReplayTest, ADriveClockDriftReadsTheInputsOnTheDriftingClock) {
  constexpr double kDrift = 5e-3;
  const Scenario nominal = GentleDiffDrive(12.0);
  const Simulation real = SimulateOk(nominal);
  Recording fast = real.recording;
  for (Stream& s : fast.streams) {
    if (s.info.name != "wheel_encoders") continue;
    const std::int64_t t0_ns = s.t.front().nanoseconds();
    for (Time& t : s.t)
      t = Time::FromNanoseconds(t0_ns + std::llround(static_cast<double>(t.nanoseconds() - t0_ns) * (1.0 + kDrift)));
  }
  Scenario patched = nominal;
  patched.effects = {{"drive_time_offset", {{"drift_ppm", kDrift * 1e6}}}};
  const RestampedReplays r = ReplayRestamped(nominal, patched, real, fast, "encoders' clock 5000 ppm fast");
  EXPECT_LT(r.patched.max_heading_rad, r.bound.heading_rad);
  EXPECT_LT(r.patched.max_position_m, r.bound.position_m);
  EXPECT_GT(r.nominal.max_position_m, 5.0 * r.patched.max_position_m);
  auto refused = Simulate(patched);
  ASSERT_FALSE(refused.ok());
  EXPECT_THAT(refused.status().message(), HasSubstr("drive_time_offset's drift"));
}

// odometry_scale_error: the encoders read 3 % more than the wheels turn (the motion is the same). A replay of the
// patched scenario takes the encoders' drive over the scale and drives the true motion, its encoders reading what was
// recorded; the nominal one drives 3 % too far.
TEST(ReplayTest, AnOdometryScaleErrorIsUndoneByTheReplay) {
  constexpr double kScale = 1.03;
  const Scenario nominal = GentleDiffDrive(12.0);
  Scenario patched = nominal;
  patched.effects = {{"odometry_scale_error", {{"scale", kScale}}}};
  const Simulation plain = SimulateOk(nominal);
  const Simulation real = SimulateOk(patched);
  const Stream& a = *plain.recording.Find("wheel_encoders");
  const Stream& b = *real.recording.Find("wheel_encoders");
  const double tick_rad = 2.0 * kPi / a.info.attributes.at("ticks_per_revolution");
  for (Eigen::Index c = 0; c < 2; ++c)
    EXPECT_NEAR(b.values.col(c).tail(1)[0], kScale * a.values.col(c).tail(1)[0], 2.0 * kScale * tick_rad);
  const double extent = Extent(*real.recording.ground_truth);
  const TrackError same = Compare(*plain.recording.ground_truth, *real.recording.ground_truth);
  EXPECT_LT(same.max_position_m, 1e-9);  // the motion itself is unchanged

  const Simulation twin = ReplayOk(patched, real.recording);
  const TrackError follows = Compare(*twin.recording.ground_truth, *real.recording.ground_truth);
  const Simulation unpatched = ReplayOk(nominal, real.recording);
  const TrackError off = Compare(*unpatched.recording.ground_truth, *real.recording.ground_truth);
  std::printf(
      "odometry scale %.2f: patched twin error <= %.4f m, %.4f rad; unpatched %.3f m, %.3f rad (extent %.2f m)\n",
      kScale, follows.max_position_m, follows.max_heading_rad, off.max_position_m, off.max_heading_rad, extent);
  const Bound bound = EncoderBound(real.recording, extent);
  EXPECT_LT(follows.max_heading_rad, bound.heading_rad);
  EXPECT_LT(follows.max_position_m, bound.position_m);
  EXPECT_GT(off.max_position_m, 0.5 * (kScale - 1.0) * extent);
  const Stream& recorded = *twin.recording.Find("wheel_encoders");
  for (Eigen::Index c = 0; c < 2; ++c)
    EXPECT_NEAR(recorded.values.col(c).tail(1)[0], b.values.col(c).tail(1)[0], 4.0 * kScale * tick_rad);

  // Validation: the scale's range, and a robot without an odometry to scale.
  patched.effects = {{"odometry_scale_error", {{"scale", 2.0}}}};
  auto problem = patched.Validate();
  ASSERT_TRUE(problem.has_value());
  EXPECT_EQ(problem->key + ": " + problem->message, "effects[0].parameters.scale: must be in [0.5, 1.5]");
  patched.effects = {{"odometry_scale_error", {}}};
  patched.sensors.wheel_encoders.reset();
  problem = patched.Validate();
  ASSERT_TRUE(problem.has_value());
  EXPECT_EQ(problem->message, "odometry_scale_error needs sensors.wheel_encoders or sensors.odometer");
}

TEST(ReplayTest, TwinHoldsTheRecordedStreamsAtTheirStamps) {
  const Scenario s = GentleDiffDrive(5.0);
  Simulation real = SimulateOk(s);
  // Jittered stamps, as a real logger writes them: every other encoder and IMU stamp 3.3 ms late.
  for (Stream& stream : real.recording.streams)
    for (std::size_t k = 1; k + 1 < stream.t.size(); k += 2)
      stream.t[k] = Time::FromNanoseconds(stream.t[k].nanoseconds() + 3'300'000);
  const Simulation twin = ReplayOk(s, real.recording, {1.0, 4.0, std::nullopt, nullptr});
  ASSERT_EQ(twin.recording.streams.size(), real.recording.streams.size());
  for (const Stream& r : real.recording.streams) {
    const Stream* t = twin.recording.Find(r.info.name);
    ASSERT_NE(t, nullptr) << r.info.name;
    EXPECT_EQ(t->info.type, r.info.type);
    EXPECT_EQ(t->info.columns, r.info.columns);
    std::vector<Time> window;
    for (Time stamp : r.t)
      if (stamp >= Time::FromSeconds(1.0) && stamp <= Time::FromSeconds(4.0)) window.push_back(stamp);
    EXPECT_EQ(t->t, window) << r.info.name;
  }
  EXPECT_EQ(twin.recording.ground_truth->front().t, Time::FromSeconds(1.0));
  // The encoders start at the recorded angle and stay within a few ticks of it.
  const Stream* recorded = real.recording.Find("wheel_encoders");
  const Stream* replayed = twin.recording.Find("wheel_encoders");
  const auto first = static_cast<Eigen::Index>(
      std::lower_bound(recorded->t.begin(), recorded->t.end(), Time::FromSeconds(1.0)) - recorded->t.begin());
  EXPECT_EQ(replayed->values.row(0), recorded->values.row(first));
}

TEST(ReplayTest, RecordingWithoutDriveInputsIsRefused) {
  const Scenario s = GentleDiffDrive(2.0);
  Simulation real = SimulateOk(s);
  std::vector<Stream> imu_only;
  for (Stream& stream : real.recording.streams)
    if (stream.info.name == "imu") imu_only.push_back(stream);
  real.recording.streams = imu_only;
  const auto twin = Replay(s, real.recording);
  ASSERT_FALSE(twin.ok());
  EXPECT_THAT(twin.status().message(), HasSubstr("no drive input"));
  EXPECT_THAT(twin.status().message(), HasSubstr("wheel_encoders"));
  EXPECT_EQ(twin.status().message().find('\n'), std::string::npos);
}

TEST(ReplayTest, RecordedCommandsDriveTheTwin) {
  const Scenario s = GentleDiffDrive(8.0);
  const Simulation real = SimulateOk(s);
  // The schedule's commands at 50 Hz, in an inputs stream, and no encoders.
  Recording commands = real.recording;
  commands.streams.erase(std::remove_if(commands.streams.begin(), commands.streams.end(),
                                        [](const Stream& st) { return st.info.name == "wheel_encoders"; }),
                         commands.streams.end());
  Stream inputs;
  inputs.info.name = "inputs";
  inputs.info.type = recording::StreamType::kInputs;
  inputs.info.columns = {"linear_mps", "angular_radps"};
  inputs.values.resize(401, 2);
  for (int k = 0; k <= 400; ++k) {
    const double t = 0.02 * k;
    inputs.t.push_back(Time::FromNanoseconds(20'000'000LL * k));
    inputs.values.row(k) << s.driver.linear_mps.Evaluate(t), s.driver.angular_radps.Evaluate(t);
  }
  commands.streams.push_back(inputs);
  const Simulation twin = ReplayOk(s, commands);
  const TrackError e = Compare(*twin.recording.ground_truth, *real.recording.ground_truth);
  std::printf("commands at 50 Hz: twin error <= %.4f m, %.4f rad\n", e.max_position_m, e.max_heading_rad);
  EXPECT_THAT(twin.truth.replay->drive, HasSubstr("inputs"));
  // Commands held for 20 ms act 10 ms late on average: the heading lags by at most 0.01 s times the range of the yaw
  // rate (+-0.8 rad/s), the position by 0.01 s times the range of the speed (0.2 +- 0.3 m/s) plus the heading's lag
  // times the distance from the start.
  const double heading_bound = 0.01 * 1.6;
  EXPECT_LT(e.max_heading_rad, heading_bound);
  EXPECT_LT(e.max_position_m, 0.01 * 0.6 + heading_bound * Extent(*real.recording.ground_truth));
}

TEST(ReplayTest, WheelOdometryDrivesTheTwinAndIsSynthesized) {
  const Scenario s = GentleDiffDrive(8.0);
  const Simulation real = SimulateOk(s);
  // The wheel odometry a robot's controller would publish at 20 Hz: the nominal kinematics on the encoder rates.
  const Stream* encoders = real.recording.Find("wheel_encoders");
  const double r = real.recording.platform.geometry.at("wheel_radius_m");
  const double B = real.recording.platform.geometry.at("baseline_m");
  Stream odometry;
  odometry.info.name = "wheel_odometry";
  odometry.info.type = recording::StreamType::kOdometry;
  odometry.info.columns = recording::FixedColumns(recording::StreamType::kOdometry);
  odometry.values.setZero(static_cast<Eigen::Index>(encoders->t.size() / 5), 6);
  for (Eigen::Index k = 0; k < odometry.values.rows(); ++k) {
    const Eigen::Index row = 5 * k + 2;  // the mean rate over the 50 ms around the stamp
    const Eigen::RowVectorXd rate = (encoders->values.row(row + 2) - encoders->values.row(row - 2)) / 0.04;
    odometry.t.push_back(encoders->t[static_cast<std::size_t>(row)]);
    odometry.values(k, 0) = r * (rate[0] + rate[1]) / 2.0;
    odometry.values(k, 5) = r * (rate[1] - rate[0]) / B;
  }
  Recording recorded = real.recording;
  recorded.streams = {*real.recording.Find("imu"), odometry};
  const Simulation twin = ReplayOk(s, recorded);
  EXPECT_THAT(twin.truth.replay->drive, HasSubstr("odometry"));
  const Stream* replayed = twin.recording.Find("wheel_odometry");
  ASSERT_NE(replayed, nullptr);
  ASSERT_EQ(replayed->t, odometry.t);  // the window: the drive inputs' span, the odometry's own
  const double rms_v = (replayed->values.col(0) - odometry.values.col(0)).norm() /
                       std::sqrt(static_cast<double>(replayed->values.rows()));
  const TrackError e = Compare(*twin.recording.ground_truth, *real.recording.ground_truth);
  std::printf(
      "wheel odometry at 20 Hz: twin error <= %.4f m, %.4f rad; twin odometry against recorded: v rms %.4f "
      "m/s\n",
      e.max_position_m, e.max_heading_rad, rms_v);
  // The recorded odometry is the mean over 40 ms, the twin's the instantaneous wheel rates: over this drive's speed
  // changes (at most 0.3 m/s * 2 pi / 6 s = 0.31 m/s^2) they differ by well under 0.01 m/s, plus the servos' lag.
  EXPECT_LT(rms_v, 0.02);
  // Driven by a body velocity, the twin's wheels have no angles to track, so the velocity servos' steady-state error
  // stays (sim/replay_schedule.h): on these drives it turned an encoder-driven twin without the tracking by up to
  // 0.03 rad in 12 s. The position then drifts by at most that heading error times the extent, plus the 40 ms means'
  // lag at the speed changes (0.31 m/s^2 * 0.02 s * 8 s = 0.05 m at most, far less as the changes alternate).
  EXPECT_LT(e.max_heading_rad, 0.03);
  EXPECT_LT(e.max_position_m, 0.03 * Extent(*real.recording.ground_truth) + 0.05);
}

std::string FileBytes(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  std::ostringstream content;
  content << file.rdbuf();
  return content.str();
}

TEST(ReplayTest, SameReplayGivesTheSameBytes) {
  const Scenario s = GentleDiffDrive(3.0);
  const Simulation real = SimulateOk(s);
  ::roamlab::testing::TempDir a, b;
  for (const auto* dir : {&a, &b}) {
    const Simulation twin = ReplayOk(s, real.recording);
    ASSERT_TRUE(recording::WriteRecording(twin.recording, dir->File("twin")).ok());
    ASSERT_TRUE(recording::WriteTruth(twin.truth, dir->File("twin")).ok());
  }
  for (const char* file : {"recording.yaml", "imu.csv", "wheel_encoders.csv", "ground_truth.tum", "truth.yaml"}) {
    const std::string bytes = FileBytes(a.File(std::string("twin/") + file));
    EXPECT_FALSE(bytes.empty()) << file;
    EXPECT_EQ(bytes, FileBytes(b.File(std::string("twin/") + file))) << file;
  }
  auto truth = recording::ReadTruth(a.File("twin"));
  ASSERT_TRUE(truth.ok()) << truth.status().message();
  ASSERT_TRUE(truth.value().replay.has_value());
}

TEST(ReplayTest, MatchWheelColumnsBySideForSkidSteer) {
  auto match = MatchWheelColumns({"right", "left"}, {"front_left", "front_right", "rear_left", "rear_right"});
  ASSERT_TRUE(match.ok()) << match.status().message();
  EXPECT_EQ(match.value(), (std::vector<int>{1, 0, 1, 0}));
  auto exact = MatchWheelColumns({"right", "left"}, {"left", "right"});
  ASSERT_TRUE(exact.ok());
  EXPECT_EQ(exact.value(), (std::vector<int>{1, 0}));
  auto none = MatchWheelColumns({"w1", "w2"}, {"left", "right"});
  ASSERT_FALSE(none.ok());
  EXPECT_THAT(none.status().message(), HasSubstr("'left'"));
}

// The twin's pose stream against the recorded one over windows of `window_s`: the difference of the displacements,
// each in its own start frame. Returns {mean, max} [m].
std::pair<double, double> WindowDrift(const Stream& real, const Stream& twin, double window_s) {
  double sum = 0.0, max = 0.0;
  int windows = 0;
  const auto yaw_at = [](const Stream& s, Eigen::Index k) {
    return Yaw(Eigen::Quaterniond(s.values(k, 6), s.values(k, 3), s.values(k, 4), s.values(k, 5)));
  };
  const auto displacement = [&](const Stream& s, Eigen::Index a, Eigen::Index b) {
    const Eigen::Vector2d d = (s.values.row(b).head<2>() - s.values.row(a).head<2>()).transpose();
    return Eigen::Rotation2Dd(-yaw_at(s, a)) * d;
  };
  const auto n = static_cast<Eigen::Index>(twin.t.size());
  for (Eigen::Index a = 0, b = 0; a < n; a += 10) {
    while (b < n && SecondsBetween(twin.t[a], twin.t[b]) < window_s) ++b;
    if (b == n) break;
    // The twin's rows are the recording's rows from its first stamp on.
    const auto offset = std::lower_bound(real.t.begin(), real.t.end(), twin.t[0]) - real.t.begin();
    const double drift = (displacement(real, a + offset, b + offset) - displacement(twin, a, b)).norm();
    sum += drift;
    max = std::max(max, drift);
    ++windows;
  }
  return {windows > 0 ? sum / windows : 0.0, max};
}

// `nominal` driven from rest: straight for 6 s, then weaving.
Scenario AtvFromRest(const Scenario& nominal) {
  Scenario s = nominal;
  ProfileTerm speed = RampTo(3.0);
  speed.end_s = 4.0;
  ProfileTerm weave = Sine(0.3, 11.0);
  weave.windowed = true;
  weave.window_begin_s = 6.0;
  weave.window_end_s = 1e9;
  s.driver.speed_mps.terms = {speed};
  s.driver.handlebar_rad.terms = {weave};
  return s;
}

TEST(ReplayTest, AtvFollowsItsRecordedSpeedAndSteering) {
  // The recording: AtvFromRest; the nominal scenario: atv_hills.yaml's own schedule.
  const Scenario nominal = testing::AtvHills(20.0);
  const Scenario s = AtvFromRest(nominal);
  const Simulation real = SimulateOk(s);
  const Simulation twin = ReplayOk(nominal, real.recording);
  const Simulation own = SimulateOk(nominal);
  const Trajectory& truth = *real.recording.ground_truth;
  const TrackError start = Compare({twin.recording.ground_truth->front()}, {truth.front()});
  const TrackError e = Compare(AlignedStart(*twin.recording.ground_truth, truth), truth);
  const TrackError schedule = Compare(*own.recording.ground_truth, truth);
  std::printf(
      "ATV: extent %.1f m; start from %s off by %.2f m, %.3f rad; drive from there within %.3f m, %.4f rad "
      "(the nominal schedule's %.1f m); %.1fx real time\n",
      Extent(truth), twin.truth.replay->start.c_str(), start.max_position_m, start.max_heading_rad, e.max_position_m,
      e.max_heading_rad, schedule.max_position_m, twin.stats.realtime_factor);
  EXPECT_THAT(twin.truth.replay->drive, HasSubstr("rear-wheel speed"));
  EXPECT_THAT(twin.truth.replay->start, HasSubstr("gps"));
  EXPECT_THAT(twin.truth.replay->start, HasSubstr("aligned"));
  // The start is the twin's first kStartAlignS fitted onto the N fixes there, spread along the track over L: a line's
  // direction from N points spread evenly over L has the std sigma sqrt(12 / N) / L, its centre sigma / sqrt(N), and
  // the start, at one end, moves by the heading error times L / 2 more. 3 stds of each.
  const double sigma_m = s.sensors.gps->sigma_m;
  const recording::Stream& gps = *real.recording.Find("gps");
  const double n = static_cast<double>(
      std::upper_bound(gps.t.begin(), gps.t.end(), Time::FromSeconds(gps.t.front().seconds() + kStartAlignS)) -
      gps.t.begin());
  Trajectory first_span;
  for (const auto& pose : truth)
    if (pose.t.seconds() <= gps.t.front().seconds() + kStartAlignS) first_span.push_back(pose);
  const double length_m = Extent(first_span);
  const double heading_std = sigma_m * std::sqrt(12.0 / n) / length_m;
  std::printf("ATV start: %g fixes over %.1f m: heading std %.4f rad\n", n, length_m, heading_std);
  EXPECT_LT(start.max_heading_rad, 3.0 * heading_std);
  EXPECT_LT(start.max_position_m, 3.0 * (sigma_m / std::sqrt(n) + heading_std * length_m / 2.0));
  EXPECT_LT(e.max_position_m, 0.2 * schedule.max_position_m);
}

// Mean and RMS of a one-column stream's differences from another with the same stamps.
struct Difference {
  double mean = 0.0;
  double rms = 0.0;
};
Difference Differ(const Stream& a, const Stream& b) {
  const Eigen::ArrayXd d = a.values.col(0).array() - b.values.col(0).array();
  return {d.mean(), std::sqrt(d.square().mean())};
}

// The ATV's speed and steering readings carry a steering offset and the drive tires' slip under traction. A replay of
// the patched scenario takes both back to the drive: its front wheels turn by the offset more than the nominal
// calibration reads, its rear wheels slower by the slip than the sensor reads; so its readings are the recorded ones,
// and its path the recording's. The nominal replay drives the readings as they are.
TEST(ReplayTest, ReadingEffectsOfTheAtvDriveAreTakenBackToTheDrive) {
  constexpr double kOffsetRad = 0.03, kSlipPerMps2 = 0.1;
  const Scenario nominal = AtvFromRest(testing::AtvHills(20.0));
  Scenario patched = nominal;
  patched.effects = {{"steering_offset", {{"offset_rad", kOffsetRad}}},
                     {"longitudinal_slip", {{"slip_per_mps2", kSlipPerMps2}}}};
  const Simulation real = SimulateOk(patched);
  const Trajectory& truth = *real.recording.ground_truth;
  const Simulation twin = ReplayOk(patched, real.recording);
  const Simulation unpatched = ReplayOk(nominal, real.recording);
  const TrackError follows = Compare(AlignedStart(*twin.recording.ground_truth, truth), truth);
  const TrackError off = Compare(AlignedStart(*unpatched.recording.ground_truth, truth), truth);
  const Simulation clean = SimulateOk(nominal);
  const TrackError base =
      Compare(AlignedStart(*ReplayOk(nominal, clean.recording).recording.ground_truth, *clean.recording.ground_truth),
              *clean.recording.ground_truth);
  const Difference steer = Differ(*twin.recording.Find("steering"), *real.recording.Find("steering"));
  const Difference steer_off = Differ(*unpatched.recording.Find("steering"), *real.recording.Find("steering"));
  const Difference speed = Differ(*twin.recording.Find("rear_wheel"), *real.recording.Find("rear_wheel"));
  const Difference speed_off = Differ(*unpatched.recording.Find("rear_wheel"), *real.recording.Find("rear_wheel"));
  std::printf(
      "ATV steering offset %.2f rad, slip %.2f s^2/m over %.1f m: patched twin within %.3f m, %.4f rad (nominal "
      "%.3f m, %.4f rad; the effect-free drive's replay %.3f m, %.4f rad); steering reading mean %+.5f rms %.5f "
      "(nominal %+.5f, %.5f); speed reading mean %+.4f rms %.4f (nominal %+.4f, %.4f)\n",
      kOffsetRad, kSlipPerMps2, Extent(truth), follows.max_position_m, follows.max_heading_rad, off.max_position_m,
      off.max_heading_rad, base.max_position_m, base.max_heading_rad, steer.mean, steer.rms, steer_off.mean,
      steer_off.rms, speed.mean, speed.rms, speed_off.mean, speed_off.rms);
  // The patched twin follows the recorded path within a tenth of the nominal twin's error.
  EXPECT_LT(follows.max_position_m, 0.1 * off.max_position_m);
  EXPECT_LT(follows.max_heading_rad, 0.1 * off.max_heading_rad);
  // Its readings are the recorded ones, as closely as the nominal twin's, which drives them as they are.
  EXPECT_LT(steer.rms, 1.2 * steer_off.rms);
  EXPECT_LT(speed.rms, 1.2 * speed_off.rms);
}

// The scenario names and orders the encoder columns (optiodom_diff.yaml: right = wheel 1, then left = wheel 0): the
// twin's encoder stream keeps the recording's name and columns and each column follows its own wheel, and motion
// capture is the twin's one pose stream.
TEST(ReplayTest, ScenarioEncoderColumnsReadTheirOwnWheels) {
  auto loaded = LoadScenario(testing::SourcePath("scenarios/real/optiodom_diff.yaml"));
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  Scenario s = loaded.value();
  s.duration_s = 12.0;
  const Simulation real = SimulateOk(s);
  const Simulation twin = ReplayOk(s, real.recording);
  const Stream* recorded = real.recording.Find("wheel_encoders");
  const Stream* replayed = twin.recording.Find("wheel_encoders");
  ASSERT_NE(recorded, nullptr);
  ASSERT_NE(replayed, nullptr);
  EXPECT_EQ(replayed->info.columns, (std::vector<std::string>{"right", "left"}));
  EXPECT_EQ(replayed->t, recorded->t);
  int pose_streams = 0;
  for (const Stream& stream : twin.recording.streams) pose_streams += stream.info.type == recording::StreamType::kPose;
  EXPECT_EQ(pose_streams, 1);
  EXPECT_NE(twin.recording.Find("mocap"), nullptr);
  const auto max_difference = [&](Eigen::Index twin_column, Eigen::Index recorded_column) {
    return (replayed->values.col(twin_column) - recorded->values.col(recorded_column)).cwiseAbs().maxCoeff();
  };
  const double matched = std::max(max_difference(0, 0), max_difference(1, 1));
  const double swapped = std::min(max_difference(0, 1), max_difference(1, 0));
  std::printf("encoder columns right, left: twin within %.4f rad of its own column, %.2f rad of the other\n", matched,
              swapped);
  // The twin's wheels track the measured angles (kAngleTrackingS): a few ticks of 2 pi / 2796.8 rad and the lag.
  EXPECT_LT(matched, 0.1 * swapped);
}

// The bound on the OptiOdom differential drive twin's mean 10 s drift against motion capture [m]: measured 1.0 to
// 1.2 cm on the three runs below, where the twin of indoor_diffdrive_slip's model drifts 0.7 to 0.9 m.
constexpr double kRealDiffTwinDriftM = 0.05;

struct Drift {
  double end_m = 0.0, mean_10s_m = 0.0, max_10s_m = 0.0;
};

// The twin of `real` under `nominal` against the recorded motion capture: the end error and the 10 s drift.
Drift ReportDrift(const Recording& real, const Scenario& nominal, const std::string& label) {
  const Simulation twin = ReplayOk(nominal, real);
  const Stream* mocap = real.Find("mocap");
  const Stream* replayed = twin.recording.Find("mocap");
  EXPECT_NE(mocap, nullptr);
  EXPECT_NE(replayed, nullptr);
  if (mocap == nullptr || replayed == nullptr) return {};
  EXPECT_EQ(replayed->t.front(), *std::lower_bound(mocap->t.begin(), mocap->t.end(), replayed->t.front()));
  const Eigen::Index last = replayed->values.rows() - 1;
  const auto offset = std::lower_bound(mocap->t.begin(), mocap->t.end(), replayed->t.front()) - mocap->t.begin();
  Drift d;
  d.end_m = (replayed->values.row(last).head<2>() - mocap->values.row(last + offset).head<2>()).norm();
  std::tie(d.mean_10s_m, d.max_10s_m) = WindowDrift(*mocap, *replayed, 10.0);
  std::printf("%s (%.0f s), nominal %s: end error %.3f m; 10 s drift mean %.3f m, max %.3f m; %.1fx real time\n",
              label.c_str(), SecondsBetween(replayed->t.front(), replayed->t.back()), nominal.name.c_str(), d.end_m,
              d.mean_10s_m, d.max_10s_m, twin.stats.realtime_factor);
  return d;
}

// The OptiOdom differential drive's twin (scenarios/real/optiodom_diff.yaml: its published wheels and encoders) follows
// the motion capture of square, circular and Ivanjko-test runs far closer than a twin of another robot's nominal
// model (indoor_diffdrive_slip: wheel radius 0.075 m, track 0.4 m, against 0.042 m and 0.2 m) driven by the same
// encoder readings: its 10 s drift is the real robot's unmodelled slip and geometry error, a few centimetres.
TEST(ReplayTest, RealOptiOdomDiffTwinFollowsMotionCapture) {
  const std::vector<std::pair<std::string, std::string>> runs = {
      {"optiodom/data/diff/square/231220200029/231220200029", "square"},
      {"optiodom/data/diff/circular/231220200121/231220200121", "circular"},
      {"optiodom/data/diff/ivanjko/231220200057/231220200057", "ivanjko"}};
  auto real_model = LoadScenario(testing::SourcePath("scenarios/real/optiodom_diff.yaml"));
  auto other_robot = LoadScenario(testing::SourcePath("scenarios/indoor_diffdrive_slip.yaml"));
  ASSERT_TRUE(real_model.ok()) << real_model.status().message();
  ASSERT_TRUE(other_robot.ok()) << other_robot.status().message();
  int replayed = 0;
  for (const auto& [set_path, label] : runs) {
    const std::string set = ::roamlab::testing::RealData(set_path);
    const std::string run = set + "_run-01.csv";
    if (!std::ifstream(run)) continue;
    auto real = importers::ImportOptiOdom(run, set + "_metadata.csv");
    ASSERT_TRUE(real.ok()) << real.status().message();
    const Drift own = ReportDrift(real.value(), real_model.value(), "OptiOdom diff " + label + " run-01");
    const Drift other = ReportDrift(real.value(), other_robot.value(), "OptiOdom diff " + label + " run-01");
    EXPECT_LT(own.mean_10s_m, kRealDiffTwinDriftM) << label;
    EXPECT_LT(own.mean_10s_m, 0.1 * other.mean_10s_m) << label;
    ++replayed;
  }
  if (replayed == 0) GTEST_SKIP() << "real data absent: " << ::roamlab::testing::RealData("optiodom/data/diff");
}

// The body yaw rate of an imu stream (its gyroscope through its mounting), as means over +-0.25 s at the stamps `at`.
std::vector<double> YawRateMeans(const recording::Stream& imu, const std::vector<Time>& at) {
  const Eigen::Matrix3d R = imu.info.mounting.value_or(recording::Mounting{}).q_body_sensor.toRotationMatrix();
  std::vector<double> out;
  for (const Time& t : at) {
    double sum = 0.0;
    int n = 0;
    for (std::size_t k = 0; k < imu.t.size(); ++k) {
      if (std::abs(SecondsBetween(t, imu.t[k])) > 0.25) continue;
      sum += (R * imu.values.row(static_cast<Eigen::Index>(k)).head<3>().transpose()).z();
      ++n;
    }
    out.push_back(n > 0 ? sum / n : 0.0);
  }
  return out;
}

// The Husky bag's twin against its gyroscope, over 120 s with most of its turns: the ratio of the twin's yaw rate to
// the gyroscope's (least squares over the samples turning faster than 0.1 rad/s) and the RMS difference.
struct YawAgreement {
  double ratio = 0.0, rms_radps = 0.0;
};
YawAgreement HuskyTwinYaw(const recording::Recording& real, const Scenario& nominal, const std::string& label) {
  const recording::Stream& imu = *real.Find("imu");
  ReplayOptions options;
  options.from_s = imu.t.front().seconds() + 180.0;
  options.to_s = imu.t.front().seconds() + 300.0;
  auto twin = Replay(nominal, real, options);
  EXPECT_TRUE(twin.ok()) << twin.status().message();
  if (!twin.ok()) return {};
  std::vector<Time> at;
  for (double t = *options.from_s + 1.0; t < *options.to_s - 1.0; t += 0.1) at.push_back(Time::FromSeconds(t));
  const std::vector<double> gyro = YawRateMeans(imu, at);
  const std::vector<double> model = YawRateMeans(*twin.value().recording.Find("imu"), at);
  double gm = 0.0, gg = 0.0, squares = 0.0;
  for (std::size_t i = 0; i < at.size(); ++i) {
    squares += (model[i] - gyro[i]) * (model[i] - gyro[i]);
    if (std::abs(gyro[i]) < 0.1) continue;
    gm += gyro[i] * model[i];
    gg += gyro[i] * gyro[i];
  }
  const YawAgreement a{gm / gg, std::sqrt(squares / static_cast<double>(at.size()))};
  std::printf("husky twin, wheels %s: yaw rate %.3f x the gyroscope's, RMS difference %.4f rad/s\n", label.c_str(),
              a.ratio, a.rms_radps);
  return a;
}

// The Husky's twin turns with the gyroscope once the wheel speeds are recovered with the controller's own wheel
// separation (importers/rosbag.h: 0.5708 m x wheel_separation_multiplier 1.875): with the geometric track instead,
// the wheel-rate difference is 1.93 times too small and the twin turns at well under half the recorded rate.
TEST(ReplayTest, RealHuskyTwinTurnsWithTheGyroscope) {
  const std::string bag = ::roamlab::testing::RealData("husky_test1/test1.bag");
  if (!std::ifstream(bag)) GTEST_SKIP() << "real data absent: " << bag;
  auto nominal = LoadScenario(testing::SourcePath("scenarios/real/husky.yaml"));
  ASSERT_TRUE(nominal.ok()) << nominal.status().message();
  importers::RosbagImportOptions geometric = ::roamlab::testing::HuskyImportOptions();
  auto before = importers::ImportRosbag(bag, geometric);
  ASSERT_TRUE(before.ok()) << before.status().message();
  importers::RosbagImportOptions controller = geometric;
  controller.odometry_wheel_separation_m = 0.5708 * 1.875;
  auto after = importers::ImportRosbag(bag, controller);
  ASSERT_TRUE(after.ok()) << after.status().message();
  const YawAgreement b = HuskyTwinYaw(before.value(), nominal.value(), "from the geometric track 0.555 m");
  const YawAgreement a = HuskyTwinYaw(after.value(), nominal.value(), "from the controller's separation 1.07 m");
  EXPECT_LT(b.ratio, 0.5);
  EXPECT_GT(a.ratio, 0.75);
  EXPECT_LT(a.ratio, 1.1);
  EXPECT_LT(a.rms_radps, 0.8 * b.rms_radps);
}

}  // namespace
}  // namespace roamlab::sim
