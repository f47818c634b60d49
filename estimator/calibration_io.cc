#include "estimator/calibration_io.h"

#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/json.h"
#include "estimator/covariance.h"
#include "estimator/internal/json_io.h"
#include "estimator/solver.h"

namespace roamlab::estimator {
namespace {

using nlohmann::json;

json ParametersJson(const std::vector<ParameterEstimate>& parameters) {
  json params = json::object();
  for (const auto& p : parameters) {
    json components = json::array();
    for (auto o : p.components) components.push_back(ObservabilityName(o));
    params[p.name] = {{"estimate", NumberArray(p.estimate)},
                      {"std", NumberArray(p.std)},
                      {"observability", ObservabilityName(p.observability)},
                      {"component_observability", components},
                      {"manifold", p.manifold.Name()}};
  }
  return params;
}

// {"parameters": [NAME, ...], "matrix": [[...], ...]}: the rows of `information`, in the order of `names`.
json InformationJson(const std::vector<std::string>& names, const Eigen::MatrixXd& information) {
  json matrix = json::array();
  for (int row = 0; row < information.rows(); ++row)
    matrix.push_back(NumberArray(Eigen::VectorXd(information.row(row).transpose())));
  return {{"parameters", names}, {"matrix", matrix}};
}

json SolverJson(const CalibrationResult& r) {
  json stages = json::array();
  for (const auto& s : r.stages)
    stages.push_back({{"free", s.free_parameters},
                      {"iterations", s.solver.iterations},
                      {"initial_cost", s.solver.initial_cost},
                      {"final_cost", s.solver.final_cost},
                      {"termination", TerminationName(s.solver.termination)},
                      {"cost_history", s.solver.cost_history},
                      {"rejected", s.rejected},
                      {"seconds", s.solver.seconds}});
  return {{"iterations", r.iterations},   {"initial_cost", r.initial_cost}, {"final_cost", r.final_cost},
          {"termination", r.termination}, {"seconds", r.seconds},           {"stages", stages}};
}

}  // namespace

Status WriteCalibrationFile(const CalibrationResult& result, const std::string& recording, const std::string& config,
                            const std::string& path) {
  std::vector<std::string> names;
  for (const auto& p : result.parameters) names.push_back(p.name);
  json correlations = json::array();
  for (const auto& c : result.correlations) correlations.push_back({{"a", c.a}, {"b", c.b}, {"rho", c.rho}});
  const json out = {{"parameters", ParametersJson(result.parameters)},
                    {"information", InformationJson(names, result.information)},
                    {"correlations", correlations},
                    {"solver", SolverJson(result)},
                    {"measurements", internal::CountsJson(result.counts)},
                    {"recording", recording},
                    {"config", config}};
  return internal::WriteJson(out, path);
}

Status WriteCalibrationValues(const std::map<std::string, Eigen::VectorXd>& values, const CalibrationPrior& prior,
                              const std::string& path) {
  json j;
  for (const auto& [name, v] : values) j["parameters"][name]["estimate"] = NumberArray(v);
  j["information"] = InformationJson(prior.names, prior.information);
  return internal::WriteJson(j, path);
}

Result<std::map<std::string, Eigen::VectorXd>> ReadCalibrationValues(const std::string& path) {
  auto file = internal::ReadJsonFile(path);
  if (!file.ok()) return file.status();
  json j = std::move(file).value();
  if (!j.contains("parameters") || !j["parameters"].is_object())
    return Status::Error(path + ": missing object 'parameters'");
  std::map<std::string, Eigen::VectorXd> out;
  for (const auto& [name, p] : j["parameters"].items()) {
    if (!p.contains("estimate") || !p["estimate"].is_array())
      return Status::Error(path + ": parameter '" + name + "' has no 'estimate' array");
    Eigen::VectorXd v(static_cast<int>(p["estimate"].size()));
    for (std::size_t i = 0; i < p["estimate"].size(); ++i) {
      if (!p["estimate"][i].is_number())
        return Status::Error(path + ": parameter '" + name + "' estimate has a non-number");
      v[static_cast<int>(i)] = p["estimate"][i].get<double>();
    }
    out[name] = v;
  }
  return out;
}

Result<CalibrationPrior> ReadCalibrationPrior(const std::string& path) {
  auto file = internal::ReadJsonFile(path);
  if (!file.ok()) return file.status();
  json j = std::move(file).value();
  const json& info = j["information"];
  if (!info.is_object() || !info["parameters"].is_array() || !info["matrix"].is_array())
    return Status::Error(path + ": no 'information' with 'parameters' and 'matrix' (calibrate it again)");
  CalibrationPrior prior;
  for (const auto& name : info["parameters"]) {
    if (!name.is_string()) return Status::Error(path + ": information.parameters must be names");
    prior.names.push_back(name.get<std::string>());
  }
  const json& m = info["matrix"];
  const int n = static_cast<int>(m.size());
  prior.information.resize(n, n);
  for (int r = 0; r < n; ++r) {
    if (!m[r].is_array() || static_cast<int>(m[r].size()) != n)
      return Status::Error(path + ": information.matrix must be square");
    for (int c = 0; c < n; ++c) {
      if (!m[r][c].is_number()) return Status::Error(path + ": information.matrix has a non-number");
      prior.information(r, c) = m[r][c].get<double>();
    }
  }
  return prior;
}

Result<TrackingOptions> TrackingOptionsFor(const EstimatorConfig& config, const std::string& calibration_path) {
  TrackingOptions options;
  if (!config.tracking.calibration_prior) return options;
  if (calibration_path.empty())
    return Status::Error(config.source_file +
                         ": tracking.calibration_prior needs --calibration calibration.json (montecarlo: or "
                         "tracking.calibrate)");
  auto prior = ReadCalibrationPrior(calibration_path);
  if (!prior.ok()) return prior.status();
  options.calibration_prior = std::move(prior).value();
  return options;
}

}  // namespace roamlab::estimator
