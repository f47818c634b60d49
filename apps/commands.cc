#include "apps/commands.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <set>

#include <nlohmann/json.hpp>

#include "common/time.h"
#include "estimator/calibration.h"
#include "estimator/config.h"
#include "estimator/tracking.h"
#include "recording/recording.h"
#include "recording/trajectory.h"

namespace roamlab::apps {
namespace {

using nlohmann::json;

int BadInput(std::ostream* err, const std::string& command, const std::string& message) {
  (err ? *err : std::cerr) << "roamlab " << command << ": " << message << "\n";
  return 2;
}

int Failure(std::ostream* err, const std::string& command, const std::string& message) {
  (err ? *err : std::cerr) << "roamlab " << command << ": " << message << "\n";
  return 1;
}

json Vector(const Eigen::VectorXd& v) {
  json a = json::array();
  for (int i = 0; i < v.size(); ++i) a.push_back(std::isfinite(v[i]) ? json(v[i]) : json(nullptr));
  return a;
}

Status WriteJson(const json& j, const std::string& path) {
  std::ofstream out(path);
  if (!out) return Status::Error(path + ": cannot write");
  out << j.dump(2) << "\n";
  return out ? Status::Ok() : Status::Error(path + ": write failed");
}

Status MakeOutputDirectory(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return Status::Error(dir + ": cannot create the output directory: " + ec.message());
  return Status::Ok();
}

// Loads the configuration and the recording streams it reads.
struct Inputs {
  estimator::EstimatorConfig config;
  recording::Recording recording;
};
Result<Inputs> LoadInputs(const std::string& config_path, const std::string& recording_dir) {
  auto config = estimator::LoadEstimatorConfig(config_path);
  if (!config.ok()) return config.status();
  recording::ReadOptions read;
  read.load_ground_truth = false;
  for (const auto& [name, stream] : config.value().streams)
    for (const auto& [role, source] : stream.sources) read.required_streams.push_back(source);
  auto rec = recording::ReadRecording(recording_dir, read);
  if (!rec.ok()) return rec.status();
  return Inputs{std::move(config).value(), std::move(rec).value()};
}

json CountsJson(const std::map<std::string, estimator::StreamCounts>& counts) {
  json j = json::object();
  for (const auto& [name, c] : counts)
    j[name] = {{"attached", c.attached}, {"rejected", c.rejected}, {"too_late", c.too_late}, {"outside", c.outside}};
  return j;
}

// A JSON file, or one line naming it and the problem.
Result<json> ReadJsonFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) return Status::Error(path + ": cannot open");
  json j;
  try {
    in >> j;
  } catch (const json::exception& e) {
    return Status::Error(path + ": not valid JSON: " + e.what());
  }
  return j;
}

}  // namespace

// Parameter values from a calibration.json: parameters.NAME.estimate.
Result<std::map<std::string, Eigen::VectorXd>> ReadCalibrationValues(const std::string& path) {
  auto file = ReadJsonFile(path);
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

Result<estimator::CalibrationPrior> ReadCalibrationPrior(const std::string& path) {
  auto file = ReadJsonFile(path);
  if (!file.ok()) return file.status();
  json j = std::move(file).value();
  const json& info = j["information"];
  if (!info.is_object() || !info["parameters"].is_array() || !info["matrix"].is_array())
    return Status::Error(path + ": no 'information' with 'parameters' and 'matrix' (calibrate it again)");
  estimator::CalibrationPrior prior;
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

Result<estimator::TrackingOptions> TrackingOptionsFor(const estimator::EstimatorConfig& config,
                                                      const std::string& calibration_path) {
  estimator::TrackingOptions options;
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

int RunCalibrate(const CalibrateArgs& args) {
  const std::string cmd = "calibrate";
  auto inputs = LoadInputs(args.config, args.recording);
  if (!inputs.ok()) return BadInput(args.err, cmd, inputs.status().message());
  const Status dir = MakeOutputDirectory(args.out);
  if (!dir.ok()) return BadInput(args.err, cmd, dir.message());

  estimator::CalibrationOptions options;
  if (!args.quiet) options.progress = [](const std::string& line) { std::cerr << "calibrate: " << line << "\n"; };
  auto result = estimator::Calibrate(inputs.value().config, inputs.value().recording, options);
  if (!result.ok()) return Failure(args.err, cmd, result.status().message());
  const estimator::CalibrationResult& r = result.value();

  // calibration.json
  json params = json::object();
  for (const auto& p : r.parameters) {
    json components = json::array();
    for (auto o : p.components) components.push_back(estimator::ObservabilityName(o));
    params[p.name] = {{"estimate", Vector(p.estimate)},
                      {"std", Vector(p.std)},
                      {"observability", estimator::ObservabilityName(p.observability)},
                      {"component_observability", components},
                      {"manifold", p.manifold.Name()}};
  }
  json names = json::array(), matrix = json::array();
  for (const auto& p : r.parameters) names.push_back(p.name);
  for (int row = 0; row < r.information.rows(); ++row) matrix.push_back(Vector(r.information.row(row).transpose()));
  json correlations = json::array();
  for (const auto& c : r.correlations) correlations.push_back({{"a", c.a}, {"b", c.b}, {"rho", c.rho}});
  json stages = json::array();
  for (const auto& s : r.stages)
    stages.push_back({{"free", s.free_parameters},
                      {"iterations", s.solver.iterations},
                      {"initial_cost", s.solver.initial_cost},
                      {"final_cost", s.solver.final_cost},
                      {"termination", estimator::TerminationName(s.solver.termination)},
                      {"cost_history", s.solver.cost_history},
                      {"rejected", s.rejected},
                      {"seconds", s.solver.seconds}});
  const json out = {{"parameters", params},
                    {"information", {{"parameters", names}, {"matrix", matrix}}},
                    {"correlations", correlations},
                    {"solver",
                     {{"iterations", r.iterations},
                      {"initial_cost", r.initial_cost},
                      {"final_cost", r.final_cost},
                      {"termination", r.termination},
                      {"seconds", r.seconds},
                      {"stages", stages}}},
                    {"measurements", CountsJson(r.counts)},
                    {"recording", args.recording},
                    {"config", args.config}};
  const std::string json_path = args.out + "/calibration.json";
  Status st = WriteJson(out, json_path);
  if (!st.ok()) return Failure(args.err, cmd, st.message());
  st = WriteTum(r.trajectory, args.out + "/trajectory.tum");
  if (!st.ok()) return Failure(args.err, cmd, st.message());

  // Human-readable table.
  if (args.quiet) return 0;
  std::printf("%-28s %-13s %s\n", "parameter", "observability", "estimate (std)");
  for (const auto& p : r.parameters) {
    std::string values;
    for (int i = 0; i < p.estimate.size(); ++i) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "%s%.5g", i ? ", " : "", p.estimate[i]);
      values += buf;
    }
    std::string stds;
    for (int i = 0; i < p.std.size(); ++i) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "%s%.2g", i ? ", " : "", p.std[i]);
      stds += std::isfinite(p.std[i]) ? buf : (i ? ", -" : "-");
    }
    std::printf("%-28s %-13s [%s] (%s)\n", p.name.c_str(), estimator::ObservabilityName(p.observability),
                values.c_str(), stds.c_str());
  }
  for (const auto& c : r.correlations)
    std::printf("strongly correlated: %s ~ %s (rho %.3f)\n", c.a.c_str(), c.b.c_str(), c.rho);
  std::printf("cost %.6g -> %.6g in %d iterations, %.2f s; wrote %s\n", r.initial_cost, r.final_cost, r.iterations,
              r.seconds, json_path.c_str());
  return 0;
}

