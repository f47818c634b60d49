#include "sim/simulated_camera.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <system_error>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/atomic_file.h"
#include "sim/mujoco_model.h"

namespace roamlab::sim {
namespace {

namespace fs = std::filesystem;

// Orientation of a MuJoCo body in the world (xmat is row-major).
Eigen::Matrix3d BodyRotation(const mjData* data, int body_id) {
  Eigen::Matrix3d R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R(r, c) = data->xmat[9 * body_id + 3 * r + c];
  return R;
}

}  // namespace

std::string SimulatedCameraOptions::Validate() const {
  if (camera.empty()) return "camera name is empty";
  if (stream_name.empty()) return "stream name is empty";
  if (!(rate_hz > 0.0) || !std::isfinite(rate_hz) || rate_hz > 1000.0) return "rate_hz must be in (0, 1000]";
  if (!std::isfinite(floor_height_m)) return "floor_height_m must be finite";
  return render.Validate();
}

class SimulatedCamera::Impl {
 public:
  SimulatedCameraOptions options;
  std::unique_ptr<CameraRenderer> renderer;
  std::optional<frontend::VisualOdometryStream> vo;
  recording::Mounting mounting;
  std::optional<Time> t0;       // first call
  std::int64_t next_frame = 0;  // index of the next frame due
  int frame_index = 0;
  cv::Mat rgb;
  cv::Mat gray;
  cv::Mat bgr;
  std::vector<Time> image_t;
  std::vector<std::string> image_names;
};

Result<std::unique_ptr<SimulatedCamera>> SimulatedCamera::Create(const mjModel* model, const mjData* data,
                                                                 const SimulatedCameraOptions& options) {
  if (const std::string problem = options.Validate(); !problem.empty()) {
    return Status::Error("visual odometry stream '" + options.stream_name + "': " + problem);
  }
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  Result<std::unique_ptr<CameraRenderer>> renderer = CameraRenderer::Create(model, options.camera, options.render);
  if (!renderer.ok()) return renderer.status();
  impl->renderer = std::move(renderer).value();
  const int camera_id = impl->renderer->camera_id();

  // Mounting of C in the reference body, from the initial state.
  int body_id = model->cam_bodyid[camera_id];
  if (!options.body.empty()) {
    body_id = IdOf(model, mjOBJ_BODY, options.body);
    if (body_id < 0) return Status::Error("the model has no body named '" + options.body + "'");
  }
  const CameraPose camera = CameraPoseInWorld(model, data, camera_id);
  const Eigen::Matrix3d R_world_body = BodyRotation(data, body_id);
  const Eigen::Vector3d p_world_body(data->xpos + 3 * body_id);
  impl->mounting.p_body_sensor = R_world_body.transpose() * (camera.p_world_camera_m - p_world_body);
  impl->mounting.q_body_sensor = Eigen::Quaterniond(R_world_body.transpose() * camera.R_world_camera).normalized();

  // The floor's height and normal in C, unless given.
  frontend::VisualOdometryOptions vo = options.vo;
  if (!(vo.camera_height_m > 0.0)) vo.camera_height_m = camera.p_world_camera_m.z() - options.floor_height_m;
  if (vo.floor_normal_camera.isZero()) {
    vo.floor_normal_camera = camera.R_world_camera.transpose() * Eigen::Vector3d(0.0, 0.0, -1.0);
  }
  if (!(vo.camera_height_m > 0.0)) {
    return Status::Error("camera '" + options.camera +
                         "' is not above the floor z = " + std::to_string(options.floor_height_m) + " m");
  }
  if (const std::string problem = vo.Validate(); !problem.empty()) {
    return Status::Error("visual odometry stream '" + options.stream_name + "': " + problem);
  }
  impl->vo.emplace(impl->renderer->intrinsics(), vo, options.stream_name, options.rate_hz);

  // Image directory.
  if (!options.image_directory.empty()) {
    std::error_code error;
    const fs::path dir = fs::path(options.image_directory) / options.stream_name;
    fs::create_directories(dir, error);
    if (error) return Status::Error(dir.string() + ": cannot create directory: " + error.message());
  }
  return std::unique_ptr<SimulatedCamera>(new SimulatedCamera(std::move(impl)));
}

SimulatedCamera::SimulatedCamera(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
SimulatedCamera::~SimulatedCamera() = default;

Result<std::optional<frontend::VoEstimate>> SimulatedCamera::Observe(Time t, mjData* data) {
  Impl& s = *impl_;
  // Frame k is due at t0 + k / rate (rounded to the nanosecond, without accumulating); a late call does not shift
  // the schedule, a frame whose time has passed entirely is skipped.
  if (!s.t0) s.t0 = t;
  const auto due = [&s](std::int64_t k) {
    return Time::FromNanoseconds(s.t0->nanoseconds() + std::llround(1e9 * static_cast<double>(k) / s.options.rate_hz));
  };
  if (t < due(s.next_frame)) return std::optional<frontend::VoEstimate>();
  while (due(s.next_frame + 1) <= t) ++s.next_frame;
  ++s.next_frame;
  // Render, keep the image when asked, run the VO.
  s.renderer->RenderRgb(data, &s.rgb);
  if (!s.options.image_directory.empty()) {
    char name[32];
    std::snprintf(name, sizeof name, "%06d.png", s.frame_index);
    const std::string relative = s.options.stream_name + "/" + name;
    const std::string path = (fs::path(s.options.image_directory) / relative).string();
    cv::cvtColor(s.rgb, s.bgr, cv::COLOR_RGB2BGR);
    std::vector<unsigned char> png;
    bool encoded = false;
    try {
      encoded = cv::imencode(".png", s.bgr, png);
    } catch (const cv::Exception&) {
      encoded = false;
    }
    if (!encoded) return Status::Error(path + ": cannot encode the camera image");
    const std::string_view bytes(reinterpret_cast<const char*>(png.data()), png.size());
    if (Status written = WriteFileAtomic(path, bytes); !written.ok()) return written;
    s.image_t.push_back(t);
    s.image_names.push_back(relative);
  }
  ++s.frame_index;
  cv::cvtColor(s.rgb, s.gray, cv::COLOR_RGB2GRAY);
  return s.vo->ProcessFrame(t, s.gray);
}

recording::Stream SimulatedCamera::TakeStream() const {
  recording::Stream stream = impl_->vo->TakeStream();
  stream.info.mounting = impl_->mounting;
  return stream;
}

std::optional<recording::Stream> SimulatedCamera::TakeCameraStream() const {
  const Impl& s = *impl_;
  if (s.options.image_directory.empty()) return std::nullopt;
  recording::Stream stream;
  stream.info.name = s.options.stream_name + "_images";
  stream.info.type = recording::StreamType::kCamera;
  stream.info.rate_hz = s.options.rate_hz;
  stream.info.units = "png";
  stream.info.mounting = s.mounting;
  stream.info.attributes = frontend::IntrinsicsAttributes(s.renderer->intrinsics());
  stream.info.attributes.merge(frontend::FloorAttributes(s.vo->options()));
  stream.t = s.image_t;
  stream.text = s.image_names;
  return stream;
}

const frontend::VoCounters& SimulatedCamera::counters() const { return impl_->vo->counters(); }
const PinholeIntrinsics& SimulatedCamera::intrinsics() const { return impl_->renderer->intrinsics(); }
const frontend::VisualOdometryOptions& SimulatedCamera::vo_options() const { return impl_->vo->options(); }
const recording::Mounting& SimulatedCamera::mounting() const { return impl_->mounting; }
int SimulatedCamera::camera_id() const { return impl_->renderer->camera_id(); }

}  // namespace roamlab::sim
