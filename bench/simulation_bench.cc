#include <algorithm>
#include <cmath>
#include <ctime>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>

#include <mujoco/mujoco.h>
#include <opencv2/core/utility.hpp>

#include "bench/bench.h"
#include "frontend/visual_odometry.h"
#include "sim/mujoco_model.h"
#include "sim/render.h"
#include "sim/replay.h"
#include "sim/simulator.h"

namespace roamlab::bench {
namespace {

// Rendering + VO at 15 Hz in a 1 kHz loop: the camera rig of models/vo_test_room.xml drives a 0.6 m/s, 0.5 rad/s
// circle for `duration_s` (mj_forward every step stands in for the physics, which the robot simulations add at 20-40x
// real time). Returns {"WxH": {"realtime_factor", "vo_ms_per_pair", "render_ms_per_frame", "failures", "pairs"}}, or
// null with `error` set.
nlohmann::json BenchRenderVo(const std::string& root, double duration_s, std::string* error) {
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
    frontend::VisualOdometryOptions options;
    options.camera_height_m = 0.30;  // the rig's mounting: 0.30 m high, pitched 15 deg down
    options.floor_normal_camera = Eigen::Vector3d(0.0, std::cos(0.2617993877991494), std::sin(0.2617993877991494));
    frontend::VisualOdometry vo(renderer.value()->intrinsics(), options);
    cv::Mat gray;
    double render_s = 0.0;
    double vo_s = 0.0;
    const auto t0 = Clock::now();
    const int steps = static_cast<int>(std::lround(1000.0 * duration_s));
    for (int step = 0; step <= steps; ++step) {
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
      vo.ProcessFrame(Time::FromNanoseconds(1'000'000LL * step), gray);
      render_s += std::chrono::duration<double>(t_vo - t_render).count();
      vo_s += Since(t_vo);
    }
    const double wall = Since(t0);
    const auto& counters = vo.counters();
    out[std::to_string(width) + "x" + std::to_string(height)] = {
        {"realtime_factor", duration_s / wall},
        {"vo_ms_per_pair", 1e3 * vo_s / std::max(1, counters.pairs)},
        {"render_ms_per_frame", 1e3 * render_s / std::max(1, counters.frames)},
        {"pairs", counters.pairs},
        {"failures", counters.failures}};
  }
  return out;
}

}  // namespace

// 1. Simulation of the ATV scenario with every sensor (its recording is the later steps'), then the indoor
// scenarios without rendering (1b) and rendering with visual odometry (1c).
int BenchSimulation(const Context& ctx, Json* j, recording::Recording* recording) {
  // 1. Simulation with every sensor.
  const auto t_sim = Clock::now();
  auto simulation = sim::Simulate(ctx.scenario);
  const double sim_wall = Since(t_sim);
  if (!simulation.ok()) return Fail(simulation.status().message());
  const double sim_factor = simulation.value().stats.simulated_s / sim_wall;
  (*j)["simulation_realtime_factor"] = sim_factor;
  Say("  simulation, all sensors            %8.1fx real time    target >= 10x       ratio %.2f\n", sim_factor,
      sim_factor / 10.0);
  *recording = std::move(simulation).value().recording;

  // 1b. The indoor yardstick: scenarios/indoor_diffdrive_slip.yaml (differential drive) and
  // scenarios/indoor_omni_slip.yaml (three omni wheels with 36 roller bodies), each with IMU, encoders and a 683-beam
  // laser with scan matching; no rendering; target >= 10x; CPU time too, since on a shared machine the wall clock also
  // counts other processes.
  for (const auto& [name, key] :
       {std::pair<std::string, std::string>{"indoor_diffdrive_slip", "indoor_simulation_realtime_factor"},
        std::pair<std::string, std::string>{"indoor_omni_slip", "indoor_omni_simulation_realtime_factor"}}) {
    auto indoor = sim::LoadScenario(ctx.root + "/scenarios/" + name + ".yaml");
    if (!indoor.ok()) return Fail(indoor.status().message());
    indoor.value().sensors.camera.reset();  // rendering: 1c and 1e
    indoor.value().duration_s = ctx.sizes.indoor_s;
    const auto t_indoor = Clock::now();
    const std::clock_t cpu_indoor = std::clock();
    auto indoor_simulation = sim::Simulate(indoor.value());
    const double indoor_wall = Since(t_indoor);
    const double indoor_cpu = static_cast<double>(std::clock() - cpu_indoor) / CLOCKS_PER_SEC;
    if (!indoor_simulation.ok()) return Fail(indoor_simulation.status().message());
    const double indoor_factor = indoor_simulation.value().stats.simulated_s / indoor_wall;
    const double indoor_cpu_factor = indoor_simulation.value().stats.simulated_s / indoor_cpu;
    (*j)[key] = indoor_factor;
    Say("  %-22s no rendering %8.1fx real time    target >= 10x       ratio %.2f   (CPU time: %.1fx)\n", name.c_str(),
        indoor_factor, indoor_factor / 10.0, indoor_cpu_factor);
  }

  // 1c. The indoor camera yardstick: rendering + visual odometry at 15 Hz (sim/visual_odometry_stream.h) on
  // the test room of models/vo_test_room.xml, at 320x240 and 640x480, OpenCV on one thread (target >= 1x).
  {
    std::string vo_error;
    const nlohmann::json render_vo = BenchRenderVo(ctx.root, ctx.sizes.render_vo_s, &vo_error);
    if (render_vo.is_null()) return Fail(vo_error);
    for (const auto& [size, r] : render_vo.items()) {
      const double factor = r["realtime_factor"].get<double>();
      (*j)["render_vo_realtime_factor_15hz"][size] = r["realtime_factor"];
      (*j)["vo_ms_per_pair"][size] = r["vo_ms_per_pair"];
      Say("  render + VO 15 Hz, %-7s          %8.1fx real time    target >= 1x        ratio %.2f   (VO %.1f ms/pair, "
          "render %.1f ms/frame, %d/%d pairs failed)\n",
          size.c_str(), factor, factor, r["vo_ms_per_pair"].get<double>(), r["render_ms_per_frame"].get<double>(),
          r["failures"].get<int>(), r["pairs"].get<int>());
    }
  }
  return 0;
}

