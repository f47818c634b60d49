#include "experiment/information.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "common/atomic_file.h"
#include "common/json.h"
#include "eval/plots.h"
#include "estimator/config.h"
#include "estimator/problem.h"
#include "sim/scenario.h"
#include "sim/simulator.h"

namespace roamlab::experiment {
namespace {

constexpr double kDegPerRad = 180.0 / 3.14159265358979323846;
// Drive samples for the figure: one every kDriveStepS over the true poses, velocities over that step.
constexpr double kDriveStepS = 0.1;

// Speed, yaw rate and pitch of O between true poses about kDriveStepS apart, stamped at the middle (seconds since t0).
struct DriveSample {
  double t_s, speed_mps, yaw_rate_radps, pitch_deg;
};
std::vector<DriveSample> DriveSamples(const Trajectory& truth, Time t0) {
  std::vector<DriveSample> out;
  std::size_t a = 0;
  for (std::size_t b = 1; b < truth.size(); ++b) {
    const double dt = SecondsBetween(truth[a].t, truth[b].t);
    if (dt < kDriveStepS - 1e-9 && b + 1 < truth.size()) continue;
    if (dt <= 0.0) continue;
    const Eigen::AngleAxisd turn(truth[a].q_world_body.conjugate() * truth[b].q_world_body);
    const Eigen::Quaterniond middle = truth[a].q_world_body.slerp(0.5, truth[b].q_world_body);
    const Eigen::Vector3d x_world = middle.toRotationMatrix().col(0);
    DriveSample s;
    s.t_s = SecondsBetween(t0, truth[a].t) + 0.5 * dt;
    s.speed_mps = (truth[b].p_world_body - truth[a].p_world_body).norm() / dt;
    s.yaw_rate_radps = (turn.angle() * turn.axis()).z() / dt;
    s.pitch_deg = std::asin(std::clamp(x_world.z(), -1.0, 1.0)) * kDegPerRad;
    out.push_back(s);
    a = b;
  }
  return out;
}

std::vector<WindowDrive> WindowMeans(const std::vector<DriveSample>& samples, const estimator::InformationResult& r) {
  std::vector<WindowDrive> out(static_cast<std::size_t>(r.windows));
  std::vector<int> counts(out.size(), 0);
  for (std::size_t k = 0; k < out.size(); ++k) {
    out[k].begin_s = static_cast<double>(k) * r.window_s;
    out[k].end_s = out[k].begin_s + r.window_s;
  }
  for (const DriveSample& s : samples) {
    const int k = static_cast<int>(std::floor(s.t_s / r.window_s));
    if (k < 0 || k >= r.windows) continue;
    WindowDrive& w = out[static_cast<std::size_t>(k)];
    w.speed_mps += s.speed_mps;
    w.yaw_rate_radps += std::abs(s.yaw_rate_radps);
    w.pitch_deg += s.pitch_deg;
    ++counts[static_cast<std::size_t>(k)];
  }
  for (std::size_t k = 0; k < out.size(); ++k) {
    const double n = counts[k] > 0 ? counts[k] : std::nan("");
    out[k].speed_mps /= n;
    out[k].yaw_rate_radps /= n;
    out[k].pitch_deg /= n;
  }
  return out;
}

// The figure's data: one row per component, the drive samples.
eval::InformationPlotData PlotData(const estimator::InformationResult& r, const std::vector<DriveSample>& samples) {
  eval::InformationPlotData data;
  data.window_s = r.window_s;
  for (const estimator::InformationComponent& c : r.components) {
    data.rows.push_back(c.label);
    data.shares.push_back(c.by_window);
  }
  for (const DriveSample& s : samples) {
    data.t_s.push_back(s.t_s);
    data.speed_mps.push_back(s.speed_mps);
    data.yaw_rate_radps.push_back(s.yaw_rate_radps);
    data.pitch_deg.push_back(s.pitch_deg);
  }
  return data;
}

}  // namespace

nlohmann::json InformationJson(const InformationRequest& request, const InformationRun& run) {
  using nlohmann::json;
  const estimator::InformationResult& r = run.result;
  json parameters = json::object();
  for (const estimator::InformationParameter& p : r.parameters) {
    json components = json::array();
    for (int k = 0; k < p.manifold.tangent_dim(); ++k) {
      const estimator::InformationComponent& c = r.components[static_cast<std::size_t>(p.first_component + k)];
      json by_stream = json::object(), by_stream_window = json::object(), measured_by = json::object(),
           measured_by_stream_window = json::object();
      for (const auto& [stream, shares] : c.measured_by_stream_window)
        measured_by_stream_window[stream] = NumberArray(shares);
      for (const auto& [stream, share] : c.by_stream) by_stream[stream] = Number(share);
      for (const auto& [stream, share] : c.measured_by) measured_by[stream] = Number(share);
      for (const auto& [stream, shares] : c.by_stream_window) by_stream_window[stream] = NumberArray(shares);
      components.push_back({{"label", c.label},
                            {"crb_std", Number(c.crb_std)},
                            {"observability", estimator::ObservabilityName(c.observability)},
                            {"by_stream", by_stream},
                            {"by_window", NumberArray(c.by_window)},
                            {"by_stream_window", by_stream_window},
                            {"measured_by", measured_by},
                            {"measured_by_stream_window", measured_by_stream_window}});
    }
    parameters[p.name] = {{"truth", p.has_truth ? NumberArray(p.truth) : json()},
                          {"linearized_at", NumberArray(p.truth)},
                          {"manifold", p.manifold.Name()},
                          {"components", components}};
  }
  json windows = json::array();
  for (const WindowDrive& w : run.windows)
    windows.push_back({{"begin_s", w.begin_s},
                       {"end_s", w.end_s},
                       {"speed_mps", Number(w.speed_mps)},
                       {"yaw_rate_radps", Number(w.yaw_rate_radps)},
                       {"pitch_deg", Number(w.pitch_deg)}});
  json directions = json::array();
  for (const estimator::InformationDirection& d : r.directions)
    directions.push_back({{"eigenvalue", d.eigenvalue},
                          {"observability", estimator::ObservabilityName(d.observability)},
                          {"name", d.name},
                          {"direction", NumberArray(d.direction)}});
  json labels = json::array();
  for (const estimator::InformationComponent& c : r.components) labels.push_back(c.label);
  return {{"scenario", request.scenario},
          {"config", request.config},
          {"window_s", r.window_s},
          {"poses", r.poses},
          {"factors", r.factors},
          {"streams", r.streams},
          {"windows", windows},
          {"parameters", parameters},
          {"directions", directions},
          {"components", labels}};
}

Outcome InformationToDirectory(const InformationRequest& request, InformationRun* run_out) {
  // Inputs: the scenario, the configuration, the window.
  auto scenario = sim::LoadScenario(request.scenario);
  if (!scenario.ok()) return Outcome::BadInput(scenario.status());
  auto config = estimator::LoadEstimatorConfig(request.config);
  if (!config.ok()) return Outcome::BadInput(config.status());
  estimator::InformationOptions options;
  options.window_s = request.window_s;
  if (const std::string problem = options.Validate(); !problem.empty())
    return Outcome::BadInput(Status::Error("--window: " + problem));
  if (Status dir = MakeOutputDirectory(request.out); !dir.ok()) return Outcome::BadInput(dir);

  // The drive without sensor noise (without the laser and camera the configuration does not read); the configuration
  // against its recording.
  scenario.value().DropUnreadCostlySensors(estimator::StreamsRead(config.value()));
  sim::SimulateOptions simulate;
  simulate.noise = false;
  simulate.progress = request.progress;
  auto simulation = sim::Simulate(scenario.value(), simulate);
  if (!simulation.ok()) {
    Outcome failed = Outcome::Failed(simulation.status());
    failed.step = "simulate";
    return failed;
  }
  const recording::Recording& recording = simulation.value().recording;
  if (!recording.ground_truth || recording.ground_truth->empty())
    return Outcome::Failed(Status::Error(request.scenario + ": the simulation wrote no ground truth"));
  if (auto builder = estimator::ProblemBuilder::Create(config.value(), recording); !builder.ok())
    return Outcome::BadInput(builder.status());

  // The analysis, the drive per window, the JSON and the figure.
  InformationRun run;
  auto analysed = estimator::AnalyzeInformation(config.value(), recording, simulation.value().truth.calibration,
                                                *recording.ground_truth, options);
  if (!analysed.ok()) return Outcome::Failed(Status::Error(request.config + ": " + analysed.status().message()));
  run.result = std::move(analysed).value();
  const std::vector<DriveSample> samples = DriveSamples(*recording.ground_truth, run.result.t0);
  run.windows = WindowMeans(samples, run.result);
  if (Status s = WriteFileAtomic(request.out + "/information.json", InformationJson(request, run).dump(2) + "\n");
      !s.ok())
    return Outcome::Failed(s);
  auto plot = eval::WriteInformationPlot(request.out, "Information per window: " + request.scenario + ", " +
                                                          request.config,
                                         PlotData(run.result, samples));
  Status drawn = plot.ok() ? eval::RunGnuplot(request.out, plot.value().script) : plot.status();
  if (!drawn.ok()) run.plot_warning = drawn.message();
  if (run_out) *run_out = std::move(run);
  return Outcome::Ok();
}

}  // namespace roamlab::experiment
