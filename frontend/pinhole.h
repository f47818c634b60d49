// The pinhole camera model of the visual odometry and of camera streams (recording.h, camera intrinsics): no
// distortion, pixel coordinates in OpenCV's convention (the centre of the top-left pixel is (0, 0)), camera frame C
// x right, y down, z forward. A point p_C = (x, y, z), z > 0, projects to u = fx x / z + cx, v = fy y / z + cy.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace roamlab::frontend {

// Pinhole intrinsics. Units: pixels.
struct PinholeIntrinsics {
  int width_px = 0;
  int height_px = 0;
  double fx_px = 0.0;
  double fy_px = 0.0;
  double cx_px = 0.0;
  double cy_px = 0.0;

  cv::Matx33d K() const { return {fx_px, 0.0, cx_px, 0.0, fy_px, cy_px, 0.0, 0.0, 1.0}; }
  // Pixel of a point in the camera frame C (z > 0).
  Eigen::Vector2d Project(const Eigen::Vector3d& p_camera_m) const {
    return {fx_px * p_camera_m.x() / p_camera_m.z() + cx_px, fy_px * p_camera_m.y() / p_camera_m.z() + cy_px};
  }
};

}  // namespace roamlab::frontend
