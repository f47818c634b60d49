#include "frontend/visual_odometry.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <opencv2/core/utility.hpp>

#include "sim/mujoco_model.h"
#include "sim/render.h"
#include "tests/sim/vo_testing.h"

namespace roamlab::frontend {
namespace {

using sim::CameraPose;
using sim::CameraPoseInWorld;
using sim::CameraRenderer;
using sim::DataPtr;
using sim::IntrinsicsFromFovy;
using sim::MakeData;
using sim::ModelPtr;
using sim::RenderOptions;

constexpr double kRadToDeg = 180.0 / M_PI;

double Median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values.empty() ? NAN : values[values.size() / 2];
}

Eigen::Vector3d LogRotation(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

// CPU time of this thread [s]: the VO's cost without the other processes of a loaded machine (OpenCV runs on
// this thread alone: see the fixture below).
double ThreadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// What a drive of the test room's camera gives against MuJoCo's camera poses.
struct DriveResult {
  bool skipped = false;
  std::string skip_reason;
  VoCounters counters;
  std::vector<double> rotation_error_deg;    // angle of R_est^T R_true per pair
  std::vector<double> speed_relative_error;  // (|p_est| - |p_true|) / |p_true|
  std::vector<double> velocity_error_mps;    // |v_est - v_true|
  std::vector<double> rotation_nees;         // e_w^T P_w^-1 e_w (3 dof), angular velocity
  std::vector<double> velocity_nees;         // e_v^T P_v^-1 e_v (3 dof), linear velocity
  double ms_per_pair = 0.0;
};

// Drives the rig for duration_s, renders at rate_hz and runs the VO on each frame pair. The VO knows the camera's
// height and the floor's normal from the rig's mounting (0.30 m, pitched 15 deg down), not from the poses.
DriveResult Drive(double duration_s, double rate_hz, int width, int height) {
  DriveResult result;
  cv::setNumThreads(0);  // OpenCV on the calling thread only, as on one core
  ModelPtr model = sim::testing::VoTestRoom();
  if (model == nullptr) return result;
  DataPtr data = MakeData(model.get());
  sim::testing::PlaceRig(model.get(), data.get(), sim::testing::RigPoseAt(0.0));
  RenderOptions render;
  render.width_px = width;
  render.height_px = height;
  auto created = CameraRenderer::Create(model.get(), "camera", render);
  if (!created.ok()) {
    result.skipped = true;
    result.skip_reason = created.status().message();
    return result;
  }
  std::unique_ptr<CameraRenderer> renderer = std::move(created).value();
  VisualOdometryOptions options;
  options.camera_height_m = 0.30;
  const double pitch = 15.0 / kRadToDeg;
  options.floor_normal_camera = Eigen::Vector3d(0.0, std::cos(pitch), std::sin(pitch));
  VisualOdometry vo(renderer->intrinsics(), options);

  cv::Mat gray;
  CameraPose previous;
  double vo_seconds = 0.0;
  const int frames = static_cast<int>(std::lround(duration_s * rate_hz)) + 1;
  for (int k = 0; k < frames; ++k) {
    const Time t = Time::FromSeconds(k / rate_hz);
    sim::testing::PlaceRig(model.get(), data.get(), sim::testing::RigPoseAt(t.seconds()));
    renderer->RenderGray(data.get(), &gray);
    const CameraPose truth = CameraPoseInWorld(model.get(), data.get(), renderer->camera_id());
    const double start = ThreadCpuSeconds();
    const std::optional<VoEstimate> estimate = vo.ProcessFrame(t, gray);
    vo_seconds += ThreadCpuSeconds() - start;
    if (estimate) {
      // Truth of the pair from MuJoCo's camera poses, in C1, and the velocities of visual_odometry.h step 5.
      const double dt = 1.0 / rate_hz;
      const Eigen::Matrix3d R12 = previous.R_world_camera.transpose() * truth.R_world_camera;
      const Eigen::Vector3d p12 =
          previous.R_world_camera.transpose() * (truth.p_world_camera_m - previous.p_world_camera_m);
      const Eigen::Vector3d omega = LogRotation(R12) / dt;
      const Eigen::Vector3d v = Eigen::AngleAxisd(-0.5 * dt * omega.norm(), omega.normalized()) * p12 / dt;
      result.rotation_error_deg.push_back(Eigen::AngleAxisd(estimate->R_prev_curr.transpose() * R12).angle() *
                                          kRadToDeg);
      result.speed_relative_error.push_back((estimate->p_prev_curr_m.norm() - p12.norm()) / p12.norm());
      result.velocity_error_mps.push_back((estimate->v_camera_mps - v).norm());
      const Eigen::Vector3d e_w = estimate->omega_camera_radps - omega;
      const Eigen::Vector3d e_v = estimate->v_camera_mps - v;
      result.rotation_nees.push_back(e_w.dot(estimate->covariance.bottomRightCorner<3, 3>().ldlt().solve(e_w)));
      result.velocity_nees.push_back(e_v.dot(estimate->covariance.topLeftCorner<3, 3>().ldlt().solve(e_v)));
    }
    previous = truth;
  }
  result.counters = vo.counters();
  result.ms_per_pair = 1e3 * vo_seconds / std::max(1, result.counters.pairs);
  return result;
}

void Report(const char* name, const DriveResult& r) {
  std::vector<double> abs_speed;
  for (double e : r.speed_relative_error) abs_speed.push_back(std::abs(e));
  std::printf(
      "%s: %d pairs, %d failures (%.1f %%); rotation error median %.4f deg, max %.4f deg; speed error median %.2f %%, "
      "median |signed| bias %.2f %%; velocity error median %.4f m/s; NEES median omega %.2f v %.2f; %.2f ms/pair\n",
      name, r.counters.pairs, r.counters.failures, 100.0 * r.counters.failures / std::max(1, r.counters.pairs),
      Median(r.rotation_error_deg),
      r.rotation_error_deg.empty() ? NAN : *std::max_element(r.rotation_error_deg.begin(), r.rotation_error_deg.end()),
      100.0 * Median(abs_speed), 100.0 * Median(r.speed_relative_error), Median(r.velocity_error_mps),
      Median(r.rotation_nees), Median(r.velocity_nees), r.ms_per_pair);
}

// The accuracy targets on rendered frames at 15 Hz, 320x240, against MuJoCo's camera pose: median rotation error per
// pair <= 0.2 deg, no estimate on <= 5 % of the pairs, median speed error <= 1.5 % (room for other textures and image
// sizes). Covariance: the median NEES of a consistent 3-dof estimate is 2.37 (chi-square(3)); the first-order
// covariance is optimistic (visual_odometry.h says why), and the test holds it within a factor 3 of consistency
// either way.
TEST(VisualOdometryTest, RenderedDriveMeetsTheAccuracyTargets) {
  const DriveResult r = Drive(10.0, 15.0, 320, 240);
  if (r.skipped) GTEST_SKIP() << "no headless OpenGL: " << r.skip_reason;
  Report("320x240 15 Hz", r);
  ASSERT_EQ(r.counters.pairs, 150);
  EXPECT_LE(r.counters.failures, 7);  // 5 % of 150
  ASSERT_GE(r.rotation_error_deg.size(), 143u);
  EXPECT_LE(Median(r.rotation_error_deg), 0.2);
  std::vector<double> abs_speed;
  for (double e : r.speed_relative_error) abs_speed.push_back(std::abs(e));
  EXPECT_LE(Median(abs_speed), 0.015);
  constexpr double kChiSquare3Median = 2.366;
  EXPECT_LT(Median(r.rotation_nees), 3.0 * kChiSquare3Median);
  EXPECT_GT(Median(r.rotation_nees), kChiSquare3Median / 3.0);
  EXPECT_LT(Median(r.velocity_nees), 3.0 * kChiSquare3Median);
  EXPECT_GT(Median(r.velocity_nees), kChiSquare3Median / 3.0);
}

TEST(VisualOdometryTest, RenderedDriveAt640x480) {
  const DriveResult r = Drive(3.0, 15.0, 640, 480);
  if (r.skipped) GTEST_SKIP() << "no headless OpenGL: " << r.skip_reason;
  Report("640x480 15 Hz", r);
  ASSERT_EQ(r.counters.pairs, 45);
  EXPECT_LE(r.counters.failures, 2);  // 5 % of 45
  EXPECT_LE(Median(r.rotation_error_deg), 0.2);
}

// The same image twice: no flow, a zero velocity flagged stationary with a positive-definite covariance.
TEST(VisualOdometryTest, SameImageTwiceIsStationary) {
  ModelPtr model = sim::testing::VoTestRoom();
  ASSERT_NE(model, nullptr);
  DataPtr data = MakeData(model.get());
  sim::testing::PlaceRig(model.get(), data.get(), sim::testing::RigPoseAt(0.0));
  auto renderer = CameraRenderer::Create(model.get(), "camera", RenderOptions{});
  if (!renderer.ok()) GTEST_SKIP() << "no headless OpenGL: " << renderer.status().message();
  cv::Mat gray;
  renderer.value()->RenderGray(data.get(), &gray);
  VisualOdometryOptions options;
  options.camera_height_m = 0.3;
  options.floor_normal_camera = Eigen::Vector3d(0.0, 1.0, 0.0);
  VisualOdometry vo(renderer.value()->intrinsics(), options);
  EXPECT_FALSE(vo.ProcessFrame(Time::FromSeconds(0.0), gray));
  const auto estimate = vo.ProcessFrame(Time::FromSeconds(0.1), gray);
  ASSERT_TRUE(estimate);
  EXPECT_TRUE(estimate->stationary);
  EXPECT_EQ(estimate->v_camera_mps.norm(), 0.0);
  EXPECT_EQ(estimate->omega_camera_radps.norm(), 0.0);
  EXPECT_EQ(estimate->t_mid, Time::FromSeconds(0.05));
  EXPECT_GT(estimate->covariance.diagonal().minCoeff(), 0.0);
  EXPECT_EQ(vo.counters().estimates, 1);
}

// A blank image has no corners: every pair fails and is counted as such.
TEST(VisualOdometryTest, BlankImagesFailAndAreCounted) {
  const PinholeIntrinsics k = IntrinsicsFromFovy(60.0, 320, 240);
  VisualOdometryOptions options;
  options.camera_height_m = 0.3;
  options.floor_normal_camera = Eigen::Vector3d(0.0, 1.0, 0.0);
  VisualOdometry vo(k, options);
  const cv::Mat blank(240, 320, CV_8UC1, cv::Scalar(128));
  for (int i = 0; i < 4; ++i) EXPECT_FALSE(vo.ProcessFrame(Time::FromSeconds(0.1 * i), blank));
  EXPECT_EQ(vo.last_failure(), VoFailure::kTooFewFeatures);
  EXPECT_EQ(vo.counters().frames, 4);
  EXPECT_EQ(vo.counters().pairs, 3);
  EXPECT_EQ(vo.counters().failures, 3);
  EXPECT_EQ(vo.counters().too_few_features, 3);
  EXPECT_EQ(vo.counters().estimates, 0);
}

TEST(VisualOdometryOptionsTest, ValidateNamesTheProblem) {
  VisualOdometryOptions options;
  EXPECT_EQ(options.Validate(), "camera_height_m must be positive");
  options.camera_height_m = 0.3;
  options.floor_normal_camera = Eigen::Vector3d(0.0, 2.0, 0.0);
  EXPECT_EQ(options.Validate(), "floor_normal_camera must be a unit vector");
  options.floor_normal_camera = Eigen::Vector3d(0.0, 1.0, 0.0);
  EXPECT_EQ(options.Validate(), "");
}

}  // namespace
}  // namespace roamlab::frontend
