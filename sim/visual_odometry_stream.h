// The rendered camera and its visual odometry as a recording stream: call Observe() from a simulation loop at every
// physics step; at the camera's rate it renders the MuJoCo camera (render.h), runs the front end
// (visual_odometry.h) on the grayscale image and appends a row to a `visual_odometry` stream:
//
//   t, vx, vy, vz [m/s], wx, wy, wz [rad/s], then the 21 covariance columns cov_vx_vx, cov_vx_vy, ..., cov_wz_wz
//   (upper triangle of the 6x6 covariance of [v; w], row by row, in (m/s)^2, m/s rad/s, (rad/s)^2)
//
// in OpenCV's camera frame C (x right, y down, z forward; the frame at the start of the pair), stamped at the middle
// of each frame pair (visual_odometry.h, step 5). A failed pair writes no row; counters() says how many and why.
// The stream entry carries the camera's intrinsics as attributes (width_px, height_px, fx_px, fy_px, cx_px, cy_px,
// recording.h) and the nominal mounting of C in the robot body (`mounting`); the VO's failure counts are not part of
// the recording (the caller reports them from counters()). Optionally every frame is also written as a PNG (RGB) into
// <image_directory>/<stream name>/<index, six digits>.png and listed in a `camera` stream named
// <stream name>_images whose frame column holds that path relative to image_directory (give the recording directory
// so that the paths resolve).
//
// Mounting and the floor. At Create() the robot is expected at rest on the level floor (the initial state): the
// camera's pose relative to `body` (default: the camera's own body) becomes the stream's nominal mounting, and the
// camera's height over the plane z = floor_height_m and the floor's normal in C become the VO's known scale reference,
// unless the VO options already set them. They are fixed values from then on, as a measured mounting would be: the
// VO never reads MuJoCo's camera pose while the robot moves.
//
// Integration in a simulation loop (one physics step per iteration, data advanced by mj_step):
//   auto vo = VisualOdometryStream::Create(model, data, options);     // once, robot at rest at its start pose
//   for (...) { mj_step(model, data); ...; vo->Observe(t, data); }    // t: simulation time of `data`
//   recording.streams.push_back(vo->TakeStream());                     // plus TakeCameraStream() when images are kept
#pragma once

#include <memory>
#include <optional>
#include <string>

#include <mujoco/mujoco.h>

#include "common/status.h"
#include "common/time.h"
#include "recording/recording.h"
#include "sim/render.h"
#include "sim/visual_odometry.h"

namespace roamlab::sim {

struct VisualOdometryStreamOptions {
  std::string camera = "camera";           // MuJoCo camera name
  std::string body;                        // mounting reference body; empty: the camera's body
  std::string stream_name = "visual_odometry";
  double rate_hz = 15.0;                   // frames per second; frame k is due at t0 + k / rate_hz
  RenderOptions render;                    // 320x240 by default
  VisualOdometryOptions vo;                // camera_height_m <= 0: measured at Create(); likewise a zero normal
  double floor_height_m = 0.0;             // the floor plane z = floor_height_m in the world
  std::string image_directory;             // empty: no images; else PNGs and a camera stream (above)

  // "" when fine, else what is wrong (the VO options are checked once the floor is known).
  std::string Validate() const;
};

class VisualOdometryStream {
 public:
  // `data` holds the initial state (positions current). Errors (one line): invalid options, unknown camera or body,
  // a camera not above the floor, rendering unavailable (render.h), an image directory that cannot be created.
  static Result<std::unique_ptr<VisualOdometryStream>> Create(const mjModel* model, const mjData* data,
                                                              const VisualOdometryStreamOptions& options);
  ~VisualOdometryStream();
  VisualOdometryStream(const VisualOdometryStream&) = delete;
  VisualOdometryStream& operator=(const VisualOdometryStream&) = delete;

  // At time t (of `data`, positions current), renders and processes a frame when one is due (the first call takes
  // the first frame). Returns the pair's estimate when a frame was processed and succeeded. Errors: a PNG that
  // cannot be written.
  Result<std::optional<VoEstimate>> Observe(Time t, mjData* data);

  // The visual_odometry stream so far (rows of successful pairs).
  recording::Stream TakeStream() const;
  // The camera stream of the stored images; nullopt when images are not kept.
  std::optional<recording::Stream> TakeCameraStream() const;

  const VoCounters& counters() const;
  const PinholeIntrinsics& intrinsics() const;
  const VisualOdometryOptions& vo_options() const;  // with the floor measured at Create()
  const recording::Mounting& mounting() const;
  int camera_id() const;

 private:
  class Impl;
  explicit VisualOdometryStream(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// The stream row of an estimate: [v (3), omega (3), the covariance's upper triangle row by row (21)].
Eigen::Matrix<double, 1, 27> VisualOdometryRow(const VoEstimate& estimate);

}  // namespace roamlab::sim
