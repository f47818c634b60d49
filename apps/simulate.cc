#include "apps/simulate.h"

#include <cmath>
#include <cstdio>
#include <iostream>

#include "recording/recording.h"
#include "recording/truth.h"
#include "sim/scenario.h"
#include "sim/simulator.h"

namespace roamlab::apps {
namespace {

constexpr double kDegPerRad = 180.0 / 3.14159265358979323846;

int Fail(std::ostream* err, int code, const std::string& message) {
  (err ? *err : std::cerr) << "roamlab simulate: " << message << "\n";
  return code;
}

}  // namespace

int RunSimulate(const SimulateArgs& args) {
  auto scenario = sim::LoadScenario(args.scenario);
  if (!scenario.ok()) return Fail(args.err, 2, scenario.status().message());

  // Simulate, with a progress line on stderr.
  sim::SimulateOptions options;
  options.seed = args.seed;
  options.image_directory = args.out;  // sensors.camera.store_images
  if (!args.quiet) {
    options.progress = [](double fraction) {
      std::cerr << "\rsimulate: " << static_cast<int>(100.0 * fraction) << "%" << std::flush;
    };
  }
  auto simulator = sim::Simulator::Create(scenario.value(), options);
  if (!simulator.ok()) return Fail(args.err, 2, simulator.status().message());
  auto simulation = simulator.value()->Run();
  if (!args.quiet) std::cerr << "\n";
  if (!simulation.ok()) return Fail(args.err, 1, simulation.status().message());

  // The recording and its truth.
  const sim::Simulation& s = simulation.value();
  Status status = recording::WriteRecording(s.recording, args.out);
  if (status.ok()) status = recording::WriteTruth(s.truth, args.out);
  if (!status.ok()) return Fail(args.err, 1, status.message());

  if (!args.quiet) {
    const sim::SimulationStats& st = s.stats;
    for (const std::string& warning : st.warnings) std::cerr << "simulate: MuJoCo warning: " << warning << "\n";
    std::printf("simulated %.1f s (%ld steps) in %.2f s: %.1fx real time\n", st.simulated_s, st.physics_steps,
                st.wall_s, st.realtime_factor);
    std::printf("drive: %.1f m, |pitch| <= %.1f deg, |roll| <= %.1f deg, height range %.2f m (terrain relief %.2f m), "
                "side slip <= %.2f m/s, wheel slip <= %.2f m/s\n",
                st.distance_m, st.max_abs_pitch_rad * kDegPerRad, st.max_abs_roll_rad * kDegPerRad,
                st.path_height_range_m, st.terrain_relief_m, st.max_lateral_speed_mps, st.max_wheel_slip_mps);
    if (st.failed_scan_matches > 0) std::printf("scan matcher: %d scan pairs not matched\n", st.failed_scan_matches);
    if (const auto& vo = st.visual_odometry) {
      std::printf("visual odometry: %d frames, %d pairs, %d estimates, %d failures (features %d, tracks %d, inliers "
                  "%d, scale %d); camera %.4f m above the floor\n",
                  vo->frames, vo->pairs, vo->estimates, vo->failures, vo->too_few_features, vo->too_few_tracks,
                  vo->too_few_inliers, vo->no_scale, st.camera_height_m);
    }
    std::printf("wrote %s (seed %llu): %zu streams, ground_truth.tum, truth.yaml\n", args.out.c_str(),
                static_cast<unsigned long long>(*s.recording.provenance.seed), s.recording.streams.size());
  }
  return 0;
}

}  // namespace roamlab::apps
