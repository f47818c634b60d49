// Monte-Carlo consistency of online tracking over noise realizations (seed 000, Section V, Fig. 4).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "eval/nees.h"
#include "experiment/external.h"
#include "experiment/steps.h"

namespace roamlab::experiment {

// Run i's calibration drive simulates with noise seed seed_base + kCalibrationSeedOffset + i.
inline constexpr unsigned long long kCalibrationSeedOffset = 1000000;

struct MonteCarloOptions {
  std::string scenario;
  std::string config;
  // Or, instead of `config`, an external estimator under test (experiment/external.h): run i's recording (without
  // the truth) is written to OUT/runs/NNNNNN/recording, the command writes OUT/runs/NNNNNN/estimate (its output in
  // OUT/runs/NNNNNN/estimator.log); the recording is removed once the run succeeded. Its poses are paired with the
  // truth poses of the same stamp; the NEES needs its covariance.csv (all runs or none: without, no NEES).
  ExternalCommand command;
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
  // Runs whose result file (MonteCarloRunFile) exists are not run again, and the shared calibration an earlier call
  // wrote to OUT/calibration/calibration.json is read instead of calibrating again: the summary is the one an
  // uninterrupted call writes.
  bool resume = false;
  // Calibrate each run's recording with `config` (a calibration configuration) instead of tracking it, and test the
  // calibration's reported std against its errors (experiment/consistency.h, RunCalibrationConsistency).
  bool calibration_consistency = false;
  // With calibration_consistency: run i also drives a terrain of its own, the scenario's hills drawn with terrain seed
  // terrain_seed_base + i (experiment/terrain_redraw.h); unset: every run drives the scenario's terrain.
  std::optional<unsigned long long> terrain_seed_base;
  std::function<void(const std::string& line)> log;      // optional: what is being done, one line at a time
  std::function<void(int finished, int runs)> progress;  // optional: once with 0 before the runs, then after each run

  // What is wrong with the options ("--runs must be at least 1"), "" when nothing.
  std::string Validate() const;
  bool external() const { return !command.command.empty(); }
};

struct MonteCarloSummary {
  eval::MonteCarloNees nees;
  bool has_nees = true;  // false when an external estimator wrote no covariance.csv: no nees.json, `nees` unset
  std::string plot_note;  // "" or why OUT/nees.png (or OUT/report.html) was not written, as " (...)"
};

// Run i's result file, OUT/runs/NNNNNN.json (six digits): {"run", "seed", "ate_m", "mean_nees", "rpe_m" (translation
// RMSE of the RPE over pose pairs about 1 s apart [m]), "track_seconds" (an external estimator's: its command's wall
// time), "covariance" (false: no NEES), "t_ns": [...], "nees": [...]} (a NEES that is not finite as null), written
// under a temporary name and renamed.
std::string MonteCarloRunFile(const std::string& out, int i);

// The inputs every run shares: scenario, configurations and calibration.
struct MonteCarloShared;

// Reads the shared inputs and, with tracking.calibrate and no calibration file, calibrates once into OUT/calibration
// (with `resume`, reads the calibration an earlier call wrote there when it exists).
Outcome PrepareMonteCarlo(const MonteCarloOptions& options, std::shared_ptr<const MonteCarloShared>* shared);
// Runs run i (0 <= i < runs) and writes its result file; a failed run writes none. Safe to call from several threads.
Outcome RunMonteCarloRun(const MonteCarloOptions& options, const MonteCarloShared& shared, int i);
// Runs run(i) for each i of `todo` over `jobs` threads (0: one per core), calling progress(finished, total) once
// with 0 and after each run; no new run starts once an interrupt is requested (common/interrupt.h). Each run writes
// its own result, so nothing depends on scheduling. A failed run does not stop the others; the outcome then says how
// many failed and carries the first (lowest in `todo`) failure.
Outcome RunSpread(const std::vector<int>& todo, int jobs, const std::function<void(int finished, int total)>& progress,
                  const std::function<Outcome(int i)>& run);
// The runs in [0, runs) whose result file does not exist, in increasing order.
std::vector<int> MissingMonteCarloRuns(const MonteCarloOptions& options);
// Reads every run's result file and writes the summaries (nees.json, runs.json, nees.png, report.html): the same
// bytes whichever process or host ran each run. A missing or malformed result file is an error naming it.
Outcome AggregateMonteCarlo(const MonteCarloOptions& options, MonteCarloSummary* summary = nullptr);

// Simulates `runs` noise realizations of the scenario (the terrain and the drive stay the same), tracks each online,
// computes the position NEES (eq. 16) of every pose against the truth, writes each run's result file and from them
// OUT/nees.json
// ({"runs", "dof", "band", "t", "mean_nees", "fraction_in_band", ...}), OUT/runs.json (per-run ATE, mean NEES, RPE
// and tracking time),
// OUT/nees.png and OUT/report.html (the in-band fraction, the per-run table and the figure on one page). Runs are
// spread over `jobs` threads; results do not depend on the number of jobs. A run that fails does not stop the others;
// the call then fails naming the first failed run and writes no summary. Calibration (the configuration's
// tracking.calibrate, when no calibration file is given): by default one calibration of the scenario simulated with its
// own noise seed, shared by every run (the seed's protocol). Its error is then one draw common to all runs, so the
// average NEES tests that draw as much as the tracker (the band assumes independent runs). With calibrate_each_run, run
// i also simulates a calibration drive of its own (noise seed seed_base + kCalibrationSeedOffset + i), calibrates it
// (warm-started at the shared calibration, a single stage with every parameter free: the same minimum, fewer
// iterations) and tracks with those values under that calibration's prior: every random input of the run is its own.
Outcome RunMonteCarlo(const MonteCarloOptions& options, MonteCarloSummary* summary = nullptr);

}  // namespace roamlab::experiment
