// The robot's rendered camera feeding the visual odometry front end: call Observe() from a simulation loop at every
// physics step; at the camera's rate it renders the MuJoCo camera (render.h) and runs the front end's
// visual_odometry stream (frontend/visual_odometry_stream.h) on the grayscale image. The VO's failure counts are not
// part of the recording (the caller reports them from counters()). Optionally every frame is also written as a PNG
// (RGB) into <image_directory>/<stream name>/<index, six digits>.png and listed in a `camera` stream named
// <stream name>_images whose frame column holds that path relative to image_directory (give the recording directory
// so that the paths resolve); its attributes carry the intrinsics and the floor reference (camera_height_m,
// floor_normal_x/y/z, frontend/visual_odometry_stream.h), so that `roamlab frontend vo` reproduces the stream from
// the images alone.
//
// Mounting and the floor. At Create() the robot is expected at rest on the level floor (the initial state): the
// camera's pose relative to `body` (default: the camera's own body) becomes the streams' nominal mounting, and the
// camera's height over the plane z = floor_height_m and the floor's normal in C become the VO's known scale reference,
// unless the VO options already set them. They are fixed values from then on, as a measured mounting would be: the
// VO never reads MuJoCo's camera pose while the robot moves.
//
// Integration in a simulation loop (one physics step per iteration, data advanced by mj_step):
//   auto camera = SimulatedCamera::Create(model, data, options);       // once, robot at rest at its start pose
//   for (...) { mj_step(model, data); ...; camera->Observe(t, data); }  // t: simulation time of `data`
//   recording.streams.push_back(camera->TakeStream());                   // and TakeCameraStream() when images are kept
#pragma once

#include <memory>
#include <optional>
#include <string>

#include <mujoco/mujoco.h>

#include "common/status.h"
#include "common/time.h"
#include "frontend/visual_odometry.h"
#include "frontend/visual_odometry_stream.h"
#include "recording/recording.h"
#include "sim/render.h"

namespace roamlab::sim {

struct SimulatedCameraOptions {
  std::string camera = "camera";  // MuJoCo camera name
  std::string body;               // mounting reference body; empty: the camera's body
  std::string stream_name = "visual_odometry";
  double rate_hz = 15.0;               // frames per second; frame k is due at t0 + k / rate_hz
  RenderOptions render;                // 320x240 by default
  frontend::VisualOdometryOptions vo;  // camera_height_m <= 0: measured at Create(); likewise a zero normal
  double floor_height_m = 0.0;         // the floor plane z = floor_height_m in the world
  std::string image_directory;         // empty: no images; else PNGs and a camera stream (above)

  // "" when fine, else what is wrong (the VO options are checked once the floor is known).
  std::string Validate() const;
};

class SimulatedCamera {
 public:
  // `data` holds the initial state (positions current). Errors (one line): invalid options, unknown camera or body,
  // a camera not above the floor, rendering unavailable (render.h), an image directory that cannot be created.
  static Result<std::unique_ptr<SimulatedCamera>> Create(const mjModel* model, const mjData* data,
                                                         const SimulatedCameraOptions& options);
  ~SimulatedCamera();
  SimulatedCamera(const SimulatedCamera&) = delete;
  SimulatedCamera& operator=(const SimulatedCamera&) = delete;

  // At time t (of `data`, positions current), renders and processes a frame when one is due (the first call takes
  // the first frame). Returns the pair's estimate when a frame was processed and succeeded. Errors: a PNG that
  // cannot be written.
  Result<std::optional<frontend::VoEstimate>> Observe(Time t, mjData* data);

  // The visual_odometry stream so far (rows of successful pairs), with the mounting.
  recording::Stream TakeStream() const;
  // The camera stream of the stored images; nullopt when images are not kept.
  std::optional<recording::Stream> TakeCameraStream() const;

  const frontend::VoCounters& counters() const;
  const PinholeIntrinsics& intrinsics() const;
  const frontend::VisualOdometryOptions& vo_options() const;  // with the floor measured at Create()
  const recording::Mounting& mounting() const;
  int camera_id() const;

 private:
  class Impl;
  explicit SimulatedCamera(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace roamlab::sim
