// The diagnosis on real recordings (tests/support/real_data.h, skipped when absent), where nothing labels the effects,
// with the standard deviations `roamlab diagnose` reports by default (HAC on an imported recording):
// OptiOdom's differential drive (unequal wheel diameters, a wider effective track) and the Husky bag (skid-steer yaw
// mismatch). The data README's reference values come from a "quick least-squares look", not from ground truth; the
// OptiOdom test checks the diagnosis against an independent least-squares fit on the same run instead (YawRatio).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include "estimator/config.h"
#include "estimator/models/differential_drive.h"
#include "gap/diagnose.h"
#include "importers/optiodom.h"
#include "importers/rosbag.h"
#include "tests/support/husky_bag.h"
#include "tests/support/paths.h"
#include "tests/support/real_data.h"

namespace roamlab::gap {
namespace {

const std::string kData = ::roamlab::testing::RealDataDir();
// A Dec-2020 square set: straight legs and turns in place separate the wheel ratio from the track (a circle at
// constant curvature does not: there the ratio trades against the track and the time offset).
const std::string kSet = kData + "/optiodom/data/diff/square/231220200029/231220200029";

// The diagnosis as `roamlab diagnose` runs it by default: on an imported recording the effects' standard deviations are
// the HAC ones (autocorrelated residuals), against which the significance checks below are made.
Result<Diagnosis> DiagnoseDefault(const estimator::EstimatorConfig& config, const recording::Recording& rec) {
  auto d = Diagnose(config, rec);
  if (d.ok()) {
    EXPECT_EQ(d.value().std_method, "hac");
  }
  return d;
}

const EffectEstimate* Find(const Diagnosis& d, const std::string& name) {
  for (const EffectEstimate& e : d.effects)
    if (e.name == name) return &e;
  return nullptr;
}

// Dead reckoning of a run's encoders with the given geometry against the motion capture (both streams share the
// stamps): the RMS of the planar position error [m] over every sample. The dead reckoning restarts from the motion
// capture's pose every `segment` samples (0: starts once, at the first pose), so that a short segment measures the
// drift over that span (a relative pose error) rather than where the first turns happened to send the heading.
double DeadReckoningRms(const recording::Recording& rec, double radius_left, double radius_right, double track,
                        Eigen::Index segment = 0) {
  const recording::Stream* enc = rec.Find("wheel_encoders");
  const recording::Stream* mocap = rec.Find("mocap");
  const auto yaw_at = [&](Eigen::Index k) { return 2.0 * std::atan2(mocap->values(k, 5), mocap->values(k, 6)); };
  double x = 0.0, y = 0.0, yaw = 0.0, sum = 0.0;
  const Eigen::Index n = std::min(enc->values.rows(), mocap->values.rows());
  for (Eigen::Index k = 0; k + 1 < n; ++k) {
    if (k == 0 || (segment > 0 && k % segment == 0)) {
      x = mocap->values(k, 0);
      y = mocap->values(k, 1);
      yaw = yaw_at(k);
    }
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

// An independent look at the wheel ratio: the motion capture's yaw increments over windows of 5 cycles regressed on
// the two wheels' angle increments, dyaw = a_R dphi_R - a_L dphi_L with a = r / B (eq. 7's yaw row), by ordinary
// least squares; rho = a_R / a_L. Only the yaw enters: the forward displacement in a turn in place, which also
// depends on where the motion-capture frame sits on the robot, does not.
double YawRatio(const recording::Recording& rec) {
  const recording::Stream* enc = rec.Find("wheel_encoders");
  const recording::Stream* mocap = rec.Find("mocap");
  constexpr Eigen::Index kWindow = 5;
  const Eigen::Index n = (std::min(enc->values.rows(), mocap->values.rows()) - 1) / kWindow;
  Eigen::MatrixXd X(n, 2);
  Eigen::VectorXd y(n);
  const auto yaw = [&](Eigen::Index k) { return 2.0 * std::atan2(mocap->values(k, 5), mocap->values(k, 6)); };
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Index a = i * kWindow, b = a + kWindow;
    X(i, 0) = enc->values(b, 0) - enc->values(a, 0);
    X(i, 1) = -(enc->values(b, 1) - enc->values(a, 1));
    y[i] = std::remainder(yaw(b) - yaw(a), 2.0 * M_PI);
  }
  const Eigen::Vector2d coef = X.colPivHouseholderQr().solve(y);
  return coef[0] / coef[1];
}

TEST(RealDataTest, OptiOdomDifferentialDriveTrackAndWheelRatio) {
  if (!std::filesystem::exists(kSet + "_metadata.csv")) GTEST_SKIP() << "real data absent: " << kSet;
  auto rec = importers::ImportOptiOdom(kSet + "_run-01.csv", kSet + "_metadata.csv");
  ASSERT_TRUE(rec.ok()) << rec.status().message();
  auto config =
      estimator::LoadEstimatorConfig(roamlab::testing::SourceDir() + "/configs/real/optiodom_diff_nominal.yaml");
  ASSERT_TRUE(config.ok()) << config.status().message();
  auto d = DiagnoseDefault(config.value(), rec.value());
  ASSERT_TRUE(d.ok()) << d.status().message();
  const Diagnosis& diagnosis = d.value();
  for (const EffectEstimate& e : diagnosis.candidates) {
    std::cout << e.name;
    for (const auto& [k, v] : e.parameters) {
      std::cout << " " << k << " = " << v;
      if (e.std.count(k)) std::cout << " +- " << e.std.at(k);
    }
    std::cout << " LR " << e.lr << " dBIC " << e.delta_bic << " " << e.decision << "\n";
  }
  EXPECT_EQ(diagnosis.verdict, "named");
  const EffectEstimate* track = Find(diagnosis, "track_width_error");
  const EffectEstimate* ratio = Find(diagnosis, "wheel_radius_asymmetry");
  ASSERT_NE(track, nullptr);
  ASSERT_NE(ratio, nullptr);
  // The effective track: wider than the nominal 0.2 m; the data README's look says about 0.2027 m.
  const double b_eff = 0.2 + track->parameters.at("track_error_m");
  std::cout << "effective track " << b_eff << " m +- " << track->std.at("track_error_m") << "\n";
  // With the HAC std (1.7 mm; the white one is 0.19 mm) the track error of this one run is about one std from zero:
  // not significant on its own, but its 2-sigma interval holds the dataset's value.
  EXPECT_NEAR(b_eff, 0.2027, 0.002);
  EXPECT_NEAR(b_eff, 0.2027, 2.0 * track->std.at("track_error_m"));
  // The wheel ratio against the independent yaw regression on the same run. The data README's 0.983-0.989 is not
  // what the yaw says (about 0.998 on every Dec-2020 square run): it comes from the forward displacement in turns in
  // place, which a millimetre's offset of the motion-capture frame from the axle centre explains as well.
  const double rho = ratio->parameters.at("ratio_right_left");
  const double rho_yaw = YawRatio(rec.value());
  std::cout << "wheel ratio R/L: diagnosis " << rho << " +- " << ratio->std.at("ratio_right_left")
            << ", yaw regression " << rho_yaw << "\n";
  // With the HAC std (0.0008; the white one is 0.0004) the ratio is about 2 std below 1, not 3: the claim is the
  // agreement with the independent regression within its 2-sigma interval.
  EXPECT_NEAR(rho, rho_yaw, 0.002);
  EXPECT_NEAR(rho, rho_yaw, 2.0 * ratio->std.at("ratio_right_left"));

  // Other runs of the set: dead reckoning with the geometry calibrated on the training part of run 01 with the
  // accepted effects (the radius re-fitted beside them) against the nominal model calibrated on the same part (one
  // radius, track 0.2 m: the held-out part's `before` and `after`), and against the manufacturer's values.
  const auto& before = diagnosis.training_parameters_before;
  const auto& after = diagnosis.training_parameters_after;
  const double r0 = before.at("wheels.radius")[0];
  const double r = after.at("wheels.radius")[0];
  const double rho_fit = after.at("wheels.right_left_ratio")[0];
  const double b = after.at("wheels.baseline")[0];
  std::cout << "radius: nominal " << r0 << " m; patched left " << r << " m, right " << rho_fit * r << " m, track " << b
            << " m\n";
  // The data README's quick look (D_R / D_L 0.986, the middle of its 0.983-0.989, track 0.2027 m) at the patch's
  // mean radius, so that only the wheels' ratio and the track differ from the patch.
  const double mean_radius = 0.5 * (1.0 + rho_fit) * r;
  const double readme_left = 2.0 * mean_radius / (1.0 + 0.986), readme_right = 0.986 * readme_left;
  // Whole runs (the robot's 69 s drives) and 10 s segments (200 samples).
  double whole_nominal = 0.0, whole_patched = 0.0, seg_nominal = 0.0, seg_patched = 0.0;
  for (const char* run : {"02", "03", "04", "05", "06"}) {
    auto other = importers::ImportOptiOdom(kSet + "_run-" + run + ".csv", kSet + "_metadata.csv");
    ASSERT_TRUE(other.ok()) << other.status().message();
    const recording::Recording& o = other.value();
    const double nominal = DeadReckoningRms(o, r0, r0, 0.2), patched = DeadReckoningRms(o, r, rho_fit * r, b);
    const double readme = DeadReckoningRms(o, readme_left, readme_right, 0.2027);
    const double nominal_10s = DeadReckoningRms(o, r0, r0, 0.2, 200);
    const double patched_10s = DeadReckoningRms(o, r, rho_fit * r, b, 200);
    std::cout << "run " << run << ": dead-reckoning RMS whole run: manufacturer "
              << DeadReckoningRms(o, 0.042, 0.042, 0.2) << " m, nominal " << nominal << " m, patched " << patched
              << " m, data README's ratio " << readme << " m; 10 s segments: manufacturer "
              << DeadReckoningRms(o, 0.042, 0.042, 0.2, 200) << " m, nominal " << nominal_10s << " m, patched "
              << patched_10s << " m\n";
    // The yaw's ratio, not the data README's, is what these runs bear out.
    EXPECT_LT(patched, readme) << "run " << run;
    whole_nominal += nominal / 5.0;
    whole_patched += patched / 5.0;
    seg_nominal += nominal_10s / 5.0;
    seg_patched += patched_10s / 5.0;
  }
  std::cout << "mean over runs 02-06: whole run nominal " << whole_nominal << " m, patched " << whole_patched
            << " m; 10 s segments nominal " << seg_nominal << " m, patched " << seg_patched << " m\n";
  // Only the whole runs are asserted: over 10 s segments (errors of 3-10 mm) the patch does not help, since there the
  // error is of the size of the clock offset between the encoders and the motion capture, one 50 ms cycle that jumps
  // within a run.
  EXPECT_LT(whole_patched, whole_nominal);
}

// An independent look at the skid-steer yaw mismatch: over 5 s windows in which the gyroscope turns more than 0.5 rad,
// the least-squares ratio of the wheel odometry's heading change (its own wz) to the gyroscope's (the sensor's y axis
// is vertical), both integrated by the rectangle rule.
double HeadingRatioInTurns(const recording::Recording& rec) {
  const recording::Stream* odo = rec.Find("odometry");
  const recording::Stream* imu = rec.Find("imu");
  const auto integral = [](const recording::Stream& s, Eigen::Index col, double a, double b) {
    double sum = 0.0;
    for (std::size_t i = 0; i + 1 < s.t.size(); ++i) {
      const double t0 = std::max(a, s.t[i].seconds()), t1 = std::min(b, s.t[i + 1].seconds());
      if (t1 > t0) sum += s.values(static_cast<Eigen::Index>(i), col) * (t1 - t0);
    }
    return sum;
  };
  double og = 0.0, gg = 0.0;
  for (double a = odo->t.front().seconds() + 1.0; a + 5.0 < odo->t.back().seconds() - 1.0; a += 5.0) {
    const double g = integral(*imu, 1, a, a + 5.0), o = integral(*odo, 5, a, a + 5.0);
    if (std::abs(g) < 0.5) continue;
    og += o * g;
    gg += g * g;
  }
  return og / gg;
}

TEST(RealDataTest, HuskySkidSteerYawMismatch) {
  const std::string bag = kData + "/husky_test1/test1.bag";
  if (!std::filesystem::exists(bag)) GTEST_SKIP() << "real data absent: " << bag;
  auto rec = importers::ImportRosbag(bag, ::roamlab::testing::HuskyImportOptions());
  ASSERT_TRUE(rec.ok()) << rec.status().message();
  auto config = estimator::LoadEstimatorConfig(roamlab::testing::SourceDir() + "/configs/real/husky_nominal.yaml");
  ASSERT_TRUE(config.ok()) << config.status().message();
  auto d = DiagnoseDefault(config.value(), rec.value());
  ASSERT_TRUE(d.ok()) << d.status().message();
  for (const EffectEstimate& e : d.value().candidates) {
    std::cout << e.name;
    for (const auto& [k, v] : e.parameters) {
      std::cout << " " << k << " = " << v;
      if (e.std.count(k)) std::cout << " +- " << e.std.at(k);
    }
    std::cout << " LR " << e.lr << " dBIC " << e.delta_bic << " " << e.decision << "\n";
  }
  for (const std::string& u : d.value().unexplained) std::cout << "unexplained: " << u << "\n";
  // Both effects below are kept. The verdict is "unknown": a GPS component stays several times its level on
  // the held-out part with them, structure of the real receiver that no candidate of
  // the library models (the verdict's rule), so it is reported beside the named effects rather than hidden.
  EXPECT_NE(d.value().verdict, "none");
  EXPECT_EQ(d.value().effects.size(), 2u);
  // The wheel odometry reaches the bag late against the IMU (its velocities are a rolling mean in the controller):
  // the IMU's stamps move later to meet it, a negative offset. Its HAC std (0.19 s; the white one 0.036 s) leaves the
  // estimate (-0.25 s) about 1.3 std from zero: named (by its chi-square drop and the held-out part), but not
  // significant by its std alone, so only the sign is claimed.
  const EffectEstimate* offset = Find(d.value(), "imu_time_offset");
  ASSERT_NE(offset, nullptr);
  EXPECT_LT(offset->parameters.at("offset_s"), 0.0);
  // The skid-steer yaw mismatch: wheel speeds converted with the nominal track turn the odometry slower than the
  // robot turns, so the effective track is narrower: B_eff / B_nominal = omega_odometry / omega_gyro.
  const EffectEstimate* track = Find(d.value(), "track_width_error");
  ASSERT_NE(track, nullptr);
  const double ratio = (0.555 + track->parameters.at("track_error_m")) / 0.555;
  const double ratio_std = track->std.at("track_error_m") / 0.555;
  const double heading_ratio = HeadingRatioInTurns(rec.value());
  std::cout << "effective track / nominal = " << ratio << " +- " << ratio_std << "; heading ratio in turns "
            << heading_ratio << "\n";
  EXPECT_LT(ratio, 1.0 - 3.0 * ratio_std);
  EXPECT_NEAR(ratio, heading_ratio, 3.0 * ratio_std);
}

}  // namespace
}  // namespace roamlab::gap
