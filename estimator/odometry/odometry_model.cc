#include "estimator/odometry/odometry_model.h"

#include <fstream>

#include <nlohmann/json.hpp>

#include "common/atomic_file.h"

namespace roamlab::estimator::odometry {
namespace {

using nlohmann::json;

json MatrixRows(const Eigen::MatrixXd& M) {
  json rows = json::array();
  for (Eigen::Index i = 0; i < M.rows(); ++i) {
    json row = json::array();
    for (Eigen::Index j = 0; j < M.cols(); ++j) row.push_back(M(i, j));
    rows.push_back(row);
  }
  return rows;
}

json VectorJson(const Eigen::VectorXd& v) {
  json a = json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(v[i]);
  return a;
}

// Parsing helpers that throw std::runtime_error with the key; LoadOdometryModel turns them into a Status.
const json& Key(const json& j, const std::string& key) {
  if (!j.is_object() || !j.contains(key)) throw std::runtime_error("missing key '" + key + "'");
  return j.at(key);
}

Eigen::VectorXd ReadVector(const json& j, const std::string& what) {
  if (!j.is_array()) throw std::runtime_error(what + " is not an array");
  Eigen::VectorXd v(static_cast<Eigen::Index>(j.size()));
  for (std::size_t i = 0; i < j.size(); ++i) {
    if (!j[i].is_number()) throw std::runtime_error(what + " holds a non-number");
    v[static_cast<Eigen::Index>(i)] = j[i].get<double>();
  }
  return v;
}

Eigen::MatrixXd ReadRows(const json& j, const std::string& what, Eigen::Index cols) {
  if (!j.is_array()) throw std::runtime_error(what + " is not an array of rows");
  Eigen::MatrixXd M(static_cast<Eigen::Index>(j.size()), cols);
  for (std::size_t i = 0; i < j.size(); ++i) {
    const Eigen::VectorXd row = ReadVector(j[i], what);
    if (row.size() != cols) throw std::runtime_error(what + ": a row has the wrong length");
    M.row(static_cast<Eigen::Index>(i)) = row.transpose();
  }
  return M;
}

}  // namespace

const char* ModelKindName(ModelKind kind) {
  switch (kind) {
    case ModelKind::kGp:
      return "gp";
    case ModelKind::kLinear:
      return "linear";
    case ModelKind::kParametric:
      return "parametric";
    case ModelKind::kNominal:
      return "nominal";
  }
  return "?";
}

Pose2 OdometryModel::Predict(const Eigen::VectorXd& delta) const {
  switch (kind) {
    case ModelKind::kGp:
      return gp->PredictMean(delta);
    case ModelKind::kLinear:
      return W * delta;
    case ModelKind::kParametric:
    case ModelKind::kNominal:
      return kinematics.Displacement(delta);
  }
  return Pose2::Zero();
}

std::string OdometryModel::MeanLabel() const { return gp ? GpMeanName(gp->mean()) : "-"; }
std::string OdometryModel::KernelLabel() const { return gp ? GpKernelName(gp->kernel()) : "-"; }

Status SaveOdometryModel(const OdometryModel& model, const std::string& path) {
  json j;
  j["format"] = "roamlab-odometry-model";
  j["version"] = 1;
  j["model"] = ModelKindName(model.kind);
  j["platform"] = model.platform;
  j["wheels"] = model.wheels;
  j["interval_s"] = model.interval_s;
  j["training"] = {{"recordings", model.training_recordings}, {"pairs", model.training_pairs}};
  if (model.kind == ModelKind::kGp) {
    const GaussianProcess& gp = *model.gp;
    json parameters = json::array();
    json weights = json::array();
    for (int i = 0; i < 3; ++i) {
      parameters.push_back(VectorJson(gp.parameters()[i]));
      weights.push_back(VectorJson(gp.weights()[i]));
    }
    j["gp"] = {{"mean", GpMeanName(gp.mean())},
               {"kernel", GpKernelName(gp.kernel())},
               {"inputs", MatrixRows(gp.inputs())},
               {"parameters", parameters},
               {"weights", weights},
               {"log_likelihood", gp.log_likelihoods()}};
  } else if (model.kind == ModelKind::kLinear) {
    j["linear"] = {{"W", MatrixRows(model.W)}, {"scale", VectorJson(model.huber_scale)}};
  } else {
    const WheelKinematics& k = model.kinematics;
    j["kinematics"] = {
        {"J", MatrixRows(k.J)}, {"radius_m", VectorJson(k.radius_m)}, {"sensor_pose", VectorJson(k.sensor_pose)}};
  }
  return WriteFileAtomic(path, j.dump(1) + "\n");
}

Result<OdometryModel> LoadOdometryModel(const std::string& path) {
  std::ifstream in(path);
  if (!in) return Status::Error(path + ": cannot open");
  json j;
  try {
    in >> j;
  } catch (const json::exception&) {
    return Status::Error(path + ": not valid JSON");
  }
  OdometryModel model;
  try {
    if (!Key(j, "format").is_string() || Key(j, "format").get<std::string>() != "roamlab-odometry-model" ||
        Key(j, "version") != 1) {
      throw std::runtime_error("not a roamlab odometry model (format roamlab-odometry-model, version 1)");
    }
    const std::string kind = Key(j, "model").get<std::string>();
    model.platform = Key(j, "platform").get<std::string>();
    model.wheels = Key(j, "wheels").get<std::vector<std::string>>();
    model.interval_s = Key(j, "interval_s").get<double>();
    if (!(model.interval_s > 0.0)) throw std::runtime_error("interval_s must be positive");
    model.training_recordings = Key(Key(j, "training"), "recordings").get<std::vector<std::string>>();
    model.training_pairs = Key(Key(j, "training"), "pairs").get<int>();
    const auto m = static_cast<Eigen::Index>(model.wheels.size());
    if (m < 1) throw std::runtime_error("no wheels");
    if (kind == "gp") {
      model.kind = ModelKind::kGp;
      const json& g = Key(j, "gp");
      GpMean mean;
      GpKernel kernel;
      if (!ParseGpMean(Key(g, "mean").get<std::string>(), &mean)) throw std::runtime_error("unknown gp.mean");
      if (!ParseGpKernel(Key(g, "kernel").get<std::string>(), &kernel)) throw std::runtime_error("unknown gp.kernel");
      const Eigen::MatrixXd X = ReadRows(Key(g, "inputs"), "gp.inputs", m);
      std::vector<Eigen::VectorXd> parameters;
      std::vector<Eigen::VectorXd> weights;
      for (std::size_t i = 0; i < Key(g, "parameters").size(); ++i) {
        parameters.push_back(ReadVector(Key(g, "parameters")[i], "gp.parameters"));
      }
      for (std::size_t i = 0; i < Key(g, "weights").size(); ++i) {
        weights.push_back(ReadVector(Key(g, "weights")[i], "gp.weights"));
      }
      Result<GaussianProcess> gp = GaussianProcess::FromParts(mean, kernel, X, parameters, weights);
      if (!gp.ok()) throw std::runtime_error(gp.status().message());
      model.gp = std::move(gp).value();
    } else if (kind == "linear") {
      model.kind = ModelKind::kLinear;
      model.W = ReadRows(Key(Key(j, "linear"), "W"), "linear.W", m);
      if (model.W.rows() != 3) throw std::runtime_error("linear.W must have three rows");
    } else if (kind == "parametric" || kind == "nominal") {
      model.kind = kind == "parametric" ? ModelKind::kParametric : ModelKind::kNominal;
      const json& k = Key(j, "kinematics");
      model.kinematics.kind = model.platform;
      model.kinematics.wheels = model.wheels;
      model.kinematics.J = ReadRows(Key(k, "J"), "kinematics.J", 3);
      model.kinematics.radius_m = ReadVector(Key(k, "radius_m"), "kinematics.radius_m");
      const Eigen::VectorXd sensor = ReadVector(Key(k, "sensor_pose"), "kinematics.sensor_pose");
      if (model.kinematics.J.rows() != m || model.kinematics.radius_m.size() != m || sensor.size() != 3) {
        throw std::runtime_error("kinematics sizes do not match the wheels");
      }
      model.kinematics.sensor_pose = sensor;
    } else {
      throw std::runtime_error("unknown model '" + kind + "' (gp, linear, parametric, nominal)");
    }
  } catch (const std::exception& e) {
    return Status::Error(path + ": " + e.what());
  }
  return model;
}

}  // namespace roamlab::estimator::odometry
