// The blind benchmark of the reality-gap diagnosis (`roamlab gap-benchmark`). Each case draws a platform (the ATV, the
// differential drive or the mecanum robot), a noise seed and a hidden effect: none, a decoy outside the diagnosis's
// candidates, or one candidate effect with a random magnitude (gap/benchmark/cases.h); it simulates the "real"
// recording (truth.yaml included), diagnoses the written recording against the nominal scenario (baseline learned once
// per platform from a seed no case uses) and only then reads truth.yaml to score.
//   1. calibration: C cases from their own seed range (draws seeded S * 1000 + 500, noise seeds S * 1000 + 500 + i),
//      stratified (a quarter none, a quarter decoys, the rest effects: CalibrationKind), are diagnosed with the
//      loosest thresholds, the held-out part evaluated for every candidate passing them; the decision thresholds
//      (alpha, Delta BIC, held-out drop, share of the held-out mismatch explained) are chosen on them
//      (gap/benchmark/score.h), and so is each candidate parameter's noise (the median reported std);
//   2. scored: N cases (draws seeded S, noise seeds S * 1000 + i) diagnosed with the chosen thresholds.
// With BenchmarkOptions::other_drive, a share of the cases of both phases drives its "real" recording by another
// schedule than the nominal scenario's (Draw::other_drive): the diagnosis (estimator-side) is unchanged, and the
// re-simulation detects the other drive and replays it (gap/resimulate.h ChooseTwin); score.json's figures give both
// drives' cases apart ("by_drive").
// Both phases judge a case by one rule (Identified / FalseDiscovery): a none or decoy case that keeps any library
// effect is a false discovery, whatever the verdict.
// Writes the recordings in OUT/calibration/NNN/rec and OUT/cases/NNN/rec, each case's row in OUT/.../NNN/case.json and
// its diagnosis as `roamlab diagnose` writes it in OUT/.../NNN/gap.json; returns score.json's content (figures against
// the benchmark's targets, thresholds, per-case table, seconds).
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/status.h"
#include "gap/benchmark/cases.h"

namespace roamlab::gap::benchmark {

inline constexpr int kMaxCases = 500;  // per phase: the calibration seeds start 500 after the scored ones

struct BenchmarkOptions {
  int cases = 16;             // scored cases, in [1, kMaxCases]
  int calibration_cases = 8;  // in [1, kMaxCases]
  std::uint64_t seed = 1;
  int jobs = 2;  // cases run in parallel
  // The fraction of the cases (each phase) whose "real" recording is driven by another schedule (Draw::other_drive):
  // drawn per case from its own random numbers (seeded by the phase's draw seed), so the cases' other draws do not
  // depend on it.
  double other_drive = 0.5;
  double duration_s = 0.0;  // 0: the scenarios' own
  std::string atv_scenario = "scenarios/atv_hills_sines.yaml";
  std::string diffdrive_scenario = "scenarios/indoor_diffdrive_gap.yaml";
  std::string mecanum_scenario = "scenarios/indoor_mecanum_gap.yaml";
  std::string out;  // output directory (exists)
  // Cases whose OUT/.../NNN/case.json exists are read back instead of run again (case.json is written last, under a
  // temporary name then renamed); score.json is then the uninterrupted call's but for the timings.
  bool resume = false;
};

// The three platforms (atv, diffdrive, mecanum), in that order. Errors name the scenario file.
Result<std::vector<Platform>> LoadPlatforms(const BenchmarkOptions& options);

// Learns the platforms' baselines, runs the calibration and the scored cases and returns score.json's content.
// `progress` (null: quiet) receives the progress bars, one line per case and the chosen thresholds. Errors: a case or
// a baseline failed.
Result<nlohmann::json> RunBenchmark(const BenchmarkOptions& options, std::vector<Platform> platforms,
                                    std::ostream* progress);

}  // namespace roamlab::gap::benchmark
