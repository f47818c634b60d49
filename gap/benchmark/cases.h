// One case of the gap benchmark (gap/benchmark/benchmark.h): a platform, a drawn hidden effect (none, a decoy outside
// the diagnosis's library, or a library effect with a random magnitude), the "real" recording simulated with it, the
// blind diagnosis of that recording, and the score from its truth.yaml read only afterwards.
#pragma once

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "common/status.h"
#include "estimator/config.h"
#include "gap/benchmark/score.h"
#include "gap/diagnose.h"
#include "sim/scenario.h"

namespace roamlab::gap::benchmark {

// A robot of the benchmark: its nominal scenario (no effects), nominal configuration and learned baseline.
struct Platform {
  std::string name;  // atv | diffdrive | mecanum
  sim::Scenario scenario;
  estimator::EstimatorConfig config;
  Baseline baseline;
  double rear_compliance_s = 0.0;  // ATV: the nominal drive's cornering compliance, on its truth
};

// Loads the scenario at `path` (a robot of kind `kind`), its effects removed and its duration set to `duration_s`
// when that is positive, with its nominal configuration (the baseline is learned later). Errors name the file.
Result<Platform> LoadPlatform(const std::string& name, const std::string& path, const std::string& kind,
                              double duration_s);

// One drawn case: the platform, the kind and the effect hidden in its scenario (empty name: none).
struct Draw {
  int platform = 0;  // index into the platforms
  std::string kind;  // none | effect | decoy
  sim::EffectOptions effect;
  std::string parameter;     // the parameter drawn away from neutral
  bool other_drive = false;  // the "real" recording is driven by OtherDrive(driver, drive_seed)
  std::uint64_t drive_seed = 0;
};

// Another drive than `nominal`'s: every sine and square term of its profiles with its phase moved by an angle uniform
// on [0, 2 pi) (random numbers seeded by `seed`): the same kinds of speeds and turns at the same frequencies, another
// schedule.
sim::DriverOptions OtherDrive(const sim::DriverOptions& nominal, std::uint64_t seed);

// Draws which cases drive another schedule: for each of `draws`, from `rng`, a uniform number (below `fraction`:
// another drive) and the drive's seed, both drawn whatever the fraction.
void DrawDrives(std::mt19937_64& rng, double fraction, std::vector<Draw>* draws);

// Draws a case: platform 0 is the ATV (half of the cases: its library is the largest), 1 the differential drive and
// 2 the mecanum robot (a quarter each). Kinds: none 20 %, decoy 15 %, effect 65 %; or `stratum` (none, decoy or
// effect) when given (the calibration's stratified draws: the same random numbers are drawn, the kind's is overruled).
Draw DrawCase(std::mt19937_64& rng, const std::string& stratum);

// The thresholds the diagnosis is run with, and whether it evaluates every passing candidate on the held-out part.
struct CaseSetup {
  Thresholds thresholds;
  bool heldout_all = false;
};

// Simulates the case (noise seed `noise_seed`), writes the recording and its truth to dir/rec, diagnoses the written
// recording blind, writes the diagnosis as dir/gap.json, then reads truth.yaml, scores the case and writes
// dir/case.json.
Result<CaseResult> RunCase(const Platform& platform, const Draw& draw, std::uint64_t noise_seed, const std::string& id,
                           const std::string& dir, const CaseSetup& setup);

// The case's one-line summary (the progress line).
std::string CaseLine(const CaseResult& c);

}  // namespace roamlab::gap::benchmark
