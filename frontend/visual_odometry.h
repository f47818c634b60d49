// Monocular visual odometry front end (OpenCV): the camera's linear and angular velocity between two frames, with
// a covariance, for the seed's Section VI "linear and angular speed logical sensor" (estimator model `odometer`,
// seed eqs. 5-8, stream type visual_odometry).
//
// Per frame pair (previous frame 1, current frame 2, both in OpenCV's camera frame C: x right, y down, z forward):
//   1. Features (DetectFeatures): Shi-Tomasi corners (GFTT) in a grid of cells, so that floor and walls both get some;
//      the tracks that survived the previous pair are kept and topped up.
//   2. Tracking (TrackForwardBackward): pyramidal Lucas-Kanade from frame 1 to 2 and back; a track is kept when it
//      returns within `max_forward_backward_px` of where it started.
//   3. Rotation and translation direction (FitEssential, RefineOnSampson): essential matrix by 5-point RANSAC
//      (findEssentialMat), the cheirality check of recoverPose, then Gauss-Newton on the Sampson error of the inliers
//      over (R, t/|t|) (5 parameters). Convention: a point X1 in C1 is X2 = R_21 X1 + t_21 in C2; the camera moves by
//      R_12 = R_21^T, p_12 = -R_21^T t_21 (the pose of C2 in C1).
//   4. Metric scale from the floor (ScaleFromFloor): the camera's height h over the floor and the floor's unit normal n
//      (pointing from the camera down to the floor, in C) are known from the mounting (options). A floor point seen at
//      normalized ray x1 lies at X1 = x1 h / (n . x1), so with t_21 = s t_hat it must appear at
//      x2 = proj(R_21 X1 + s t_hat). Each point below the horizon (n . x1 > 0) gives a 1-point hypothesis of s; RANSAC
//      keeps the s with the most points within `floor_threshold_px` (walls and boxes are the outliers), Gauss-Newton on
//      their reprojection error refines it: the scale comes from the known camera height over the floor. Limits: the
//      floor must be planar and visible in the lower image (enough textured floor points); n and h are those of the
//      mounting on a level robot, so a robot that pitches or rolls (bumps, hard braking on a soft suspension) biases
//      the scale by about the relative height change; obstacles that cover the floor near the robot leave no scale (a
//      failure is counted, never a guess).
//   5. Velocities (Velocities), held constant over dt = t2 - t1 as the estimator's eq. 7 assumes:
//        omega_C = Log(R_12) / dt,   v_C = Exp(-omega_C dt / 2) p_12 / dt
//      (eq. 7 moves by q_mid v dt with q_mid = Exp(omega dt / 2): this v reproduces p_12 exactly). Both are in the
//      camera frame C1 at the start of the pair, stamped at the middle of the pair (the mean velocity over the pair
//      equals the velocity at its middle to second order).
//   6. Covariance (OutputCovariance), first order: the Sampson residuals give the pixel noise
//      sigma^2 = sum e^2 / (N - 5) and the pose covariance sigma^2 (J^T J)^-1; the floor residuals give the scale's own
//      variance; both are propagated through step 4 (the scale depends on R and t) and step 5 by central differences.
//      It describes the pixel noise only: not the floor's flatness nor the robot's pitch (tests compare it with the
//      errors).
// A pair with too few features, tracks, inliers or floor points gives no estimate, and the failure is counted by
// reason. Two frames with no measurable motion (median flow below `stationary_flow_px`) give a zero velocity whose
// covariance is that of a flow at the threshold (StationaryCovariance).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "common/time.h"
#include "frontend/pinhole.h"

namespace roamlab::frontend {

struct VisualOdometryOptions {
  // Mounting: camera height over the floor [m] and the floor's unit normal in C, pointing down to the floor, for the
  // robot standing level. Required (height > 0, |normal| = 1 within 1e-6).
  double camera_height_m = 0.0;
  Eigen::Vector3d floor_normal_camera = Eigen::Vector3d::Zero();

