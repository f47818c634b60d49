// roamlab_bench: speed against the peers and the floor, measured side by side in one run on this machine and printed
// as ratios to their targets. Not a test: timings depend on the machine and its load,
// so every timing is reported as wall time and as CPU time of the measuring process or thread.
//
//   roamlab_bench [--quick] [--json OUT.json]
//
// 1. Simulation of scenarios/atv_hills.yaml with every sensor (multiple of real time); 1f: replays of that recording
//    and of indoor differential-drive and omni recordings (sim/replay.h, multiple of real time).
// 2. Offline calibration of that recording by roamlab and by the Ceres peer (bench/ceres_peer.h) on the same graph:
//    one stage with every parameter of configs/atv_calibration.yaml free, from the same aligned initial values,
//    no gating; final costs (both evaluated by roamlab's objective) and parameters compared; time ratio (each solver's
//    least time of three runs).
// 3. The floor: one CHOLMOD factorization of the final Hessian, against roamlab's time per iteration.
// 4. Online tracking (configs/atv_tracking.yaml) with windows of 10, 40 and 160 poses, parameters fixed and under
//    the calibration prior (the configuration's default), at the product's calibration of step 1's recording (as
//    `roamlab calibrate`): multiple of real time by wall time and by CPU time of the tracking thread, mean and p99
//    update latency; the 40-pose window best of three runs (least CPU time) with the median beside it, and also
//    under the calibration of step 2 (the peer problem's).
// 5. Scaling of the offline calibration (the product's Calibrate, stages and gating included) on 30 s, 5 min and
//    30 min drives of the same scenario on a circular route, each in a child process for its peak memory; the drives
//    up to 1 min the median of five such processes, up to 10 min of three.
// 6. Memory of a one-hour online run (child process): resident set after the first minute and at the end.
// 7. Monte-Carlo runs per minute with one and two jobs.
// 8. Import speed (runs first: it needs nothing of the others): a CSV log, a ROS 1 bag, an MCAP file with zstd chunks
//    and a rosbag2 SQLite directory of about 100 MB each, written to the scratch directory and imported into a
//    recording in memory on one thread, beside a plain read of the same files (the I/O floor); target 10 s each.
// --quick: the same steps and JSON keys on reduced sizes (JSON `sizes`): 10 s indoor drives, 3 s of rendering, the
// Ceres comparison on a 10 s drive, windows of 10 and 40 poses, scaling on 10 s and 30 s, a 90 s online run,
// Monte-Carlo on 10 s drives (one run with one job, two with two), 10 MB imports against a 1 s target.
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <thread>

#include <unistd.h>

#include "bench/bench.h"
#include "common/atomic_file.h"
#include "estimator/config.h"
#include "recording/recording.h"
#include "sim/scenario.h"

namespace roamlab::bench {
namespace {

// Parses --quick and --json; false on anything else.
bool ParseArguments(int argc, char** argv, bool* quick, std::string* json_path) {
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--quick") == 0) {
      *quick = true;
    } else if (std::strcmp(argv[i], "--json") == 0 && i + 1 < argc) {
      *json_path = argv[++i];
    } else {
      return false;
    }
  }
  return true;
}

// The run's inputs: the ATV scenario and its calibration and tracking configurations, a scratch directory.
int MakeContext(bool quick, Context* ctx) {
  ctx->quick = quick;
  if (quick) ctx->sizes = QuickSizes();
  ctx->self = std::filesystem::canonical("/proc/self/exe").string();
  ctx->root = ROAMLAB_SOURCE_DIR;
  ctx->scenario_path = ctx->root + "/scenarios/atv_hills.yaml";
  ctx->calibration_path = ctx->root + "/configs/atv_calibration.yaml";
  ctx->tracking_path = ctx->root + "/configs/atv_tracking.yaml";
  auto scenario = sim::LoadScenario(ctx->scenario_path);
  if (!scenario.ok()) return Fail(scenario.status().message());
  ctx->scenario = std::move(scenario).value();
  auto calibration_config = est::LoadEstimatorConfig(ctx->calibration_path);
  if (!calibration_config.ok()) return Fail(calibration_config.status().message());
  ctx->calibration_config = std::move(calibration_config).value();
  auto tracking_config = est::LoadEstimatorConfig(ctx->tracking_path);
  if (!tracking_config.ok()) return Fail(tracking_config.status().message());
  ctx->tracking_config = std::move(tracking_config).value();
  ctx->tmp = std::filesystem::temp_directory_path() / ("roamlab_bench_" + std::to_string(static_cast<long>(getpid())));
  std::filesystem::create_directories(ctx->tmp);
  return 0;
}

