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
// its diagnosis as `roamlab diagnose` writes it in OUT/.../NNN/gap.json, then OUT/score.json (figures against the
// benchmark's targets, thresholds, calibration, per-case table: the same bytes for the same options however the cases
// were run) and OUT/timings.json (how long the parts and each case took).
// The cases can also be run one by one (a Slurm task each, batch/work.h): case k of the benchmark is calibration case k
// when k < C, else scored case k - C; a scored case needs every calibration case's case.json (its thresholds are
// chosen on them); ScoreFromCaseFiles then writes the score from the case.json files alone.
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
  // temporary name then renamed); score.json is then the uninterrupted call's.
  bool resume = false;
};

// The three platforms (atv, diffdrive, mecanum), in that order. Errors name the scenario file.
Result<std::vector<Platform>> LoadPlatforms(const BenchmarkOptions& options);

// score.json's and timings.json's content.
struct BenchmarkResult {
  nlohmann::json score;
  nlohmann::json timings;
};

// Learns the platforms' baselines, runs the calibration and the scored cases and returns the score. `progress` (null:
// quiet) receives the progress bars, one line per case and the chosen thresholds. Errors: a case or a baseline failed.
Result<BenchmarkResult> RunBenchmark(const BenchmarkOptions& options, std::vector<Platform> platforms,
                                     std::ostream* progress);

// Writes OUT/score.json and OUT/timings.json.
Status WriteBenchmarkResult(const std::string& out, const BenchmarkResult& result);

// The cases one by one: C + N of them (calibration then scored), case k's directory (its case.json marks it done),
// its one-line name, and the platforms (indices into LoadPlatforms') cases [first, last) are drawn on.
int CaseCount(const BenchmarkOptions& options);
std::string CaseDirectory(const BenchmarkOptions& options, int k);
std::string CaseName(const BenchmarkOptions& options, int k);
std::vector<int> PlatformsOfCases(const BenchmarkOptions& options, int first, int last);

// Learns the baselines of the platforms `which` (the others keep theirs), one after the other.
Status LearnBaselines(std::vector<Platform>* platforms, const std::vector<int>& which);

// The thresholds the scored cases are diagnosed with, chosen on the calibration cases' case.json files (an error
// names a missing or unreadable one).
Result<Thresholds> ScoredThresholds(const BenchmarkOptions& options);

// Runs case k (its platform's baseline learned; `scored` the thresholds of a scored case) and writes its files.
Status RunOneCase(const BenchmarkOptions& options, const std::vector<Platform>& platforms, int k,
                  const Thresholds& scored);

// The score from every case's case.json (an error names a missing or unreadable one); the same score.json as
// RunBenchmark's, and timings.json with each case's seconds only.
Result<BenchmarkResult> ScoreFromCaseFiles(const BenchmarkOptions& options, const std::vector<Platform>& platforms);

}  // namespace roamlab::gap::benchmark