int RunTrack(const TrackArgs& args) {
  const std::string cmd = "track";
  auto inputs = LoadInputs(args.config, args.recording);
  if (!inputs.ok()) return BadInput(args.err, cmd, inputs.status().message());
  if (args.no_time_budget) inputs.value().config.tracking.time_budget_s = std::numeric_limits<double>::infinity();
  std::map<std::string, Eigen::VectorXd> calibration;
  if (!args.calibration.empty()) {
    auto cal = ReadCalibrationValues(args.calibration);
    if (!cal.ok()) return BadInput(args.err, cmd, cal.status().message());
    calibration = std::move(cal).value();
  }
  auto tracking_options = TrackingOptionsFor(inputs.value().config, args.calibration);
  if (!tracking_options.ok()) return BadInput(args.err, cmd, tracking_options.status().message());
  const Status dir = MakeOutputDirectory(args.out);
  if (!dir.ok()) return BadInput(args.err, cmd, dir.message());

  estimator::TrackingOptions options = std::move(tracking_options).value();
  if (!args.quiet)
    options.progress = [](double f) { std::cerr << "\rtrack: " << static_cast<int>(100 * f) << "%" << std::flush; };
  auto result = estimator::Track(inputs.value().config, inputs.value().recording, calibration, options);
  if (!args.quiet) std::cerr << "\rtrack: 100%\n";
  if (!result.ok()) return Failure(args.err, cmd, result.status().message());
  const estimator::TrackingResult& r = result.value();

  Status st = WriteTum(r.trajectory, args.out + "/trajectory.tum");
  if (!st.ok()) return Failure(args.err, cmd, st.message());
  {
    std::ofstream cov(args.out + "/covariance.csv");
    cov << "t,xx,xy,xz,yx,yy,yz,zx,zy,zz\n";
    char buf[64];
    for (std::size_t i = 0; i < r.trajectory.size(); ++i) {
      cov << FormatSeconds(r.trajectory[i].t);
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) {
          std::snprintf(buf, sizeof buf, ",%.17g", r.position_covariance[i](a, b));
          cov << buf;
        }
      cov << "\n";
    }
    if (!cov) return Failure(args.err, cmd, args.out + "/covariance.csv: write failed");
  }
  int rejected = 0;
  for (const auto& [name, c] : r.counts) rejected += c.rejected;
  const double duration =
      r.trajectory.size() > 1 ? SecondsBetween(r.trajectory.front().t, r.trajectory.back().t) : 0.0;
  const json summary = {{"poses", r.trajectory.size()},
                        {"updates", r.updates},
                        {"mean_update_s", r.mean_update_s},
                        {"max_update_s", r.max_update_s},
                        {"p99_update_s", r.p99_update_s},
                        {"mean_iterations", r.mean_iterations},
                        {"factor_evaluations", r.factor_evaluations},
                        {"factor_carries", r.factor_carries},
                        {"seconds", r.total_seconds},
                        {"realtime_factor", r.total_seconds > 0 ? duration / r.total_seconds : 0.0},
                        {"window", inputs.value().config.tracking.window},
                        {"rejected_measurements", rejected},
                        {"measurements", CountsJson(r.counts)}};
  st = WriteJson(summary, args.out + "/summary.json");
  if (!st.ok()) return Failure(args.err, cmd, st.message());
  if (args.quiet) return 0;
  std::printf("tracked %zu poses, %d updates (mean %.2f ms, max %.2f ms), %d rejected, %.1fx real time; wrote %s\n",
              r.trajectory.size(), r.updates, 1e3 * r.mean_update_s, 1e3 * r.max_update_s, rejected,
              r.total_seconds > 0 ? duration / r.total_seconds : 0.0, (args.out + "/trajectory.tum").c_str());
  return 0;
}

}  // namespace roamlab::apps
