#include "sim/render.h"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "sim/mujoco_model.h"
#include "tests/sim/vo_testing.h"

namespace roamlab::sim {
namespace {

using ::testing::HasSubstr;

// Creates a renderer or skips the test when EGL is unavailable (any other error fails it).
#define ROAMLAB_RENDERER_OR_SKIP(var, model, camera, options)                        \
  auto var##_result = CameraRenderer::Create(model, camera, options);                \
  if (!var##_result.ok() && var##_result.status().message().rfind("EGL:", 0) == 0) { \
    GTEST_SKIP() << "no headless OpenGL: " << var##_result.status().message();       \
  }                                                                                  \
  ASSERT_TRUE(var##_result.ok()) << var##_result.status().message();                 \
  std::unique_ptr<CameraRenderer> var = std::move(var##_result).value()

TEST(IntrinsicsTest, FromFovy) {
  const PinholeIntrinsics k = IntrinsicsFromFovy(60.0, 320, 240);
  EXPECT_NEAR(k.fy_px, 120.0 / std::tan(M_PI / 6.0), 1e-9);
  EXPECT_EQ(k.fx_px, k.fy_px);
  EXPECT_EQ(k.cx_px, 159.5);
  EXPECT_EQ(k.cy_px, 119.5);
  // The top edge of the field of view (fovy / 2 above the axis) is the top edge of the image, v = -0.5.
  const Eigen::Vector2d top = k.Project(Eigen::Vector3d(0.0, -std::tan(M_PI / 6.0), 1.0));
  EXPECT_NEAR(top.y(), -0.5, 1e-9);
}

TEST(RenderTest, TexturedImageWithTheFloorAtTheBottom) {
  ModelPtr model = testing::VoTestRoom();
  ASSERT_NE(model, nullptr);
  DataPtr data = MakeData(model.get());
  testing::PlaceRig(model.get(), data.get(), testing::RigPoseAt(0.0));
  ROAMLAB_RENDERER_OR_SKIP(renderer, model.get(), "camera", RenderOptions{});
  cv::Mat rgb;
  renderer->RenderRgb(data.get(), &rgb);
  ASSERT_EQ(rgb.type(), CV_8UC3);
  ASSERT_EQ(rgb.cols, 320);
  ASSERT_EQ(rgb.rows, 240);
  // Texture: the grey levels vary.
  cv::Mat gray;
  renderer->RenderGray(data.get(), &gray);
  cv::Scalar mean;
  cv::Scalar stddev;
  cv::meanStdDev(gray, mean, stddev);
  EXPECT_GT(stddev[0], 15.0);
  EXPECT_GT(mean[0], 40.0);
  // Orientation: the floor (brown, red > blue) fills the bottom rows, the wall (blue-grey, blue > red) the top rows.
  const cv::Scalar bottom = cv::mean(rgb.rowRange(200, 240));
  const cv::Scalar top = cv::mean(rgb.rowRange(0, 30));
  EXPECT_GT(bottom[0], bottom[2] + 8.0) << "bottom RGB " << bottom;
  EXPECT_GT(top[2], top[0] + 8.0) << "top RGB " << top;
}

// Two small bright spheres on a black background: their centroids are where the intrinsics project their centres.
TEST(RenderTest, IntrinsicsProjectKnownWorldPoints) {
  const std::string xml = R"(
    <mujoco>
      <visual><headlight ambient="1 1 1" diffuse="0 0 0" specular="0 0 0"/></visual>
      <worldbody>
        <body name="rig" pos="0.1 -0.2 0.3" euler="5 -10 20">
          <camera name="camera" pos="0 0 0" xyaxes="0 -1 0 0.2 0 1" fovy="50"/>
        </body>
        <geom name="a" type="sphere" size="0.01" pos="2.0 0.3 0.1" rgba="1 0 0 1"/>
        <geom name="b" type="sphere" size="0.01" pos="2.5 1.0 0.9" rgba="0 1 0 1"/>
      </worldbody>
    </mujoco>)";
  auto model = LoadModelFromString(xml);
  ASSERT_TRUE(model.ok()) << model.status().message();
  DataPtr data = MakeData(model.value().get());
  mj_forward(model.value().get(), data.get());
  RenderOptions options;
  options.width_px = 640;
  options.height_px = 480;
  ROAMLAB_RENDERER_OR_SKIP(renderer, model.value().get(), "camera", options);
  cv::Mat rgb;
  renderer->RenderRgb(data.get(), &rgb);
  const CameraPose camera = CameraPoseInWorld(model.value().get(), data.get(), renderer->camera_id());
  for (int channel : {0, 1}) {
    const int geom = channel;  // geoms "a" (red) and "b" (green), in order
    const Eigen::Vector3d p_world(data->geom_xpos + 3 * geom);
    const Eigen::Vector3d p_camera = camera.R_world_camera.transpose() * (p_world - camera.p_world_camera_m);
    ASSERT_GT(p_camera.z(), 0.0);
    const Eigen::Vector2d expected = renderer->intrinsics().Project(p_camera);
    // Centroid of the sphere's pixels, weighted by intensity.
    cv::Mat plane;
    cv::extractChannel(rgb, plane, channel);
    const cv::Moments m = cv::moments(plane);
    ASSERT_GT(m.m00, 0.0) << "sphere " << geom << " not visible";
    EXPECT_NEAR(m.m10 / m.m00, expected.x(), 0.5) << "sphere " << geom;
    EXPECT_NEAR(m.m01 / m.m00, expected.y(), 0.5) << "sphere " << geom;
    // The point is not trivially at the centre: the test checks the focal length too.
    EXPECT_GT((expected - Eigen::Vector2d(319.5, 239.5)).norm(), 40.0);
  }
}

TEST(RenderTest, UnknownCameraIsAnError) {
  ModelPtr model = testing::VoTestRoom();
  ASSERT_NE(model, nullptr);
  const auto renderer = CameraRenderer::Create(model.get(), "nope", RenderOptions{});
  ASSERT_FALSE(renderer.ok());
  EXPECT_THAT(renderer.status().message(), HasSubstr("no camera named 'nope'"));
  RenderOptions bad;
  bad.width_px = 0;
  const auto sized = CameraRenderer::Create(model.get(), "camera", bad);
  ASSERT_FALSE(sized.ok());
  EXPECT_THAT(sized.status().message(), HasSubstr("image size 0x240"));
}

}  // namespace
}  // namespace roamlab::sim
