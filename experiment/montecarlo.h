// Monte-Carlo consistency of online tracking over noise realizations (seed 000, Section V, Fig. 4).
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "eval/nees.h"
#include "experiment/steps.h"

namespace roamlab::experiment {

// Run i's calibration drive simulates with noise seed seed_base + kCalibrationSeedOffset + i.
inline constexpr unsigned long long kCalibrationSeedOffset = 1000000;

struct MonteCarloOptions {
  std::string scenario;
  std::string config;
  std::string calibration;  // optional calibration.json: tracking uses its values
  std::string out;
  int runs = 50;
  int jobs = 0;                         // 0: one per core
  unsigned long long seed_base = 1000;  // run i simulates with noise seed seed_base + i
  double t0_s = 2.0;                    // fraction_in_band counts time steps from t0_s on
  bool no_time_budget = false;  // ignore tracking.time_budget_s: results that do not depend on the machine's speed
  // With tracking.calibrate and no calibration file: one calibration per run on its own calibration drive instead of
  // one shared by every run (the seed's protocol; see RunMonteCarlo).
  bool calibrate_each_run = false;
  std::function<void(const std::string& line)> log;      // optional: what is being done, one line at a time
  std::function<void(int finished, int runs)> progress;  // optional: after each run

  // What is wrong with the options ("--runs must be at least 1"), "" when nothing.
  std::string Validate() const;
};

struct MonteCarloSummary {
  eval::MonteCarloNees nees;
  std::string plot_note;  // "" or why OUT/nees.png (or OUT/report.html) was not written, as " (...)"
};

// Simulates `runs` noise realizations of the scenario (the terrain and the drive stay the same), tracks each online,
// computes the position NEES (eq. 16) of every pose against the truth, and writes OUT/nees.json
// ({"runs", "dof", "band", "t", "mean_nees", "fraction_in_band", ...}), OUT/runs.json (per-run ATE and mean NEES),
// OUT/nees.png and OUT/report.html (the in-band fraction, the per-run table and the figure on one page). Runs are
// spread over `jobs` threads; results do not depend on the number of jobs. Calibration (the configuration's
// tracking.calibrate, when no calibration file is given): by default one calibration of the scenario simulated with its
// own noise seed, shared by every run (the seed's protocol). Its error is then one draw common to all runs, so the
// average NEES tests that draw as much as the tracker (the band assumes independent runs). With calibrate_each_run, run
// i also simulates a calibration drive of its own (noise seed seed_base + kCalibrationSeedOffset + i), calibrates it
// (warm-started at the shared calibration, a single stage with every parameter free: the same minimum, fewer
// iterations) and tracks with those values under that calibration's prior: every random input of the run is its own.
Outcome RunMonteCarlo(const MonteCarloOptions& options, MonteCarloSummary* summary = nullptr);

}  // namespace roamlab::experiment
