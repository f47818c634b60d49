#include "sim/simulated_camera.h"

#include <cmath>
#include <filesystem>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "recording/recording.h"
#include "tests/recording/temp_dir.h"
#include "tests/sim/vo_testing.h"

namespace roamlab::sim {
namespace {

using ::testing::HasSubstr;

// A 2 s drive of the test room's rig stepped at 500 Hz, with the camera observing every step and keeping its images:
// rows at 15 Hz in the recording format, the measured mounting and floor, PNGs listed in a camera stream.
TEST(SimulatedCameraTest, RowsMountingAndImagesFromASteppingLoop) {
  ModelPtr model = testing::VoTestRoom();
  ASSERT_NE(model, nullptr);
  DataPtr data = MakeData(model.get());
  testing::PlaceRig(model.get(), data.get(), testing::RigPoseAt(0.0));
  roamlab::testing::TempDir dir;
  SimulatedCameraOptions options;
  options.image_directory = dir.path();
  auto created = SimulatedCamera::Create(model.get(), data.get(), options);
  if (!created.ok() && created.status().message().rfind("EGL:", 0) == 0) {
    GTEST_SKIP() << "no headless OpenGL: " << created.status().message();
  }
  ASSERT_TRUE(created.ok()) << created.status().message();
  SimulatedCamera& vo = *created.value();

  // Mounting and floor from the initial state: 0.30 m above the rig's origin, pitched 15 deg down.
  EXPECT_NEAR(vo.vo_options().camera_height_m, 0.30, 1e-9);
  const double pitch = 15.0 * M_PI / 180.0;
  EXPECT_LT((vo.vo_options().floor_normal_camera - Eigen::Vector3d(0.0, std::cos(pitch), std::sin(pitch))).norm(),
            1e-6);
  EXPECT_LT((vo.mounting().p_body_sensor - Eigen::Vector3d(0.0, 0.0, 0.30)).norm(), 1e-9);
  // C's z axis (forward) is the rig's x axis pitched down.
  const Eigen::Vector3d forward = vo.mounting().q_body_sensor * Eigen::Vector3d::UnitZ();
  EXPECT_LT((forward - Eigen::Vector3d(std::cos(pitch), 0.0, -std::sin(pitch))).norm(), 1e-6);

  // The stepping loop.
  int processed = 0;
  for (int step = 0; step <= 1000; ++step) {
    const Time t = Time::FromNanoseconds(2'000'000LL * step);
    testing::PlaceRig(model.get(), data.get(), testing::RigPoseAt(t.seconds()));
    const auto observed = vo.Observe(t, data.get());
    ASSERT_TRUE(observed.ok()) << observed.status().message();
    processed += observed.value().has_value();
  }
  // Frames at 0, 1/15, ..., 2 s (the first step at or after each): 31 frames, 30 pairs.
  EXPECT_EQ(vo.counters().frames, 31);
  EXPECT_EQ(vo.counters().pairs, 30);
  EXPECT_EQ(vo.counters().estimates, processed);
  EXPECT_GE(processed, 29);

  // The streams, written and read back.
  recording::Recording recording;
  recording.platform.kind = "mocap_rig";
  recording.streams.push_back(vo.TakeStream());
  const std::optional<recording::Stream> images = vo.TakeCameraStream();
  ASSERT_TRUE(images);
  recording.streams.push_back(*images);
  ASSERT_TRUE(recording::WriteRecording(recording, dir.path()).ok());
  const auto read = recording::ReadRecording(dir.path());
  ASSERT_TRUE(read.ok()) << read.status().message();
  const recording::Stream& stream = *read.value().Find("visual_odometry");
  EXPECT_EQ(stream.info.type, recording::StreamType::kVisualOdometry);
  ASSERT_EQ(stream.values.rows(), processed);
  ASSERT_EQ(stream.values.cols(), 27);
  EXPECT_EQ(stream.info.attributes.at("width_px"), 320.0);
  EXPECT_NEAR(stream.info.attributes.at("fy_px"), 120.0 / std::tan(M_PI / 6.0), 1e-9);
  // The rig drives forward (along C's z) at 0.25 to 0.95 m/s; the variances are positive.
  for (Eigen::Index i = 0; i < stream.values.rows(); ++i) {
    EXPECT_GT(stream.values(i, 2), 0.2) << "row " << i;
    EXPECT_LT(stream.values(i, 2), 1.0) << "row " << i;
    EXPECT_GT(stream.values(i, 6), 0.0);
    EXPECT_GT(stream.values(i, 26), 0.0);
  }
  // The images: one PNG per frame, RGB at the render size.
  const recording::Stream& camera = *read.value().Find("visual_odometry_images");
  ASSERT_EQ(camera.text.size(), 31u);
  EXPECT_EQ(camera.text[0], "visual_odometry/000000.png");
  // Its attributes hold what the front end needs to reproduce the stream: the intrinsics and the floor reference.
  EXPECT_EQ(camera.info.attributes.at("fx_px"), stream.info.attributes.at("fx_px"));
  EXPECT_EQ(camera.info.attributes.at("camera_height_m"), vo.vo_options().camera_height_m);
  EXPECT_EQ(camera.info.attributes.at("floor_normal_y"), vo.vo_options().floor_normal_camera.y());
  const cv::Mat png = cv::imread(dir.File(camera.text[30]), cv::IMREAD_COLOR);
  EXPECT_EQ(png.cols, 320);
  EXPECT_EQ(png.rows, 240);
}

TEST(SimulatedCameraTest, BadOptionsAreErrors) {
  ModelPtr model = testing::VoTestRoom();
  ASSERT_NE(model, nullptr);
  DataPtr data = MakeData(model.get());
  mj_forward(model.get(), data.get());
  SimulatedCameraOptions options;
  options.rate_hz = 0.0;
  auto rate = SimulatedCamera::Create(model.get(), data.get(), options);
  ASSERT_FALSE(rate.ok());
  EXPECT_THAT(rate.status().message(), HasSubstr("rate_hz must be in (0, 1000]"));
  options.rate_hz = 15.0;
  options.camera = "missing";
  auto camera = SimulatedCamera::Create(model.get(), data.get(), options);
  ASSERT_FALSE(camera.ok());
  EXPECT_THAT(camera.status().message(), HasSubstr("camera"));
}

}  // namespace
}  // namespace roamlab::sim
