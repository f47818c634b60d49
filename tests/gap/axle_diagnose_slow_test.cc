// The reality-gap diagnosis of a misaligned rear axle on 30 s ATV drives (scenarios/atv_hills_sines.yaml, the drive
// of the other diagnose tests): a thrust angle (sim axle_misalignment on the ackermann rear axle, estimator
// odometer.thrust_angle) against a steering offset.
// Kinematics (estimator/models/ackermann_velocity.h): the thrust angle alpha turns the vehicle at -v tan(alpha) / L at
// zero handlebar, as a steering offset of -alpha does, and makes it crab by alpha. The crab is seen only against a
// heading reference tied to the chassis: with the IMU's misalignment free (the nominal model), a rotation of O by
// alpha absorbs it, and only alpha sin^2(delta) on the steering row is left to tell the two apart; with the IMU's
// mounting known (a boresighted IMU: imu.misalignment fixed at the scenario's value), the accelerometer and the
// gyroscope hold the chassis heading and GPS gives the course.
// Baselines are learned once per configuration on a nominal simulation with a seed the cases do not use, as
// `roamlab diagnose` does. The truth is the effect put in the scenario; the diagnosis sees the recording only.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "gap/diagnose.h"
#include "sim/simulator.h"
#include "tests/gap/gap_testing.h"

namespace roamlab::gap {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The nominal model with the IMU's mounting believed: imu.misalignment fixed at the scenario's value.
void KnownImuMounting(estimator::EstimatorConfig* config) {
  config->parameters.at("imu.misalignment").free = false;
  for (std::vector<std::string>& stage : config->stages)
    stage.erase(std::remove(stage.begin(), stage.end(), "imu.misalignment"), stage.end());
}

Diagnosis Diagnosed(const testing::LearnedNominal& nominal, const std::vector<sim::EffectOptions>& effects,
                    std::uint64_t seed) {
  auto d = testing::DiagnoseHidden(nominal, effects, seed);
  EXPECT_TRUE(d.ok()) << d.status().message();
  if (!d.ok()) return {};
  std::string names;
  for (const EffectEstimate& e : d.value().effects) names += e.name + " ";
  std::cout << "verdict " << d.value().verdict << ", named: " << names << "(" << d.value().seconds << " s)\n";
  for (const EffectEstimate& e : d.value().candidates) {
    std::cout << "  " << e.name << " LR " << e.lr << " chi2 drop " << e.lr_raw << " dBIC " << e.delta_bic << " "
              << e.decision;
    for (const auto& [k, v] : e.parameters)
      std::cout << " " << k << " " << v << " +- " << (e.std.count(k) ? e.std.at(k) : 0.0);
    std::cout << "\n";
  }
  return std::move(d).value();
}

// The candidate `name` of the first round.
const EffectEstimate* CandidateOf(const Diagnosis& d, const std::string& name) {
  for (const EffectEstimate& e : d.candidates)
    if (e.name == name) return &e;
  return nullptr;
}

// The first named effect is `name` and its `parameter` is within 3 reported std of `truth`.
void ExpectNamedFirst(const Diagnosis& d, const std::string& name, const std::string& parameter, double truth) {
  ASSERT_EQ(d.verdict, "named");
  ASSERT_FALSE(d.effects.empty());
  const EffectEstimate& e = d.effects.front();
  EXPECT_EQ(e.name, name);
  if (e.name != name) return;
  ASSERT_TRUE(e.parameters.count(parameter) && e.std.count(parameter)) << parameter;
  const double estimate = e.parameters.at(parameter), std = e.std.at(parameter);
  std::cout << name << "." << parameter << ": truth " << truth << " estimate " << estimate << " +- " << std
            << " (error / std " << (estimate - truth) / std << "), held-out chi2 " << 100.0 * e.heldout_improvement
            << " % lower\n";
  EXPECT_GT(std, 0.0);
  EXPECT_NEAR(estimate, truth, 3.0 * std);
  EXPECT_GT(e.heldout_improvement, 0.0);
}

class KnownMountingAxleTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    nominal_ = testing::LearnNominal("scenarios/atv_hills_sines.yaml", KnownImuMounting).release();
  }
  static void TearDownTestSuite() { delete nominal_; }
  void SetUp() override { ASSERT_NE(nominal_, nullptr); }
  static testing::LearnedNominal* nominal_;
};
testing::LearnedNominal* KnownMountingAxleTest::nominal_ = nullptr;

// A 2 deg thrust angle: named first as axle_misalignment, not as the steering offset its turn resembles.
TEST_F(KnownMountingAxleTest, NamesAxleMisalignmentFirst) {
  const Diagnosis d = Diagnosed(*nominal_, {{"axle_misalignment", {{"yaw_deg", 2.0}}}}, 18);
  ExpectNamedFirst(d, "axle_misalignment", "yaw_deg", 2.0);
}

// A steering offset (whose turn a thrust angle of -offset would also make, without the crab) stays a steering offset.
TEST_F(KnownMountingAxleTest, SteeringOffsetIsNotNamedAxleMisalignment) {
  const Diagnosis d = Diagnosed(*nominal_, {{"steering_offset", {{"offset_rad", 0.03}}}}, 13);
  ExpectNamedFirst(d, "steering_offset", "offset_rad", 0.03);
}

class NominalAxleTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { nominal_ = testing::LearnNominal("scenarios/atv_hills_sines.yaml").release(); }
  static void TearDownTestSuite() { delete nominal_; }
  void SetUp() override { ASSERT_NE(nominal_, nullptr); }
  static testing::LearnedNominal* nominal_;
};
testing::LearnedNominal* NominalAxleTest::nominal_ = nullptr;

// With the nominal model (IMU misalignment free) the thrust angle and a steering offset of -alpha explain the drive
// alike (to alpha sin^2(delta)): with the candidate in the library both fit about equally well, so the library leaves
// the candidate out there, and the thrust angle reads as a steering offset of -alpha.
TEST_F(NominalAxleTest, ThrustAngleReadsAsASteeringOffsetWhenTheImuMountingIsFree) {
  const double yaw_deg = 2.0;
  const Diagnosis d = Diagnosed(*nominal_, {{"axle_misalignment", {{"yaw_deg", yaw_deg}}}}, 18);
  EXPECT_EQ(CandidateOf(d, "axle_misalignment"), nullptr);
  ExpectNamedFirst(d, "steering_offset", "offset_rad", -yaw_deg * kPi / 180.0);
}

}  // namespace
}  // namespace roamlab::gap
