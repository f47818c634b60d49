// The diagnosis on real recordings (../shared/data, skipped when absent), where nothing labels the effects:
// OptiOdom's differential drive (unequal wheel diameters, a wider effective track) and the Husky bag (skid-steer yaw
// mismatch). The reference values are the data README's "quick least-squares look", not ours.
#include <cmath>
#include <filesystem>
#include <iostream>

#include <gtest/gtest.h>

#include "estimator/config.h"
#include "estimator/models/differential_drive.h"
#include "gap/diagnose.h"
#include "recording/import_optiodom.h"
#include "recording/import_rosbag.h"

namespace roamlab::gap {
namespace {

const std::string kData = std::string(ROAMLAB_SHARED_DIR) + "/data";
const std::string kSet = kData + "/optiodom/data/diff/circular/231220200121/231220200121";

const EffectEstimate* Find(const Diagnosis& d, const std::string& name) {
  for (const EffectEstimate& e : d.effects)
    if (e.name == name) return &e;
  return nullptr;
}

// Dead reckoning of a run's encoders from its first motion-capture pose with the given geometry: the RMS of the
// planar position error against the motion capture [m] at the encoder stamps (both streams share the stamps).
double DeadReckoningRms(const recording::Recording& rec, double radius_left, double radius_right, double track) {
  const recording::Stream* enc = rec.Find("wheel_encoders");
  const recording::Stream* mocap = rec.Find("mocap");
  const double yaw0 = 2.0 * std::atan2(mocap->values(0, 5), mocap->values(0, 6));
  double x = mocap->values(0, 0), y = mocap->values(0, 1), yaw = yaw0, sum = 0.0;
  const Eigen::Index n = std::min(enc->values.rows(), mocap->values.rows());
  for (Eigen::Index k = 0; k + 1 < n; ++k) {
    // Columns right, left (import_optiodom.h).
    const double right = enc->values(k + 1, 0) - enc->values(k, 0);
    const double left = enc->values(k + 1, 1) - enc->values(k, 1);
    const double ds = 0.5 * (radius_right * right + radius_left * left);
    const double dyaw = (radius_right * right - radius_left * left) / track;
    x += ds * std::cos(yaw + 0.5 * dyaw);
    y += ds * std::sin(yaw + 0.5 * dyaw);
    yaw += dyaw;
    sum += std::pow(x - mocap->values(k + 1, 0), 2) + std::pow(y - mocap->values(k + 1, 1), 2);
  }
  return std::sqrt(sum / static_cast<double>(n - 1));
}

TEST(RealDataTest, OptiOdomDifferentialDriveWheelRatioAndTrack) {
  if (!std::filesystem::exists(kSet + "_metadata.csv")) GTEST_SKIP() << "real data absent: " << kSet;
  auto rec = recording::ImportOptiOdom(kSet + "_run-01.csv", kSet + "_metadata.csv");
  ASSERT_TRUE(rec.ok()) << rec.status().message();
  auto config = estimator::LoadEstimatorConfig(std::string(ROAMLAB_SOURCE_DIR) +
                                               "/scenarios/real/optiodom_diff_nominal.yaml");
  ASSERT_TRUE(config.ok()) << config.status().message();
  auto d = Diagnose(config.value(), rec.value());
  ASSERT_TRUE(d.ok()) << d.status().message();
  const Diagnosis& diagnosis = d.value();
  for (const EffectEstimate& e : diagnosis.candidates) {
    std::cout << e.name;
    for (const auto& [k, v] : e.parameters) std::cout << " " << k << " = " << v << " +- " << e.std.at(k);
    std::cout << " LR " << e.lr << " dBIC " << e.delta_bic << " " << e.decision << "\n";
  }
  EXPECT_EQ(diagnosis.verdict, "named");
  const EffectEstimate* ratio = Find(diagnosis, "wheel_radius_asymmetry");
  const EffectEstimate* track = Find(diagnosis, "track_width_error");
  ASSERT_NE(ratio, nullptr);
  ASSERT_NE(track, nullptr);
  // The data README: D_R / D_L 0.983-0.989 in the Dec-2020 sets; effective track about 0.2027 m.
  EXPECT_NEAR(ratio->parameters.at("ratio_right_left"), 0.986, 0.006);
  EXPECT_NEAR(0.2 + track->parameters.at("track_error_m"), 0.2027, 0.002);

  // Other runs of the set: dead reckoning with the patched geometry beats the nominal one.
  const double r = diagnosis.effect_parameters.count("wheels.radius")
                       ? diagnosis.effect_parameters.at("wheels.radius")[0]
                       : diagnosis.nominal_parameters.at("wheels.radius")[0];
  const double rho = diagnosis.effect_parameters.at("wheels.right_left_ratio")[0];
  const double b = diagnosis.effect_parameters.at("wheels.baseline")[0];
  for (const char* run : {"02", "03", "04"}) {
    auto other = recording::ImportOptiOdom(kSet + "_run-" + run + ".csv", kSet + "_metadata.csv");
    ASSERT_TRUE(other.ok()) << other.status().message();
    const double nominal = DeadReckoningRms(other.value(), 0.042, 0.042, 0.2);
    const double patched = DeadReckoningRms(other.value(), r, rho * r, b);
    std::cout << "run " << run << ": dead-reckoning RMS nominal " << nominal << " m, patched " << patched << " m\n";
    EXPECT_LT(patched, 0.5 * nominal) << run;
  }
}

TEST(RealDataTest, HuskySkidSteerYawMismatch) {
  const std::string bag = kData + "/husky_test1/test1.bag";
  if (!std::filesystem::exists(bag)) GTEST_SKIP() << "real data absent: " << bag;
  recording::RosbagImportOptions options;
  options.platform = {"skid_steer", {{"wheel_radius_m", 0.1651}, {"baseline_m", 0.555}}};
  options.q_body_imu = Eigen::Quaterniond(std::sqrt(0.5), std::sqrt(0.5), 0.0, 0.0);
  options.wheels_from_odometry = true;
  auto rec = recording::ImportRosbag(bag, options);
  ASSERT_TRUE(rec.ok()) << rec.status().message();
  auto config =
      estimator::LoadEstimatorConfig(std::string(ROAMLAB_SOURCE_DIR) + "/scenarios/real/husky_nominal.yaml");
  ASSERT_TRUE(config.ok()) << config.status().message();
  auto d = Diagnose(config.value(), rec.value());
  ASSERT_TRUE(d.ok()) << d.status().message();
  for (const EffectEstimate& e : d.value().candidates) {
    std::cout << e.name;
    for (const auto& [k, v] : e.parameters) std::cout << " " << k << " = " << v << " +- " << e.std.at(k);
    std::cout << " LR " << e.lr << " dBIC " << e.delta_bic << " " << e.decision << "\n";
  }
  EXPECT_EQ(d.value().verdict, "named");
  ASSERT_FALSE(d.value().effects.empty());
  const EffectEstimate& first = d.value().effects.front();
  EXPECT_EQ(first.name, "track_width_error");
  // Wheel-odometry yaw rate ~0.94 x the gyro's (data README): B_eff / B_nominal = omega_odo / omega_true ~ 0.94.
  if (first.name == "track_width_error") {
    const double ratio = (0.555 + first.parameters.at("track_error_m")) / 0.555;
    std::cout << "effective track / nominal = " << ratio << "\n";
    EXPECT_NEAR(ratio, 0.94, 0.03);
  }
}

}  // namespace
}  // namespace roamlab::gap
