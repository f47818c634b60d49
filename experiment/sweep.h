// Parameter sweeps (`roamlab sweep SWEEP.yaml --out DIR`): Monte-Carlo points over scenario and estimator keys.
//
//   scenario: ../scenarios/atv_hills_sines.yaml   # the base files, relative to SWEEP.yaml
//   config: ../configs/atv_tracking.yaml
//   calibration: cal/calibration.json             # optional, as montecarlo --calibration
//   seeds: 20                                     # Monte-Carlo runs per point (noise seeds seed_base + i)
//   seed_base: 1000                               # optional (default 1000)
//   t0_s: 2.0                                     # optional, as montecarlo --t0 (default 2)
//   no_time_budget: true                          # optional, as montecarlo --no-time-budget (default false)
//   calibrate_each_run: false                     # optional, as montecarlo --calibrate-each-run
//   grid:                                         # every combination, the first key varying slowest ...
//     scenario.sensors.gps.sigma_m: [0.1, 0.33, 1.0]
//     config.tracking.window: [10, 20, 40, 80]
//   # list:                                       # ... or the points one by one (each names every key)
//   #   - {scenario.sensors.gps.sigma_m: 0.1, config.tracking.window: 10}
//
// A key is `scenario.` or `config.` and the dotted path of a key that exists in that file; a value is any YAML value
// (a number, a list) and replaces the file's. Point p's files are OUT/points/NNN/scenario.yaml and config.yaml (the
// base files with the point's values; the model file and tracking.calibrate made absolute), and its Monte-Carlo writes
// OUT/points/NNN/ as `roamlab montecarlo` does (experiment/montecarlo.h). The summary: OUT/sweep.json ({"keys",
// "seeds", "points": [{"point", "values": {key: value}, "dir", "fraction_in_band", "mean_nees", "ate_m", "rpe_m",
// "track_seconds"}]}: the point's in-band fraction and the mean over its runs of each run's mean NEES, ATE, RPE and
// tracking time), OUT/table.csv (one row per point, the same columns), OUT/plots/METRIC_vs_KEY.png (each metric
// against each key, one line per value of the other keys) and OUT/report.html.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "common/status.h"
#include "experiment/montecarlo.h"
#include "experiment/steps.h"

namespace roamlab::experiment {

struct SweepPlan {
  std::string out;
  std::vector<std::string> keys;                 // "scenario.sensors.gps.sigma_m", ...
  std::vector<std::vector<std::string>> values;  // per point, per key: the value as YAML text ("0.1", "[1, 0]")
  // The Monte-Carlo of every point: scenario and config the base files; runs the seeds per point.
  MonteCarloOptions montecarlo;
};

// Reads SWEEP.yaml. Bad input names the file and the key.
Result<SweepPlan> ReadSweep(const std::string& file, const std::string& out);

// Writes every point's scenario and configuration. Bad input names the base file and the key it lacks.
Status WriteSweepPoints(const SweepPlan& plan);

// Point p's Monte-Carlo: OUT/points/NNN with the point's files.
MonteCarloOptions SweepPointOptions(const SweepPlan& plan, int p);

// Reads every point's summary and writes sweep.json, table.csv, the plots and report.html; `headline` receives the
// one-line result. A point without its summary is an error naming it.
Outcome WriteSweepSummary(const SweepPlan& plan, std::string* headline);

// The local backend: writes the points' files, runs every point's Monte-Carlo on `jobs` threads (with `resume`, only
// the runs without a result file), then the summary. `log` (optional) receives a line per point, `progress`
// (optional) the runs finished over all points after each run.
Outcome RunSweep(const SweepPlan& plan, bool resume, int jobs, const std::function<void(const std::string&)>& log,
                 const std::function<void(int finished, int runs)>& progress, std::string* headline);

}  // namespace roamlab::experiment
