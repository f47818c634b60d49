// roamlab_bench: the speed yardsticks of the ATV issue, measured in one run on this machine and printed as ratios to
// their targets. Not a test: timings depend on the machine and its load.
//
//   roamlab_bench [--quick] [--json OUT.json]
//
// simulation of scenarios/atv_hills.yaml with all sensors (multiple of real time; target >= 10x), online tracking of
// that recording with scenarios/atv_tracking.yaml and a 40-pose window (multiple of real time, target >= 20x; p99
// update latency), and a Monte-Carlo of N runs on all cores (50 runs must take under 3 minutes; --quick runs 4 and
// extrapolates, saying so). Rendering + visual odometry at 15 Hz (sim/visual_odometry_stream.h) on the test room of
// models/vo_test_room.xml, at 320x240 and 640x480, OpenCV on one thread (multiple of real time, target >= 1x).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>

#include <mujoco/mujoco.h>
#include <nlohmann/json.hpp>
#include <opencv2/core/utility.hpp>

#include "apps/montecarlo.h"
#include "estimator/config.h"
#include "estimator/tracking.h"
#include "sim/mujoco_model.h"
#include "sim/render.h"
#include "sim/scenario.h"
#include "sim/simulator.h"
#include "sim/visual_odometry.h"

namespace {

using Clock = std::chrono::steady_clock;
double Since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

int Fail(const std::string& message) {
  std::fprintf(stderr, "roamlab_bench: %s\n", message.c_str());
  return 1;
}

// Rendering + VO at 15 Hz in a 1 kHz loop: the camera rig of models/vo_test_room.xml drives a 0.6 m/s, 0.5 rad/s
// circle for 10 s (mj_forward every step stands in for the physics, which the robot simulations add at 20-40x real
// time). Returns {"WxH": {"realtime_factor", "vo_ms_per_pair", "render_ms_per_frame", "failures", "pairs"}}, or
// null with `error` set.
nlohmann::json BenchRenderVo(const std::string& root, std::string* error) {
  namespace sim = roamlab::sim;
  std::ifstream file(root + "/models/vo_test_room.xml");
  const std::string xml((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  auto model = sim::LoadModelFromString(xml, "models/vo_test_room.xml");
  if (!model.ok()) return *error = model.status().message(), nlohmann::json();
  const mjModel* m = model.value().get();
  cv::setNumThreads(0);  // one core
  nlohmann::json out;
  for (const auto& [width, height] : {std::pair{320, 240}, std::pair{640, 480}}) {
    sim::DataPtr data = sim::MakeData(m);
    sim::RenderOptions render;
    render.width_px = width;
    render.height_px = height;
    auto renderer = sim::CameraRenderer::Create(m, "camera", render);
    if (!renderer.ok()) return *error = renderer.status().message(), nlohmann::json();
    sim::VisualOdometryOptions options;
    options.camera_height_m = 0.30;  // the rig's mounting: 0.30 m high, pitched 15 deg down
    options.floor_normal_camera = Eigen::Vector3d(0.0, std::cos(0.2617993877991494), std::sin(0.2617993877991494));
    sim::VisualOdometry vo(renderer.value()->intrinsics(), options);
    cv::Mat gray;
    double render_s = 0.0;
    double vo_s = 0.0;
    const auto t0 = Clock::now();
    for (int step = 0; step <= 10000; ++step) {
      const double yaw = 0.5e-3 * step;
      data->mocap_pos[0] = 1.2 * std::sin(yaw);
      data->mocap_pos[1] = -1.2 * std::cos(yaw);
      data->mocap_quat[0] = std::cos(0.5 * yaw);
      data->mocap_quat[3] = std::sin(0.5 * yaw);
      mj_forward(m, data.get());
      if ((step * 15) % 1000 >= 15) continue;  // a frame every 1000 / 15 steps
      const auto t_render = Clock::now();
      renderer.value()->RenderGray(data.get(), &gray);
      const auto t_vo = Clock::now();
      vo.ProcessFrame(roamlab::Time::FromNanoseconds(1'000'000LL * step), gray);
      render_s += std::chrono::duration<double>(t_vo - t_render).count();
      vo_s += Since(t_vo);
    }
    const double wall = Since(t0);
    const auto& counters = vo.counters();
    out[std::to_string(width) + "x" + std::to_string(height)] = {
        {"realtime_factor", 10.0 / wall},
        {"vo_ms_per_pair", 1e3 * vo_s / std::max(1, counters.pairs)},
        {"render_ms_per_frame", 1e3 * render_s / std::max(1, counters.frames)},
        {"pairs", counters.pairs},
        {"failures", counters.failures}};
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  std::string json_path;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--quick") == 0) {
      quick = true;
    } else if (std::strcmp(argv[i], "--json") == 0 && i + 1 < argc) {
      json_path = argv[++i];
    } else {
      std::fprintf(stderr, "usage: roamlab_bench [--quick] [--json OUT.json]\n");
      return 2;
    }
  }
  const std::string root = ROAMLAB_SOURCE_DIR;
  const std::string scenario_path = root + "/scenarios/atv_hills.yaml";
  const std::string tracking_path = root + "/scenarios/atv_tracking.yaml";
  auto scenario = roamlab::sim::LoadScenario(scenario_path);
  if (!scenario.ok()) return Fail(scenario.status().message());
  auto config = roamlab::estimator::LoadEstimatorConfig(tracking_path);
  if (!config.ok()) return Fail(config.status().message());

  // Simulation with every sensor.
  const auto t_sim = Clock::now();
  auto simulation = roamlab::sim::Simulate(scenario.value());
  const double sim_wall = Since(t_sim);
  if (!simulation.ok()) return Fail(simulation.status().message());
  const double simulated = simulation.value().stats.simulated_s;
  const double sim_factor = simulated / sim_wall;

  // Online tracking, 40-pose window.
  config.value().tracking.window = 40;
  auto tracked = roamlab::estimator::Track(config.value(), simulation.value().recording, {});
  if (!tracked.ok()) return Fail(tracked.status().message());
  const auto& traj = tracked.value().trajectory;
  const double duration = roamlab::SecondsBetween(traj.front().t, traj.back().t);
  const double track_factor = duration / tracked.value().total_seconds;

  // Monte-Carlo over all cores.
  const int runs = quick ? 4 : 50;
  const std::string mc_dir = (std::filesystem::temp_directory_path() / "roamlab_bench_mc").string();
  roamlab::apps::MonteCarloArgs mc;
  mc.scenario = scenario_path;
  mc.config = tracking_path;
  mc.out = mc_dir;
  mc.runs = runs;
  mc.quiet = true;
  const auto t_mc = Clock::now();
  if (roamlab::apps::RunMonteCarlo(mc) != 0) return Fail("montecarlo failed");
  const double mc_seconds = Since(t_mc);
  std::filesystem::remove_all(mc_dir);
  const double mc50_minutes = mc_seconds / runs * 50.0 / 60.0;

  // Rendering + visual odometry at 15 Hz.
  std::string vo_error;
  const nlohmann::json render_vo = BenchRenderVo(root, &vo_error);
  if (render_vo.is_null()) return Fail(vo_error);

  // Report: value, target, ratio (>= 1 means the target is met).
  std::printf("roamlab_bench on %u cores%s\n", std::thread::hardware_concurrency(), quick ? " (--quick)" : "");
  std::printf("  simulation, all sensors        %7.1fx real time   target >= 10x   ratio %.2f\n", sim_factor,
              sim_factor / 10.0);
  std::printf("  tracking, 40-pose window       %7.1fx real time   target >= 20x   ratio %.2f   (p99 update %.2f ms)\n",
              track_factor, track_factor / 20.0, 1e3 * tracked.value().p99_update_s);
  std::printf("  montecarlo, 50 runs            %7.2f min%s     target <= 3 min ratio %.2f\n", mc50_minutes,
              quick ? " (from 4)" : "        ", 3.0 / mc50_minutes);
  for (const auto& [size, r] : render_vo.items()) {
    const double factor = r["realtime_factor"].get<double>();
    std::printf("  render + VO 15 Hz, %-7s       %7.1fx real time   target >= 1x    ratio %.2f   (VO %.1f ms/pair, "
                "render %.1f ms/frame, %d/%d pairs failed)\n",
                size.c_str(), factor, factor, r["vo_ms_per_pair"].get<double>(), r["render_ms_per_frame"].get<double>(),
                r["failures"].get<int>(), r["pairs"].get<int>());
  }
  if (!json_path.empty()) {
    nlohmann::json j = {{"simulation_realtime_factor", sim_factor},
                              {"tracking_realtime_factor_w40", track_factor},
                              {"tracking_p99_ms_w40", 1e3 * tracked.value().p99_update_s},
                              {"montecarlo_runs", runs},
                              {"montecarlo_50_runs_minutes", mc50_minutes},
                              {"quick", quick}};
    for (const auto& [size, r] : render_vo.items()) {
      j["render_vo_realtime_factor_15hz"][size] = r["realtime_factor"];
      j["vo_ms_per_pair"][size] = r["vo_ms_per_pair"];
    }
    std::ofstream(json_path) << j.dump(2) << "\n";
  }
  return 0;
}
