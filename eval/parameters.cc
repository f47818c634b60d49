#include "eval/parameters.h"

#include <cmath>
#include <fstream>
#include <limits>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/json.h"
#include "recording/calibration_file.h"

namespace roamlab::eval {
namespace {

using nlohmann::json;

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;
const double kNaN = std::numeric_limits<double>::quiet_NaN();

// Ambient and tangent sizes of a kind (vectors: the given size).
int AmbientSize(ParameterKind kind, int vector_size) {
  switch (kind) {
    case ParameterKind::kQuaternion:
      return 4;
    case ParameterKind::kPose:
      return 7;
    case ParameterKind::kVector:
      break;
  }
  return vector_size;
}
int TangentSize(ParameterKind kind, int vector_size) {
  switch (kind) {
    case ParameterKind::kQuaternion:
      return 3;
    case ParameterKind::kPose:
      return 6;
    case ParameterKind::kVector:
      break;
  }
  return vector_size;
}

// Log of a unit quaternion: the full-angle rotation vector [rad], angle in [0, pi].
Eigen::Vector3d RotationVector(Eigen::Quaterniond q) {
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const Eigen::Vector3d v = q.vec();
  const double n = v.norm();
  if (n < 1e-12) return 2.0 * v / q.w();
  return v * (2.0 * std::atan2(n, q.w()) / n);
}

// Tangent error and the sign-aligned component difference of the quaternion stored at values[offset] (w first).
void CompareRotation(const std::vector<double>& truth, const std::vector<double>& estimate, int offset,
                     ParameterComparison* row) {
  Eigen::Vector4d t(truth[offset], truth[offset + 1], truth[offset + 2], truth[offset + 3]);
  Eigen::Vector4d e(estimate[offset], estimate[offset + 1], estimate[offset + 2], estimate[offset + 3]);
  t.normalize();
  e.normalize();
  const Eigen::Quaterniond q_true(t[0], t[1], t[2], t[3]);
  const Eigen::Quaterniond q_est(e[0], e[1], e[2], e[3]);
  const Eigen::Vector3d d = RotationVector(q_true.conjugate() * q_est);
  for (int i = 0; i < 3; ++i) row->error.push_back(d[i]);
  row->angle_error_deg = d.norm() * kRadToDeg;
  if (t.dot(e) < 0.0) e = -e;
  for (int i = 0; i < 4; ++i) row->component_error[offset + i] = e[i] - t[i];
}

bool AllFinite(const std::vector<double>& values) {
  for (double v : values)
    if (!std::isfinite(v)) return false;
  return true;
}

bool QuaternionNonZero(const std::vector<double>& values, int offset) {
  double sq = 0.0;
  for (int i = 0; i < 4; ++i) sq += values[offset + i] * values[offset + i];
  return sq > 1e-12;
}

const char* ManifoldName(const ParameterComparison& row) {
  switch (row.kind) {
    case ParameterKind::kQuaternion:
      return "S3";
    case ParameterKind::kPose:
      return "SE3";
    case ParameterKind::kVector:
      break;
  }
  return nullptr;
}

}  // namespace

std::optional<ParameterKind> ParameterKindFromManifold(const std::string& manifold) {
  if (manifold == "S3") return ParameterKind::kQuaternion;
  if (manifold == "SE3") return ParameterKind::kPose;
  if (manifold.size() >= 2 && manifold[0] == 'R' && manifold[1] != '0' &&
      manifold.find_first_not_of("0123456789", 1) == std::string::npos)
    return ParameterKind::kVector;
  return std::nullopt;
}

Result<ParameterComparison> CompareParameter(const std::string& name, const std::vector<double>& truth,
                                             const ParameterEstimate& estimate) {
  const std::string what = "parameter '" + name + "'";
  const int n = static_cast<int>(estimate.estimate.size());
  const int ambient = AmbientSize(estimate.kind, n);
  const int tangent = TangentSize(estimate.kind, n);
  // Sizes, finiteness and non-zero quaternions.
  if (n != ambient || n == 0)
    return Status::Error(what + ": estimate has " + std::to_string(n) + " values, expected " + std::to_string(ambient));
  if (static_cast<int>(truth.size()) != ambient)
    return Status::Error(what + ": truth has " + std::to_string(truth.size()) + " values, estimate " +
                         std::to_string(ambient));
  if (!estimate.std.empty() && static_cast<int>(estimate.std.size()) != tangent)
    return Status::Error(what + ": std has " + std::to_string(estimate.std.size()) + " values, expected " +
                         std::to_string(tangent));
  if (!AllFinite(truth)) return Status::Error(what + ": truth is not finite");
  if (!AllFinite(estimate.estimate)) return Status::Error(what + ": estimate is not finite");
  const int rotation_offset = estimate.kind == ParameterKind::kPose ? 3 : 0;
  if (estimate.kind != ParameterKind::kVector &&
      (!QuaternionNonZero(truth, rotation_offset) || !QuaternionNonZero(estimate.estimate, rotation_offset)))
    return Status::Error(what + ": zero quaternion");

  ParameterComparison row;
  row.name = name;
  row.kind = estimate.kind;
  row.truth = truth;
  row.estimate = estimate.estimate;
  row.std = estimate.std.empty() ? std::vector<double>(tangent, kNaN) : estimate.std;
  row.observability = estimate.observability;
  row.angle_error_deg = kNaN;
  // Error in the tangent space the std refers to.
  switch (estimate.kind) {
    case ParameterKind::kVector:
      for (int i = 0; i < n; ++i) row.error.push_back(estimate.estimate[i] - truth[i]);
      break;
    case ParameterKind::kQuaternion:
      row.component_error.assign(4, 0.0);
      CompareRotation(truth, estimate.estimate, 0, &row);
      break;
    case ParameterKind::kPose:
      row.component_error.assign(7, 0.0);
      for (int i = 0; i < 3; ++i) {
        row.error.push_back(estimate.estimate[i] - truth[i]);
        row.component_error[i] = row.error[i];
      }
      CompareRotation(truth, estimate.estimate, 3, &row);
      break;
  }
  // Error in units of the reported standard deviation.
  for (int i = 0; i < tangent; ++i) {
    const double s = row.std[i];
    row.error_over_std.push_back(std::isfinite(s) && s > 0.0 ? row.error[i] / s : kNaN);
  }
  return row;
}

Result<std::vector<ParameterComparison>> CompareParameters(const std::map<std::string, std::vector<double>>& truth,
                                                           const std::map<std::string, ParameterEstimate>& estimates,
                                                           std::vector<std::string>* without_truth) {
  std::vector<ParameterComparison> rows;
  for (const auto& [name, estimate] : estimates) {
    const auto found = truth.find(name);
    if (found == truth.end()) {
      if (without_truth) without_truth->push_back(name);
      continue;
    }
    Result<ParameterComparison> row = CompareParameter(name, found->second, estimate);
    if (!row.ok()) return row.status();
    rows.push_back(std::move(row).value());
  }
  return rows;
}

Result<std::map<std::string, ParameterEstimate>> ReadCalibrationEstimates(const std::string& path) {
  auto file = recording::ReadCalibrationFile(path);
  if (!file.ok()) return file.status();
  std::map<std::string, ParameterEstimate> out;
  for (const auto& [name, read] : file.value().parameters) {
    ParameterEstimate p;
    p.estimate = read.estimate;
    p.std = read.std;
    p.observability = read.observability;
    const std::string manifold = read.manifold.empty() ? "R" + std::to_string(p.estimate.size()) : read.manifold;
    const std::optional<ParameterKind> kind = ParameterKindFromManifold(manifold);
    if (!kind)
      return Status::Error(path + ": parameter '" + name + "': unknown manifold '" + manifold + "' (R<n>, S3 or SE3)");
    p.kind = *kind;
    out[name] = std::move(p);
  }
  return out;
}

json ParameterTableJson(const std::vector<ParameterComparison>& rows) {
  json table = json::object();
  for (const ParameterComparison& row : rows) {
    json entry = {{"truth", NumberArray(row.truth)},
                  {"estimate", NumberArray(row.estimate)},
                  {"std", NumberArray(row.std)},
                  {"error", NumberArray(row.error)},
                  {"error_over_std", NumberArray(row.error_over_std)}};
    if (const char* manifold = ManifoldName(row)) {
      entry["manifold"] = manifold;
      entry["angle_error_deg"] = Number(row.angle_error_deg);
      entry["component_error"] = NumberArray(row.component_error);
    } else {
      entry["manifold"] = "R" + std::to_string(row.estimate.size());
    }
    if (!row.observability.empty()) entry["observability"] = row.observability;
    table[row.name] = entry;
  }
  return table;
}

}  // namespace roamlab::eval
