// `roamlab gap-benchmark --cases N --seed S --out DIR [--scenario SCENARIO.yaml]`: the blind benchmark of the
// reality-gap diagnosis (DESIGN.md). Each case draws, from seed S, one of: no effect, one effect of the diagnosis
// library with a random parameter (gps_latency, imu_time_offset, steering_offset, gyro_scale_error), or a decoy
// outside it (magnetometer_motor_interference); simulates the scenario with it (DIR/cases/NNN/rec, truth.yaml
// included), diagnoses the recording against the nominal scenario (the baseline is learned once, from a seed no case
// uses), and only then reads truth.yaml to score: none -> verdict none; effect -> named, that effect first, each
// non-neutral parameter within 3 reported standard deviations; decoy -> not named (unknown or none).
// Writes DIR/score.json: {"cases": [{"case", "truth": {"name", "parameters"}, "verdict", "named": [...],
// "parameters": {...}, "std": {...}, "correct", "why"}], "correct", "total", "by_kind": {...}, "seconds"}.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>

namespace roamlab::apps {

struct GapBenchmarkArgs {
  int cases = 5;
  std::uint64_t seed = 1;
  std::string scenario;          // default: the nominal ATV scenario given on the command line
  std::string out;
  bool quiet = false;
  std::ostream* err = nullptr;
};
int RunGapBenchmark(const GapBenchmarkArgs& args);

}  // namespace roamlab::apps