Json SizesJson(const Context& ctx) {
  const Sizes& sizes = ctx.sizes;
  return {{"quick", ctx.quick},
          {"sizes",
           {{"indoor_s", sizes.indoor_s},
            {"render_vo_s", sizes.render_vo_s},
            {"indoor_camera_s", sizes.indoor_camera_s},
            {"ceres_drive_s", sizes.peer_drive_s},
            {"tracking_windows", sizes.windows},
            {"calibration_drives_s", sizes.calibration_s},
            {"online_run_s", sizes.online_s},
            {"montecarlo_drive_s", sizes.montecarlo_drive_s},
            {"montecarlo_runs", {sizes.montecarlo_runs_jobs1, sizes.montecarlo_runs_jobs2}},
            {"import_mb", sizes.import_mb}}}};
}

// Every step in order; 0 or the exit code of the first failure.
int RunSteps(const Context& ctx, Json* j) {
  if (int code = BenchImport(ctx, j)) return code;
  recording::Recording rec;
  if (int code = BenchSimulation(ctx, j, &rec)) return code;
  BenchCgp(j);
  if (int code = BenchIndoorCamera(ctx, j)) return code;
  if (int code = BenchReplay(ctx, rec, j)) return code;
  TrackingCalibration peer, calibrated;
  if (int code = BenchCeresPeer(ctx, rec, j, &peer)) return code;
  std::string calibration_json;
  if (int code = CalibrateForTracking(ctx, rec, &calibrated, &calibration_json)) return code;
  if (int code = BenchTracking(ctx, rec, calibrated, peer, j)) return code;
  if (int code = BenchCalibrationScaling(ctx, rec, j)) return code;
  if (int code = BenchOnlineMemory(ctx, calibration_json, j)) return code;
  return BenchMonteCarlo(ctx, calibration_json, j);
}

}  // namespace
}  // namespace roamlab::bench

int main(int argc, char** argv) {
  namespace bench = roamlab::bench;
  if (argc == 5 && std::strcmp(argv[1], "--child-calibrate") == 0)
    return bench::ChildCalibrate(argv[2], argv[3], argv[4]);
  if (argc == 6 && std::strcmp(argv[1], "--child-track") == 0)
    return bench::ChildTrack(argv[2], argv[3], argv[4], argv[5]);
  bool quick = false;
  std::string json_path;
  if (!bench::ParseArguments(argc, argv, &quick, &json_path)) {
    std::fprintf(stderr, "usage: roamlab_bench [--quick] [--json OUT.json]\n");
    return 2;
  }
  bench::Context ctx;
  if (int code = bench::MakeContext(quick, &ctx)) return code;
  bench::Json j = bench::SizesJson(ctx);
  bench::Say("roamlab_bench on %u cores%s\n", std::thread::hardware_concurrency(), quick ? " (--quick)" : "");
  if (int code = bench::RunSteps(ctx, &j)) return code;
  std::filesystem::remove_all(ctx.tmp);
  if (!json_path.empty())
    if (const roamlab::Status s = roamlab::WriteFileAtomic(json_path, j.dump(2) + "\n"); !s.ok()) {
      std::fprintf(stderr, "roamlab_bench: %s\n", s.message().c_str());
      return 1;
    }
  return 0;
}
