#include "estimator/calibration_io.h"

#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/json.h"
#include "estimator/covariance.h"
#include "estimator/internal/json_io.h"
#include "estimator/solver.h"
#include "recording/calibration_file.h"

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
                      {"std_white", NumberArray(p.std_white)},
                      {"std_hac", NumberArray(p.std_hac)},
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
                      {"readmitted", s.readmitted},
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
                    {"std_method", result.std_method},
                    {"hac_lags", result.hac_lags},
                    {"information", InformationJson(names, result.information)},
                    {"correlations", correlations},
                    {"solver", SolverJson(result)},
                    {"measurements", internal::CountsJson(result.counts)},
                    {"recording", recording},
                    {"config", config}};
  return internal::WriteJson(out, path);
}

Result<std::map<std::string, Eigen::VectorXd>> ReadCalibrationValues(const std::string& path) {
  auto file = recording::ReadCalibrationFile(path);
  if (!file.ok()) return file.status();
  std::map<std::string, Eigen::VectorXd> out;
  for (const auto& [name, p] : file.value().parameters)
    out[name] = Eigen::Map<const Eigen::VectorXd>(p.estimate.data(), static_cast<Eigen::Index>(p.estimate.size()));
  return out;
}

Result<CalibrationPrior> ReadCalibrationPrior(const std::string& path) {
  auto file = recording::ReadCalibrationFile(path);
  if (!file.ok()) return file.status();
  if (!file.value().information)
    return Status::Error(path + ": no 'information' with 'parameters' and 'matrix' (calibrate it again)");
  const recording::CalibrationInformation& info = *file.value().information;
  if (!info.matrix.allFinite()) return Status::Error(path + ": information.matrix has a non-number");
  CalibrationPrior prior;
  prior.names = info.parameters;
  prior.information = info.matrix;
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
