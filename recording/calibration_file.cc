#include "recording/calibration_file.h"

#include <fstream>
#include <limits>

#include <nlohmann/json.hpp>

namespace roamlab::recording {
namespace {

using nlohmann::json;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// An array of numbers (null read as NaN when `nullable`) into `out`; false if it is not one.
bool ReadNumbers(const json& node, bool nullable, std::vector<double>* out) {
  if (!node.is_array()) return false;
  out->clear();
  for (const json& v : node) {
    if (v.is_number()) {
      out->push_back(v.get<double>());
    } else if (nullable && v.is_null()) {
      out->push_back(kNaN);
    } else {
      return false;
    }
  }
  return true;
}

Result<CalibratedParameter> ReadParameter(const json& node, const std::string& where) {
  CalibratedParameter p;
  if (!node.is_object() || !node.contains("estimate") || !ReadNumbers(node["estimate"], false, &p.estimate))
    return Status::Error(where + ": 'estimate' must be an array of numbers");
  if (node.contains("std") && !ReadNumbers(node["std"], true, &p.std))
    return Status::Error(where + ": 'std' must be an array of numbers or nulls");
  if (node.contains("manifold")) {
    if (!node["manifold"].is_string()) return Status::Error(where + ": 'manifold' must be a string");
    p.manifold = node["manifold"].get<std::string>();
  }
  if (node.contains("observability")) {
    if (!node["observability"].is_string()) return Status::Error(where + ": 'observability' must be a string");
    p.observability = node["observability"].get<std::string>();
  }
  return p;
}

Result<std::optional<CalibrationInformation>> ReadInformation(const json& root, const std::string& path) {
  if (!root.contains("information")) return std::optional<CalibrationInformation>();
  const json& info = root["information"];
  if (!info.is_object() || !info.contains("parameters") || !info["parameters"].is_array() || !info.contains("matrix") ||
      !info["matrix"].is_array())
    return std::optional<CalibrationInformation>();
  CalibrationInformation out;
  for (const json& name : info["parameters"]) {
    if (!name.is_string()) return Status::Error(path + ": information.parameters must be names");
    out.parameters.push_back(name.get<std::string>());
  }
  const json& m = info["matrix"];
  const int n = static_cast<int>(m.size());
  out.matrix.resize(n, n);
  std::vector<double> row;
  for (int r = 0; r < n; ++r) {
    if (!ReadNumbers(m[r], true, &row) || static_cast<int>(row.size()) != n)
      return Status::Error(path + ": information.matrix must be square, of numbers");
    for (int c = 0; c < n; ++c) out.matrix(r, c) = row[static_cast<std::size_t>(c)];
  }
  return std::optional<CalibrationInformation>(std::move(out));
}

}  // namespace

Result<CalibrationFile> ReadCalibrationFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) return Status::Error(path + ": cannot open file");
  json root;
  try {
    in >> root;
  } catch (const json::exception& e) {
    return Status::Error(path + ": not valid JSON: " + e.what());
  }
  if (!root.is_object() || !root.contains("parameters") || !root["parameters"].is_object())
    return Status::Error(path + ": missing object 'parameters'");
  CalibrationFile file;
  for (const auto& [name, node] : root["parameters"].items()) {
    Result<CalibratedParameter> p = ReadParameter(node, path + ": parameter '" + name + "'");
    if (!p.ok()) return p.status();
    file.parameters[name] = std::move(p).value();
  }
  Result<std::optional<CalibrationInformation>> information = ReadInformation(root, path);
  if (!information.ok()) return information.status();
  file.information = std::move(information).value();
  return file;
}

}  // namespace roamlab::recording
