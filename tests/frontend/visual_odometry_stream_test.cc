#include "frontend/visual_odometry_stream.h"

#include <gtest/gtest.h>

namespace roamlab::frontend {
namespace {

TEST(VisualOdometryStreamTest, RowHoldsVelocitiesThenTheCovarianceUpperTriangle) {
  VoEstimate estimate;
  estimate.v_camera_mps = Eigen::Vector3d(1.0, 2.0, 3.0);
  estimate.omega_camera_radps = Eigen::Vector3d(4.0, 5.0, 6.0);
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) estimate.covariance(i, j) = 10.0 * i + j;
  const Eigen::Matrix<double, 1, 27> row = VisualOdometryRow(estimate);
  EXPECT_EQ(row[0], 1.0);
  EXPECT_EQ(row[5], 6.0);
  EXPECT_EQ(row[6], 0.0);    // cov_vx_vx
  EXPECT_EQ(row[7], 1.0);    // cov_vx_vy
  EXPECT_EQ(row[12], 11.0);  // cov_vy_vy
  EXPECT_EQ(row[26], 55.0);  // cov_wz_wz
}

TEST(VisualOdometryStreamTest, IntrinsicsAndFloorRoundTripThroughAttributes) {
  PinholeIntrinsics k;
  k.width_px = 320;
  k.height_px = 240;
  k.fx_px = 207.8;
  k.fy_px = 207.9;
  k.cx_px = 159.5;
  k.cy_px = 119.5;
  const Result<PinholeIntrinsics> back = IntrinsicsOfAttributes(IntrinsicsAttributes(k));
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back.value().width_px, 320);
  EXPECT_EQ(back.value().fy_px, 207.9);
  EXPECT_EQ(back.value().cy_px, 119.5);

  VisualOdometryOptions options;
  options.camera_height_m = 0.275;
  options.floor_normal_camera = Eigen::Vector3d(0.0, 0.8, 0.6);
  VisualOdometryOptions read;
  ASSERT_TRUE(ReadFloorAttributes(FloorAttributes(options), &read).ok());
  EXPECT_EQ(read.camera_height_m, 0.275);
  EXPECT_EQ(read.floor_normal_camera, options.floor_normal_camera);
  EXPECT_EQ(read.Validate(), "");

  std::map<std::string, double> attributes = IntrinsicsAttributes(k);
  attributes.erase("cx_px");
  EXPECT_EQ(IntrinsicsOfAttributes(attributes).status().message(), "attribute cx_px missing");
  EXPECT_EQ(ReadFloorAttributes(attributes, &read).message(), "attribute camera_height_m missing");
}

}  // namespace
}  // namespace roamlab::frontend
