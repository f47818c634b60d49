#include "apps/simulate.h"

#include <cmath>
#include <cstdio>
#include <iostream>

#include "apps/cli.h"
#include "common/progress.h"
#include "experiment/steps.h"

namespace roamlab::apps {
namespace {

constexpr double kDegPerRad = 180.0 / 3.14159265358979323846;

void PrintSummary(const sim::Simulation& s, const std::string& out) {
  const sim::SimulationStats& st = s.stats;
  for (const std::string& warning : st.warnings) std::cerr << "simulate: MuJoCo warning: " << warning << "\n";
  std::printf("simulated %.1f s (%ld steps) in %.2f s: %.1fx real time\n", st.simulated_s, st.physics_steps, st.wall_s,
              st.realtime_factor);
  std::printf(
      "drive: %.1f m, |pitch| <= %.1f deg, |roll| <= %.1f deg, height range %.2f m (terrain relief %.2f m), "
      "side slip <= %.2f m/s, wheel slip <= %.2f m/s\n",
      st.distance_m, st.max_abs_pitch_rad * kDegPerRad, st.max_abs_roll_rad * kDegPerRad, st.path_height_range_m,
      st.terrain_relief_m, st.max_lateral_speed_mps, st.max_wheel_slip_mps);
  for (const std::string& fault : st.faults) std::printf("fault: %s\n", fault.c_str());
  if (st.failed_scan_matches > 0) std::printf("scan matcher: %d scan pairs not matched\n", st.failed_scan_matches);
  if (const auto& vo = st.visual_odometry) {
    std::printf(
        "visual odometry: %d frames, %d pairs, %d estimates, %d failures (features %d, tracks %d, inliers "
        "%d, scale %d); camera %.4f m above the floor\n",
        vo->frames, vo->pairs, vo->estimates, vo->failures, vo->too_few_features, vo->too_few_tracks,
        vo->too_few_inliers, vo->no_scale, st.camera_height_m);
  }
  std::printf("wrote %s (seed %llu): %zu streams, ground_truth.tum, truth.yaml\n", out.c_str(),
              static_cast<unsigned long long>(*s.recording.provenance.seed), s.recording.streams.size());
}

// The replay's summary: speed, the twin's streams and those left out.
void PrintReplaySummary(const sim::Simulation& s, const std::string& out) {
  const sim::SimulationStats& st = s.stats;
  for (const std::string& warning : st.warnings) std::cerr << "replay: MuJoCo warning: " << warning << "\n";
  std::printf("replayed %.1f s (%ld steps) in %.2f s: %.1fx real time\n", st.simulated_s, st.physics_steps, st.wall_s,
              st.realtime_factor);
  if (s.truth.replay)
    std::printf("drive: %s; start: %s; %.1f m\n", s.truth.replay->drive.c_str(), s.truth.replay->start.c_str(),
                st.distance_m);
  for (const std::string& why : st.left_out) std::printf("left out: %s\n", why.c_str());
  std::printf("wrote %s: %zu streams, ground_truth.tum, truth.yaml (noise-free twin)\n", out.c_str(),
              s.recording.streams.size());
}

}  // namespace

int RunReplay(const ReplayArgs& args) {
  experiment::ReplayRequest request = args;
  ProgressMeter meter("replay", &std::cerr);
  if (!args.quiet) request.progress = [&meter](double fraction) { meter.Update(fraction); };
  sim::Simulation simulation;
  const experiment::Outcome outcome = experiment::ReplayToDirectory(request, &simulation);
  meter.Finish();
  if (!outcome.ok()) return Exit(args.err, "replay", outcome);
  if (!args.quiet) PrintReplaySummary(simulation, args.out);
  return 0;
}

int RunSimulate(const SimulateArgs& args) {
  experiment::SimulateRequest request = args;
  ProgressMeter meter("simulate", &std::cerr);
  if (!args.quiet) request.progress = [&meter](double fraction) { meter.Update(fraction); };
  sim::Simulation simulation;
  const experiment::Outcome outcome = experiment::SimulateToDirectory(request, &simulation);
  meter.Finish();
  if (!outcome.ok()) return Exit(args.err, "simulate", outcome);
  if (!args.quiet) PrintSummary(simulation, args.out);
  return 0;
}

}  // namespace roamlab::apps
