#include "frontend/visual_odometry_stream.h"

#include <cmath>
#include <utility>

namespace roamlab::frontend {
namespace {

// Attribute `key`, or an error naming it.
Status ReadAttribute(const std::map<std::string, double>& attributes, const std::string& key, double* value) {
  const auto it = attributes.find(key);
  if (it == attributes.end()) return Status::Error("attribute " + key + " missing");
  *value = it->second;
  return Status::Ok();
}

}  // namespace

VisualOdometryStream::VisualOdometryStream(const PinholeIntrinsics& intrinsics, const VisualOdometryOptions& options,
                                           std::string stream_name, double rate_hz)
    : vo_(intrinsics, options), stream_name_(std::move(stream_name)), rate_hz_(rate_hz) {}

std::optional<VoEstimate> VisualOdometryStream::ProcessFrame(Time t, const cv::Mat& gray) {
  std::optional<VoEstimate> estimate = vo_.ProcessFrame(t, gray);
  if (estimate) {
    t_.push_back(estimate->t_mid);
    rows_.push_back(VisualOdometryRow(*estimate));
  }
  return estimate;
}

recording::Stream VisualOdometryStream::TakeStream() const {
  recording::Stream stream;
  stream.info.name = stream_name_;
  stream.info.type = recording::StreamType::kVisualOdometry;
  stream.info.rate_hz = rate_hz_;
  stream.info.columns = recording::FixedColumns(recording::StreamType::kVisualOdometry);
  const std::vector<std::string>& covariance = recording::CovarianceColumns(recording::StreamType::kVisualOdometry);
  stream.info.columns.insert(stream.info.columns.end(), covariance.begin(), covariance.end());
  stream.info.attributes = IntrinsicsAttributes(vo_.intrinsics());
  stream.t = t_;
  stream.values.resize(static_cast<Eigen::Index>(rows_.size()), 27);
  for (std::size_t i = 0; i < rows_.size(); ++i) stream.values.row(static_cast<Eigen::Index>(i)) = rows_[i];
  return stream;
}

Eigen::Matrix<double, 1, 27> VisualOdometryRow(const VoEstimate& estimate) {
  Eigen::Matrix<double, 1, 27> row;
  row.head<3>() = estimate.v_camera_mps.transpose();
  row.segment<3>(3) = estimate.omega_camera_radps.transpose();
  int k = 6;
  for (int i = 0; i < 6; ++i)
    for (int j = i; j < 6; ++j) row[k++] = estimate.covariance(i, j);
  return row;
}

std::map<std::string, double> IntrinsicsAttributes(const PinholeIntrinsics& k) {
  return {{"width_px", k.width_px}, {"height_px", k.height_px}, {"fx_px", k.fx_px},
          {"fy_px", k.fy_px},       {"cx_px", k.cx_px},         {"cy_px", k.cy_px}};
}

Result<PinholeIntrinsics> IntrinsicsOfAttributes(const std::map<std::string, double>& attributes) {
  PinholeIntrinsics k;
  double width = 0.0;
  double height = 0.0;
  const std::pair<const char*, double*> fields[] = {{"width_px", &width}, {"height_px", &height}, {"fx_px", &k.fx_px},
                                                    {"fy_px", &k.fy_px},  {"cx_px", &k.cx_px},    {"cy_px", &k.cy_px}};
  for (const auto& [key, value] : fields) {
    if (Status s = ReadAttribute(attributes, key, value); !s.ok()) return s;
  }
  k.width_px = static_cast<int>(width);
  k.height_px = static_cast<int>(height);
  return k;
}

std::map<std::string, double> FloorAttributes(const VisualOdometryOptions& options) {
  const Eigen::Vector3d& n = options.floor_normal_camera;
  return {{"camera_height_m", options.camera_height_m},
          {"floor_normal_x", n.x()},
          {"floor_normal_y", n.y()},
          {"floor_normal_z", n.z()}};
}

Status ReadFloorAttributes(const std::map<std::string, double>& attributes, VisualOdometryOptions* options) {
  Eigen::Vector3d& n = options->floor_normal_camera;
  const std::pair<const char*, double*> fields[] = {{"camera_height_m", &options->camera_height_m},
                                                    {"floor_normal_x", &n.x()},
                                                    {"floor_normal_y", &n.y()},
                                                    {"floor_normal_z", &n.z()}};
  for (const auto& [key, value] : fields) {
    if (Status s = ReadAttribute(attributes, key, value); !s.ok()) return s;
  }
  return Status::Ok();
}

}  // namespace roamlab::frontend
