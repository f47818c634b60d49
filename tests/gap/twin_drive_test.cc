// The twin's drive (gap/resimulate.h ChooseTwin, gap/twin.h CompareDrive) on short seeded recordings of each kind of
// robot: a recording of the scenario's own drive, with the sensors' noise, keeps the plain simulation; a recording of
// another drive is replayed, and the replayed twin follows its drive.
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gap/resimulate.h"
#include "gap/twin.h"
#include "tests/gap/gap_testing.h"
#include "tests/support/paths.h"

namespace roamlab::gap {
namespace {

constexpr double kDurationS = 10.0;

sim::Scenario Load(const std::string& path) {
  auto s = sim::LoadScenario(roamlab::testing::SourceDir() + "/" + path);
  EXPECT_TRUE(s.ok()) << s.status().message();
  sim::Scenario scenario = s.value();
  scenario.effects.clear();
  scenario.duration_s = kDurationS;
  return scenario;
}

// Another drive of `nominal`: every turn-rate (or handlebar) profile reversed, and for a holonomic robot its lateral
// speed too.
sim::Scenario OtherDrive(const sim::Scenario& nominal) {
  sim::Scenario other = nominal;
  for (sim::Profile* p : {&other.driver.handlebar_rad, &other.driver.angular_radps, &other.driver.lateral_mps})
    for (sim::ProfileTerm& term : p->terms) term.amplitude = -term.amplitude;
  return other;
}

// The scenario's own drive with `hidden` effects and the sensors' noise keeps the plain simulation; another drive is
// replayed, and its replay follows it.
void ExpectOwnAndOtherDriveTold(const std::string& path, const std::vector<sim::EffectOptions>& hidden = {}) {
  const sim::Scenario nominal = Load(path);
  sim::Scenario real = nominal;
  real.effects = hidden;
  const recording::Recording own = testing::SimulatedWithSeed(real, 31).recording;
  auto twin = ChooseTwin(nominal, own, TwinDrive::kDetect);
  ASSERT_TRUE(twin.ok()) << twin.status().message();
  ASSERT_TRUE(twin.value().mismatch.has_value()) << path << ": no wheel stream told the drive";
  std::printf("%s own drive: %s %.4f\n", path.c_str(), twin.value().stream.c_str(), *twin.value().mismatch);
  EXPECT_FALSE(twin.value().replayed) << path << ": " << twin.value().reason << " " << twin.value().stream << " "
                                      << *twin.value().mismatch;

  const recording::Recording other = testing::SimulatedWithSeed(OtherDrive(nominal), 31).recording;
  twin = ChooseTwin(nominal, other, TwinDrive::kDetect);
  ASSERT_TRUE(twin.ok()) << twin.status().message();
  ASSERT_TRUE(twin.value().mismatch.has_value());
  std::printf("%s other drive: %s %.4f\n", path.c_str(), twin.value().stream.c_str(), *twin.value().mismatch);
  EXPECT_TRUE(twin.value().replayed) << path << ": " << twin.value().reason;
  // The replayed twin follows the other drive as the plain simulation follows the own one.
  auto replayed = ReplayRunner(other)(nominal);
  ASSERT_TRUE(replayed.ok()) << replayed.status().message();
  const DriveComparison drive = CompareDrive(other, replayed.value());
  std::printf("%s other drive replayed: %s %.4f\n", path.c_str(), drive.stream.c_str(), drive.relative);
  EXPECT_LT(drive.relative, kMaxDriveMismatch) << path << ": " << drive.stream;
}

// With a steering offset (0.03 rad, a quarter of the steering's RMS): an offset of the reading is not another drive.
TEST(TwinDriveTest, AtvOwnDriveKeepsThePlainSimulationAndAnotherIsReplayed) {
  ExpectOwnAndOtherDriveTold("scenarios/atv_hills_sines.yaml", {{"steering_offset", {{"offset_rad", 0.03}}}});
}

TEST(TwinDriveTest, DifferentialDriveOwnDriveKeepsThePlainSimulationAndAnotherIsReplayed) {
  ExpectOwnAndOtherDriveTold("scenarios/indoor_diffdrive_gap.yaml",
                             {{"wheel_radius_asymmetry", {{"ratio_right_left", 1.05}}}});
}

TEST(TwinDriveTest, OmniOwnDriveKeepsThePlainSimulationAndAnotherIsReplayed) {
  ExpectOwnAndOtherDriveTold("scenarios/indoor_omni_slip.yaml");
}

TEST(TwinDriveTest, MecanumOwnDriveKeepsThePlainSimulationAndAnotherIsReplayed) {
  ExpectOwnAndOtherDriveTold("scenarios/indoor_mecanum_gap.yaml");
}

// The replay of a recording of the scenario's own drive with a GPS (10 Hz, 5 mm, no lever arm) is its twin as the
// plain simulation is: the GPS residual within a few times its noise, as the plain simulation's.
TEST(TwinDriveTest, TheReplayOfTheOwnDriveFollowsItsGps) {
  sim::Scenario nominal = Load("scenarios/indoor_diffdrive_gap.yaml");
  nominal.duration_s = 15.0;
  sim::GpsOptions gps;
  gps.rate_hz = 10.0;
  gps.sigma_m = 0.005;
  gps.lever_arm_m.setZero();
  nominal.sensors.gps = gps;
  const recording::Recording own = testing::SimulatedWithSeed(nominal, 33).recording;
  auto plain = PlainSimulationRunner()(nominal);
  auto replayed = ReplayRunner(own)(nominal);
  ASSERT_TRUE(plain.ok() && replayed.ok());
  const TwinComparison a = CompareTwin(own, plain.value(), 0.0, nominal.duration_s);
  const TwinComparison b = CompareTwin(own, replayed.value(), 0.0, nominal.duration_s);
  ASSERT_TRUE(a.streams.count("gps") && b.streams.count("gps"));
  std::printf("gps RMS / noise: plain %.3f, replayed %.3f\n", a.streams.at("gps").rms, b.streams.at("gps").rms);
  EXPECT_LT(a.streams.at("gps").rms, 1.5);
  EXPECT_LT(b.streams.at("gps").rms, 3.0);
}

TEST(TwinDriveTest, ForcedChoicesAreTaken) {
  const sim::Scenario nominal = Load("scenarios/indoor_diffdrive_gap.yaml");
  const recording::Recording own = testing::SimulatedWithSeed(nominal, 32).recording;
  auto replay = ChooseTwin(nominal, own, TwinDrive::kReplay);
  ASSERT_TRUE(replay.ok()) << replay.status().message();
  EXPECT_TRUE(replay.value().replayed);
  EXPECT_FALSE(replay.value().mismatch.has_value());
  const recording::Recording other = testing::SimulatedWithSeed(OtherDrive(nominal), 32).recording;
  auto plain = ChooseTwin(nominal, other, TwinDrive::kPlain);
  ASSERT_TRUE(plain.ok()) << plain.status().message();
  EXPECT_FALSE(plain.value().replayed);
  // A recording without drive inputs cannot be replayed.
  recording::Recording no_drive = other;
  no_drive.streams.erase(std::remove_if(no_drive.streams.begin(), no_drive.streams.end(),
                                        [](const recording::Stream& s) {
                                          return s.info.type == recording::StreamType::kWheelEncoders ||
                                                 s.info.type == recording::StreamType::kOdometry ||
                                                 s.info.type == recording::StreamType::kInputs;
                                        }),
                         no_drive.streams.end());
  EXPECT_FALSE(ChooseTwin(nominal, no_drive, TwinDrive::kReplay).ok());
  auto detected = ChooseTwin(nominal, no_drive, TwinDrive::kDetect);
  ASSERT_TRUE(detected.ok()) << detected.status().message();
  EXPECT_FALSE(detected.value().replayed);
  EXPECT_NE(detected.value().reason.find("no replay"), std::string::npos) << detected.value().reason;
}

}  // namespace
}  // namespace roamlab::gap
