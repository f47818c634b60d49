// Offscreen rendering of a MuJoCo camera without a display: EGL on Mesa's surfaceless platform, MuJoCo's own
// renderer (mjr_*) into its offscreen framebuffer, read back into OpenCV images.
//
// Camera conventions. MuJoCo's camera frame is OpenGL's: x right, y up, looking down -z. Everything this header
// returns uses OpenCV's camera frame C instead: x right, y down, z forward (the optical axis); the rotation between
// them is diag(1, -1, -1). Images are rows top-down (mjr_readPixels returns them bottom-up; they are flipped here).
// The pinhole model has no distortion, square pixels and the principal point at the image centre:
//   fy = fx = (H / 2) / tan(fovy / 2),   cx = (W - 1) / 2,   cy = (H - 1) / 2          [px]
// with fovy the camera's vertical field of view (mjModel::cam_fovy) and the horizontal one following from the aspect
// ratio W / H, which is how MuJoCo sets up the frustum of a fixed camera. Pixel coordinates are OpenCV's: the centre
// of pixel (u, v) = (column, row) is at (u, v), so the image centre, W / 2 in OpenGL's pixel-edge coordinates, is at
// (W - 1) / 2. A point p_C = (x, y, z), z > 0, projects to u = fx x / z + cx, v = fy y / z + cy.
//
// Threads. Each CameraRenderer owns one EGL context and one MuJoCo rendering context. Render() makes the context
// current on the calling thread and releases it before returning, so a renderer may be used from any thread but by one
// thread at a time; different renderers render concurrently (Monte-Carlo runs one simulation, hence one renderer, per
// thread). The EGL display is opened once per process and never closed (eglTerminate would invalidate every other
// renderer's context); creating and destroying the MuJoCo contexts is serialized by a process-wide mutex because
// MuJoCo loads its OpenGL entry points into globals there. Never load OSMesa into the same process.
//
// Speed: multisampling, shadows, reflections and the skybox are off (several times faster than MuJoCo's
// defaults); sites and decorations are not drawn.
#pragma once

#include <memory>
#include <string>

#include <mujoco/mujoco.h>
#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "common/status.h"
#include "frontend/pinhole.h"

namespace roamlab::sim {

// Pinhole intrinsics in OpenCV's conventions (above), shared with the visual odometry front end.
using frontend::PinholeIntrinsics;

// The intrinsics of a camera with vertical field of view `fovy_deg` rendered at width x height pixels.
PinholeIntrinsics IntrinsicsFromFovy(double fovy_deg, int width_px, int height_px);

// Pose of camera `camera_id` in the world at the state of `data` (mj_forward or mj_kinematics done): R_world_camera
// rotates C coordinates (OpenCV: x right, y down, z forward) into world coordinates; p_world_camera_m is its centre.
struct CameraPose {
  Eigen::Matrix3d R_world_camera = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_world_camera_m = Eigen::Vector3d::Zero();
};
CameraPose CameraPoseInWorld(const mjModel* model, const mjData* data, int camera_id);

// Rotation from MuJoCo's (OpenGL) camera frame to OpenCV's: R_gl_cv = diag(1, -1, -1).
Eigen::Matrix3d RotationGlFromCv();

struct RenderOptions {
  int width_px = 320;
  int height_px = 240;

  // "" when fine, else what is wrong (sizes must be positive, at most 4096).
  std::string Validate() const;
};

class CameraRenderer {
 public:
  // Opens the EGL display (once per process), creates this renderer's contexts and uploads the model's meshes and
  // textures. `model` must outlive the renderer and keep its visual assets. Errors (one line): no camera named
  // `camera` in the model, invalid options, EGL unavailable ("EGL: ..." naming the failing call and the packages that
  // provide it).
  static Result<std::unique_ptr<CameraRenderer>> Create(const mjModel* model, const std::string& camera,
                                                        const RenderOptions& options = {});
  ~CameraRenderer();
  CameraRenderer(const CameraRenderer&) = delete;
  CameraRenderer& operator=(const CameraRenderer&) = delete;

  // Renders the camera at the state of `data` (positions current: mj_forward, mj_kinematics or after mj_step) into
  // `rgb` (CV_8UC3, RGB order, height x width, rows top-down) or `gray` (CV_8UC1). `data` is not modified (MuJoCo's
  // mjv_updateScene takes it non-const).
  void RenderRgb(mjData* data, cv::Mat* rgb);
  void RenderGray(mjData* data, cv::Mat* gray);

  const PinholeIntrinsics& intrinsics() const;
  int camera_id() const;

 private:
  class Impl;
  explicit CameraRenderer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace roamlab::sim
