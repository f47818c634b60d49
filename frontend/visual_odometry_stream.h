// The visual odometry as a recording stream: grayscale frames in (ProcessFrame, in time order), a visual_odometry
// stream out:
//
//   t, vx, vy, vz [m/s], wx, wy, wz [rad/s], then the 21 covariance columns cov_vx_vx, cov_vx_vy, ..., cov_wz_wz
//   (upper triangle of the 6x6 covariance of [v; w], row by row, in (m/s)^2, m/s rad/s, (rad/s)^2)
//
// in OpenCV's camera frame C (x right, y down, z forward; the frame at the start of the pair), stamped at the middle
// of each frame pair (visual_odometry.h, step 5). A failed pair writes no row; counters() says how many and why.
// The stream entry carries the camera's intrinsics as attributes (width_px, height_px, fx_px, fy_px, cx_px, cy_px,
// recording.h); the caller sets the mounting.
//
// The camera stream a front end reads (recording.h, type camera) carries, besides the intrinsics, the floor reference
// the VO's scale needs (visual_odometry.h, step 4), measured on the robot standing level:
//   camera_height_m                                  the camera centre's height over the floor [m]
//   floor_normal_x, floor_normal_y, floor_normal_z   the floor's unit normal in C, pointing down to the floor
#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "common/status.h"
#include "common/time.h"
#include "frontend/pinhole.h"
#include "frontend/visual_odometry.h"
#include "recording/recording.h"

namespace roamlab::frontend {

class VisualOdometryStream {
 public:
  // Options must be valid (VisualOdometryOptions::Validate), as for VisualOdometry.
  VisualOdometryStream(const PinholeIntrinsics& intrinsics, const VisualOdometryOptions& options,
                       std::string stream_name, double rate_hz);

  // Processes the frame taken at t (CV_8UC1, the intrinsics' size, after the previous frame); a successful pair
  // appends a row. Returns the pair's estimate (nullopt for the first frame and a failed pair).
  std::optional<VoEstimate> ProcessFrame(Time t, const cv::Mat& gray);

  // The visual_odometry stream so far (rows of successful pairs), without mounting.
  recording::Stream TakeStream() const;

  const VoCounters& counters() const { return vo_.counters(); }
  const VisualOdometryOptions& options() const { return vo_.options(); }
  const PinholeIntrinsics& intrinsics() const { return vo_.intrinsics(); }

 private:
  VisualOdometry vo_;
  std::string stream_name_;
  double rate_hz_ = 0.0;
  std::vector<Time> t_;
  std::vector<Eigen::Matrix<double, 1, 27>> rows_;
};

// The stream row of an estimate: [v (3), omega (3), the covariance's upper triangle row by row (21)].
Eigen::Matrix<double, 1, 27> VisualOdometryRow(const VoEstimate& estimate);

// The six intrinsics attributes (recording.h) of `intrinsics`, and the intrinsics of a stream's attributes (error:
// "<attribute> missing").
std::map<std::string, double> IntrinsicsAttributes(const PinholeIntrinsics& intrinsics);
Result<PinholeIntrinsics> IntrinsicsOfAttributes(const std::map<std::string, double>& attributes);

// The floor reference attributes of a camera stream (above) from the VO options, and back into `options` (error:
// "<attribute> missing").
std::map<std::string, double> FloorAttributes(const VisualOdometryOptions& options);
Status ReadFloorAttributes(const std::map<std::string, double>& attributes, VisualOdometryOptions* options);

}  // namespace roamlab::frontend
