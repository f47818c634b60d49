// A learned or parametric odometry model as `roamlab odometry learn` writes it and `evaluate` reads it: one JSON file
//
//   {"format": "roamlab-odometry-model", "version": 1, "model": "gp|linear|parametric|nominal",
//    "platform": KIND, "wheels": [...], "interval_s": T, "training": {"recordings": [...], "pairs": n},
//    "gp": {"mean", "kernel", "inputs": [[...] per pair], "parameters": [[...] x 3], "weights": [[...] x 3],
//           "log_likelihood": [...]},                                   (model gp; layout of gaussian_process.h)
//    "linear": {"W": [[...] x 3], "scale": [...]},                        (model linear, eq. 9)
//    "kinematics": {"J": [[...] per wheel], "radius_m": [...], "sensor_pose": [x, y, theta],
//                   "track_m", "radius_left_m", "radius_right_m"}}      (parametric / nominal)
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "estimator/odometry/gaussian_process.h"
#include "estimator/odometry/parametric.h"
#include "estimator/odometry/se2.h"

namespace roamlab::estimator::odometry {

enum class ModelKind { kGp, kLinear, kParametric, kNominal };
const char* ModelKindName(ModelKind kind);

struct OdometryModel {
  ModelKind kind = ModelKind::kNominal;
  std::string platform;
  std::vector<std::string> wheels;
  double interval_s = 0.5;
  std::vector<std::string> training_recordings;
  int training_pairs = 0;
  std::optional<GaussianProcess> gp;  // kGp
  Eigen::MatrixXd W;                  // kLinear: 3 x m
  Eigen::Vector3d huber_scale = Eigen::Vector3d::Ones();
  WheelKinematics kinematics;  // kParametric, kNominal

  // Predicted sensor displacement over one key interval.
  Pose2 Predict(const Eigen::VectorXd& delta) const;
  // "zero"/"linear" and "rbf"/... for a GP, "-" otherwise (the columns of the seed's Tables III-IV).
  std::string MeanLabel() const;
  std::string KernelLabel() const;
};

Status SaveOdometryModel(const OdometryModel& model, const std::string& path);
// Errors "<path>: <problem>" for unreadable files, malformed JSON, missing or mistyped keys, inconsistent sizes.
Result<OdometryModel> LoadOdometryModel(const std::string& path);

}  // namespace roamlab::estimator::odometry