  // Features and tracking (pixel sizes for a 320x240 image; they scale with the image width over 320).
  int max_features = 300;
  int grid_columns = 4;
  int grid_rows = 4;
  double feature_quality = 0.01;  // GFTT quality level, relative to the strongest corner
  double min_feature_distance_px = 7.0;
  int klt_window_px = 15;
  int klt_pyramid_levels = 3;
  double max_forward_backward_px = 0.5;

  // Geometry.
  double ransac_threshold_px = 0.8;  // essential-matrix RANSAC, distance to the epipolar line
  double ransac_confidence = 0.999;
  double floor_threshold_px = 1.0;   // floor reprojection inlier threshold
  double stationary_flow_px = 0.05;  // median flow below this: no motion

  // Failure thresholds.
  int min_tracks = 30;
  int min_inliers = 20;
  int min_floor_inliers = 10;

  // "" when fine, else what is wrong.
  std::string Validate() const;
};

// Why a pair gave no estimate.
enum class VoFailure {
  kNone = 0,
  kTooFewFeatures,  // fewer than min_tracks corners in frame 1
  kTooFewTracks,    // fewer than min_tracks tracks survived the forward-backward check
  kTooFewInliers,   // essential-matrix RANSAC or cheirality left fewer than min_inliers
  kNoScale,         // fewer than min_floor_inliers floor points agree on a scale
};
const char* VoFailureName(VoFailure failure);

struct VoEstimate {
  Time t_begin;                                               // frame 1
  Time t_end;                                                 // frame 2
  Time t_mid;                                                 // stamp of the velocities
  Eigen::Matrix3d R_prev_curr = Eigen::Matrix3d::Identity();  // rotates C2 coordinates into C1
  Eigen::Vector3d p_prev_curr_m = Eigen::Vector3d::Zero();    // C2's centre in C1 [m]
  Eigen::Vector3d v_camera_mps = Eigen::Vector3d::Zero();     // step 5, in C1
  Eigen::Vector3d omega_camera_radps = Eigen::Vector3d::Zero();
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();  // of [v (m/s); omega (rad/s)]
  bool stationary = false;      // no measurable motion: zero velocities
  int tracks = 0;               // tracks after the forward-backward check
  int inliers = 0;              // essential-matrix inliers
  int floor_inliers = 0;        // floor points that fixed the scale
  double pixel_sigma_px = 0.0;  // noise level of the Sampson residuals
};

struct VoCounters {
  int frames = 0;  // frames given
  int pairs = 0;   // frame pairs (frames - 1)
  int estimates = 0;
  int failures = 0;  // pairs - estimates
  int too_few_features = 0;
  int too_few_tracks = 0;
  int too_few_inliers = 0;
  int no_scale = 0;
};

class VisualOdometry {
 public:
  // Options must be valid (programmer error otherwise: check Validate() on user input first).
  VisualOdometry(const PinholeIntrinsics& intrinsics, const VisualOdometryOptions& options);

  // Processes the next frame (CV_8UC1, intrinsics' size) taken at t (strictly after the previous one). Returns the
  // motion since the previous frame, or nullopt for the first frame and for a failed pair (last_failure() says why).
  std::optional<VoEstimate> ProcessFrame(Time t, const cv::Mat& gray);

  VoFailure last_failure() const { return last_failure_; }
  const VoCounters& counters() const { return counters_; }
  const PinholeIntrinsics& intrinsics() const { return intrinsics_; }
  const VisualOdometryOptions& options() const { return options_; }

 private:
  std::optional<VoEstimate> Estimate(Time t, const cv::Mat& gray);
  void DetectFeatures(const cv::Mat& gray, std::vector<cv::Point2f>* points) const;
  void Fail(VoFailure failure);

  PinholeIntrinsics intrinsics_;
  VisualOdometryOptions options_;
  double pixel_scale_ = 1.0;  // image width / 320
  cv::Mat previous_;
  std::optional<Time> t_previous_;
  std::vector<cv::Point2f> previous_points_;  // tracks kept for the next pair, in previous_
  VoFailure last_failure_ = VoFailure::kNone;
  VoCounters counters_;
};

}  // namespace roamlab::frontend
