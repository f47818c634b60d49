#include "sim/render.h"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <vector>

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <opencv2/imgproc.hpp>

#include "common/check.h"
#include "sim/mujoco_model.h"

namespace roamlab::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kMaxImageSide = 4096;
constexpr const char* kEglPackages = "(Debian: libegl1 libegl-mesa0 libgl1-mesa-dri)";

// The surfaceless display and a config with a pbuffer bit (without it Mesa finds none), opened once per process.
struct EglDisplay {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLConfig config = nullptr;
  std::string error;  // empty when usable
};

std::string EglError(const std::string& call) {
  char code[16];
  std::snprintf(code, sizeof code, "0x%04X", static_cast<unsigned>(eglGetError()));
  return "EGL: " + call + " failed (error " + code + ") " + kEglPackages;
}

EglDisplay OpenDisplay() {
  EglDisplay out;
  const auto get_platform_display =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (get_platform_display == nullptr) {
    out.error = std::string("EGL: eglGetPlatformDisplayEXT is not available ") + kEglPackages;
    return out;
  }
  EGLDisplay display = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  if (display == EGL_NO_DISPLAY) {
    out.error = EglError("eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA)");
    return out;
  }
  EGLint major = 0;
  EGLint minor = 0;
  if (eglInitialize(display, &major, &minor) != EGL_TRUE) {
    out.error = EglError("eglInitialize");
    return out;
  }
  const EGLint attributes[] = {EGL_SURFACE_TYPE,
                               EGL_PBUFFER_BIT,
                               EGL_RENDERABLE_TYPE,
                               EGL_OPENGL_BIT,
                               EGL_RED_SIZE,
                               8,
                               EGL_GREEN_SIZE,
                               8,
                               EGL_BLUE_SIZE,
                               8,
                               EGL_DEPTH_SIZE,
                               24,
                               EGL_NONE};
  EGLint count = 0;
  if (eglChooseConfig(display, attributes, &out.config, 1, &count) != EGL_TRUE || count < 1) {
    out.error = EglError("eglChooseConfig(EGL_PBUFFER_BIT, EGL_OPENGL_BIT)");
    return out;
  }
  out.display = display;
  return out;
}

const EglDisplay& SharedDisplay() {
  static const EglDisplay display = OpenDisplay();  // thread-safe initialization; never terminated
  return display;
}

// mjr_makeContext / mjr_freeContext load MuJoCo's OpenGL entry points into globals: one at a time.
std::mutex& MujocoContextMutex() {
  static std::mutex mutex;
  return mutex;
}

}  // namespace

PinholeIntrinsics IntrinsicsFromFovy(double fovy_deg, int width_px, int height_px) {
  ROAMLAB_CHECK(fovy_deg > 0.0 && fovy_deg < 180.0 && width_px > 0 && height_px > 0,
                "fovy " << fovy_deg << " size " << width_px << "x" << height_px);
  PinholeIntrinsics k;
  k.width_px = width_px;
  k.height_px = height_px;
  k.fy_px = 0.5 * height_px / std::tan(0.5 * fovy_deg * kPi / 180.0);
  k.fx_px = k.fy_px;
  k.cx_px = 0.5 * (width_px - 1);
  k.cy_px = 0.5 * (height_px - 1);
  return k;
}

Eigen::Matrix3d RotationGlFromCv() { return Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal(); }

CameraPose CameraPoseInWorld(const mjModel* model, const mjData* data, int camera_id) {
  ROAMLAB_CHECK(camera_id >= 0 && camera_id < model->ncam, "camera id " << camera_id);
  CameraPose pose;
  // cam_xmat is row-major with the camera's (OpenGL) axes as columns.
  Eigen::Matrix3d R_world_gl;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R_world_gl(r, c) = data->cam_xmat[9 * camera_id + 3 * r + c];
  pose.R_world_camera = R_world_gl * RotationGlFromCv();
  pose.p_world_camera_m = Eigen::Vector3d(data->cam_xpos + 3 * camera_id);
  return pose;
}

std::string RenderOptions::Validate() const {
  if (width_px <= 0 || height_px <= 0 || width_px > kMaxImageSide || height_px > kMaxImageSide) {
    return "image size " + std::to_string(width_px) + "x" + std::to_string(height_px) + " must be in [1, " +
           std::to_string(kMaxImageSide) + "] pixels";
  }
  return "";
}

