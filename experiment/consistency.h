// Calibration consistency over noise realizations (`roamlab montecarlo --calibration-consistency`): N seeded
// realizations of a scenario, each calibrated and compared with its truth; per parameter the statistics of
// eval/calibration_consistency.h, with the Cramer-Rao std as the efficiency's reference.
//
// Run i simulates the scenario with noise seed seed_base + i (montecarlo's seed derivation) and, with
// terrain_seed_base set, on the scenario's hills redrawn with terrain seed terrain_seed_base + i
// (experiment/terrain_redraw.h), so that the statistics cover the terrain's variation too; it calibrates the recording
// with the configuration (every stage, from the configured initial values; the estimator never sees the truth) and
// writes OUT/calibrations/NNNNNN.json; only then is the calibration compared with the simulation's truth (what
// truth.yaml holds). The reported block covariance of a parameter is its block of the inverse of the calibration's
// joint marginal information, rescaled to the reported std (the same when the std is the white one).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "estimator/config.h"
#include "eval/calibration_consistency.h"
#include "experiment/montecarlo.h"
#include "sim/scenario.h"

namespace roamlab::experiment {

// The calibration of the scenario simulated with every noise source off, per free parameter (by name): the std it
// reports, which is the Cramer-Rao bound of the configured noise, and its error against the truth (tangent), what the
// physics the configuration does not model leaves: a bias every noisy realization of the same drive shares.
struct NoiseFreeCalibration {
  std::map<std::string, Eigen::VectorXd> std;
  std::map<std::string, Eigen::VectorXd> error;
};
Result<NoiseFreeCalibration> CalibrateWithoutNoise(const sim::Scenario& scenario,
                                                   const estimator::EstimatorConfig& config);

// The standard deviation each free parameter's tangent components can reach on the scenario's drive, by name: the
// noise-free calibration's std. One function so that another computation of the bound can replace it.
Result<std::map<std::string, Eigen::VectorXd>> CramerRaoStd(const NoiseFreeCalibration& noise_free);

// Run i's result file, OUT/calibrations/NNNNNN.json (six digits): {"run", "seed", "terrain_seed" (when the terrain is
// redrawn), "seconds" (calibration time), "drive" (the simulation's statistics, sim/simulator.h: "distance_m",
// "path_height_range_m", "max_abs_roll_rad", "max_abs_pitch_rad", "max_lateral_speed_mps", "max_wheel_slip_mps"; for
// the evaluation, the calibration never sees them), "parameters": {NAME: {"manifold", "truth", "estimate", "error"
// (tangent, eval/parameters.h), "std", "covariance" (tangent, row-major)}}}, NaN as null. A run that failed on its
// redrawn terrain: {"run", "seed", "terrain_seed", "failed": the reason}.
std::string ConsistencyRunFile(const std::string& out, int i);

// A run whose drive or calibration failed on its redrawn terrain (a rollover, the vehicle off the terrain, a diverged
// simulation or calibration): counted and named, never dropped silently.
struct FailedRun {
  int run = 0;
  std::uint64_t seed = 0;  // noise
  std::uint64_t terrain_seed = 0;
  std::string reason;  // "simulation: ..." or "calibration: ...", one line
};

struct ConsistencySummary {
  std::vector<eval::BlockConsistency> blocks;  // one per calibrated parameter, by name, over the calibrated runs
  std::vector<FailedRun> failed_runs;          // in run order
  std::string plot_note;                       // "" or why OUT/consistency.png was not drawn, as " (...)"
};

// Uses options.scenario, config (the calibration configuration), out, runs, jobs, seed_base, resume (runs whose
// result file exists are not run again), log and progress. Calibrates the noise-free recording (the Cramer-Rao std and
// each component's noise-free error), runs the calibrations over
// `jobs` threads (the result does not depend on it), then writes OUT/consistency.json ({"scenario", "config",
// "runs", "seed_base", "terrain_seed_base" (null when not redrawn), "cramer_rao": how the bound was computed,
// "calibrated_runs": the runs the statistics cover, in the order of each block's per-run NEES, "failed_runs":
// [{"run", "seed", "terrain_seed", "reason"}], "parameters": eval::ConsistencyJson}) and
// OUT/consistency.png (the normalized errors error / std of every run per component with the +-2 band, and the
// coverage of the 1, 2, 3 sigma intervals against their nominal shares). With the terrain redrawn, a run whose
// simulation or calibration fails is a failed run (summary.failed_runs) and the statistics cover the others; the call
// fails when every run failed. Otherwise a failed run does not stop the others, and the call then fails naming the
// first and writes no summary. The Cramer-Rao std and the noise-free error are those of the scenario's own terrain.
// Bad input: a scenario or configuration that does not load, a configuration with no free parameter, a terrain to
// redraw that is flat. A free parameter the scenario's truth has no value for fails the call.
Outcome RunCalibrationConsistency(const MonteCarloOptions& options, ConsistencySummary* summary = nullptr);

}  // namespace roamlab::experiment