int BenchReplay(const Context& ctx, const recording::Recording& atv, Json* j) {
  // 1f. Replay (sim/replay.h): the ATV recording of step 1 replayed from its rear-wheel speed and steering in the
  // same scenario (target >= 5x), and recordings of scenarios/indoor_diffdrive_slip.yaml and indoor_omni_slip.yaml
  // (IMU and encoders: no laser) replayed from their encoders (targets >= 20x and >= 5x); wall and CPU time on one
  // thread.
  const auto replay = [j](const sim::Scenario& nominal, const recording::Recording& rec, const std::string& name,
                          double target) {
    const std::clock_t cpu = std::clock();
    auto twin = sim::Replay(nominal, rec);
    const double cpu_s = static_cast<double>(std::clock() - cpu) / CLOCKS_PER_SEC;
    if (!twin.ok()) return Fail(twin.status().message());
    const double factor = twin.value().stats.realtime_factor;
    (*j)["replay_realtime_factor"][name] = factor;
    const std::string target_text = std::to_string(static_cast<int>(target)) + "x";
    Say("  replay, %-26s %8.1fx real time    target >= %-8s ratio %.2f   (CPU time: %.1fx)\n", name.c_str(), factor,
        target_text.c_str(), factor / target, twin.value().stats.simulated_s / cpu_s);
    return 0;
  };
  if (int code = replay(ctx.scenario, atv, "atv_hills", 5.0)) return code;
  for (const auto& [name, target] : {std::pair<std::string, double>{"indoor_diffdrive_slip", 20.0},
                                     std::pair<std::string, double>{"indoor_omni_slip", 5.0}}) {
    auto indoor = sim::LoadScenario(ctx.root + "/scenarios/" + name + ".yaml");
    if (!indoor.ok()) return Fail(indoor.status().message());
    indoor.value().sensors.camera.reset();
    indoor.value().sensors.laser.reset();
    indoor.value().duration_s = ctx.sizes.indoor_s;
    auto recorded = sim::Simulate(indoor.value());
    if (!recorded.ok()) return Fail(recorded.status().message());
    if (int code = replay(indoor.value(), recorded.value().recording, name, target)) return code;
  }
  return 0;
}

int BenchIndoorCamera(const Context& ctx, Json* j) {
  // 1e. The indoor scenario as written: physics, laser and scan matching, and the camera rendered and fed to the
  // visual odometry at 15 Hz (320x240), OpenCV on one thread; target >= 1x real time.
  {
    auto indoor = sim::LoadScenario(ctx.root + "/scenarios/indoor_diffdrive_slip.yaml");
    if (!indoor.ok()) return Fail(indoor.status().message());
    if (ctx.sizes.indoor_camera_s > 0.0) indoor.value().duration_s = ctx.sizes.indoor_camera_s;
    const auto t_indoor = Clock::now();
    auto indoor_simulation = sim::Simulate(indoor.value());
    const double indoor_wall = Since(t_indoor);
    if (!indoor_simulation.ok()) return Fail(indoor_simulation.status().message());
    const double factor = indoor_simulation.value().stats.simulated_s / indoor_wall;
    (*j)["indoor_simulation_with_camera_realtime_factor"] = factor;
    Say("  indoor simulation with camera      %8.1fx real time    target >= 1x        ratio %.2f\n", factor, factor);
  }
  return 0;
}

}  // namespace roamlab::bench