class CameraRenderer::Impl {
 public:
  ~Impl() {
    if (context_ == EGL_NO_CONTEXT) return;
    const EGLDisplay display = SharedDisplay().display;
    eglBindAPI(EGL_OPENGL_API);
    if (eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context_) == EGL_TRUE) {
      std::lock_guard<std::mutex> lock(MujocoContextMutex());
      mjr_freeContext(&mjr_context_);
    }
    mjv_freeScene(&scene_);
    eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display, context_);
  }

  Status Init(const mjModel* model, int camera_id, const RenderOptions& options) {
    model_ = model;
    camera_id_ = camera_id;
    intrinsics_ = IntrinsicsFromFovy(model->cam_fovy[camera_id], options.width_px, options.height_px);
    viewport_ = {0, 0, options.width_px, options.height_px};
    pixels_.resize(3 * static_cast<std::size_t>(options.width_px) * options.height_px);
    // This renderer's EGL context, current while the MuJoCo context is made.
    const EglDisplay& egl = SharedDisplay();
    if (!egl.error.empty()) return Status::Error(egl.error);
    if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE) return Status::Error(EglError("eglBindAPI(EGL_OPENGL_API)"));
    context_ = eglCreateContext(egl.display, egl.config, EGL_NO_CONTEXT, nullptr);
    if (context_ == EGL_NO_CONTEXT) return Status::Error(EglError("eglCreateContext"));
    if (eglMakeCurrent(egl.display, EGL_NO_SURFACE, EGL_NO_SURFACE, context_) != EGL_TRUE) {
      return Status::Error(EglError("eglMakeCurrent (surfaceless)"));
    }
    // MuJoCo sizes its offscreen buffer and multisampling from the model's <visual>: a shallow copy carries this
    // renderer's size and no multisampling (mjr_makeContext only reads the model; the copy shares its arrays).
    mjModel sized = *model;
    sized.vis.global.offwidth = std::max(options.width_px, 1);
    sized.vis.global.offheight = std::max(options.height_px, 1);
    sized.vis.quality.offsamples = 0;
    mjv_defaultScene(&scene_);
    mjv_makeScene(model, &scene_, model->ngeom + 16);
    mjr_defaultContext(&mjr_context_);
    {
      std::lock_guard<std::mutex> lock(MujocoContextMutex());
      try {
        mjr_makeContext(&sized, &mjr_context_, mjFONTSCALE_50);
      } catch (const MujocoError& e) {
        eglMakeCurrent(egl.display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        return Status::Error(std::string("MuJoCo rendering context: ") + e.what());
      }
    }
    mjr_setBuffer(mjFB_OFFSCREEN, &mjr_context_);
    const bool offscreen = mjr_context_.currentBuffer == mjFB_OFFSCREEN;
    eglMakeCurrent(egl.display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (!offscreen) return Status::Error("MuJoCo rendering context: no offscreen framebuffer");
    // What is drawn: the fixed camera, no sites, no shadows, reflections or skybox.
    mjv_defaultOption(&option_);
    std::fill(std::begin(option_.sitegroup), std::end(option_.sitegroup), 0);
    scene_.flags[mjRND_SHADOW] = 0;
    scene_.flags[mjRND_REFLECTION] = 0;
    scene_.flags[mjRND_SKYBOX] = 0;
    mjv_defaultCamera(&camera_);
    camera_.type = mjCAMERA_FIXED;
    camera_.fixedcamid = camera_id;
    return Status::Ok();
  }

  // RGB rows top-down into `rgb`.
  void Render(mjData* data, cv::Mat* rgb) {
    const EGLDisplay display = SharedDisplay().display;
    ROAMLAB_CHECK(eglBindAPI(EGL_OPENGL_API) == EGL_TRUE, "eglBindAPI failed");
    ROAMLAB_CHECK(eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context_) == EGL_TRUE,
                  "eglMakeCurrent failed: is this renderer in use on another thread?");
    mjv_updateScene(model_, data, &option_, nullptr, &camera_, mjCAT_STATIC | mjCAT_DYNAMIC, &scene_);
    mjr_render(viewport_, &scene_, &mjr_context_);
    mjr_readPixels(pixels_.data(), nullptr, viewport_, &mjr_context_);
    eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    // OpenGL rows are bottom-up.
    const cv::Mat bottom_up(viewport_.height, viewport_.width, CV_8UC3, pixels_.data());
    cv::flip(bottom_up, *rgb, 0);
  }

  const mjModel* model_ = nullptr;
  int camera_id_ = -1;
  PinholeIntrinsics intrinsics_;
  mjrRect viewport_{0, 0, 0, 0};
  EGLContext context_ = EGL_NO_CONTEXT;
  mjvScene scene_{};
  mjvOption option_{};
  mjvCamera camera_{};
  mjrContext mjr_context_{};
  std::vector<unsigned char> pixels_;
  cv::Mat rgb_;  // scratch for RenderGray
};

Result<std::unique_ptr<CameraRenderer>> CameraRenderer::Create(const mjModel* model, const std::string& camera,
                                                               const RenderOptions& options) {
  InstallMujocoHandlers();
  if (const std::string problem = options.Validate(); !problem.empty()) {
    return Status::Error("camera '" + camera + "': " + problem);
  }
  const int camera_id = IdOf(model, mjOBJ_CAMERA, camera);
  if (camera_id < 0) return Status::Error("the model has no camera named '" + camera + "'");
  auto impl = std::make_unique<Impl>();
  if (Status s = impl->Init(model, camera_id, options); !s.ok()) return s;
  return std::unique_ptr<CameraRenderer>(new CameraRenderer(std::move(impl)));
}

CameraRenderer::CameraRenderer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
CameraRenderer::~CameraRenderer() = default;

void CameraRenderer::RenderRgb(mjData* data, cv::Mat* rgb) { impl_->Render(data, rgb); }

void CameraRenderer::RenderGray(mjData* data, cv::Mat* gray) {
  impl_->Render(data, &impl_->rgb_);
  cv::cvtColor(impl_->rgb_, *gray, cv::COLOR_RGB2GRAY);
}

const PinholeIntrinsics& CameraRenderer::intrinsics() const { return impl_->intrinsics_; }
int CameraRenderer::camera_id() const { return impl_->camera_id_; }

}  // namespace roamlab::sim
