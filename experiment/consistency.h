// Calibration consistency over noise realizations (`roamlab montecarlo --calibration-consistency`): N seeded
// realizations of a scenario, each calibrated and compared with its truth; per parameter the statistics of
// eval/calibration_consistency.h, with the Cramer-Rao std as the efficiency's reference.
//
// Run i simulates the scenario with noise seed seed_base + i (montecarlo's seed derivation), calibrates the recording
// with the configuration (every stage, from the configured initial values; the estimator never sees the truth) and
// writes OUT/calibrations/NNNNNN.json; only then is the calibration compared with the simulation's truth (what
// truth.yaml holds). The reported block covariance of a parameter is its block of the inverse of the calibration's
// joint marginal information, rescaled to the reported std (the same when the std is the white one).
#pragma once

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

// Run i's result file, OUT/calibrations/NNNNNN.json (six digits): {"run", "seed", "seconds" (calibration time),
// "parameters": {NAME: {"manifold", "truth", "estimate", "error" (tangent, eval/parameters.h), "std",
// "covariance" (tangent, row-major)}}}, NaN as null.
std::string ConsistencyRunFile(const std::string& out, int i);

struct ConsistencySummary {
  std::vector<eval::BlockConsistency> blocks;  // one per calibrated parameter, by name
  std::string plot_note;                       // "" or why OUT/consistency.png was not drawn, as " (...)"
};

// Uses options.scenario, config (the calibration configuration), out, runs, jobs, seed_base, resume (runs whose
// result file exists are not run again), log and progress. Calibrates the noise-free recording (the Cramer-Rao std and
// each component's noise-free error), runs the calibrations over
// `jobs` threads (the result does not depend on it), then writes OUT/consistency.json ({"scenario", "config",
// "runs", "seed_base", "cramer_rao": how the bound was computed, "parameters": eval::ConsistencyJson}) and
// OUT/consistency.png (the normalized errors error / std of every run per component with the +-2 band, and the
// coverage of the 1, 2, 3 sigma intervals against their nominal shares). A failed run does not stop the others; the
// call then fails naming the first and writes no summary. Bad input: a scenario or configuration that does not load,
// a configuration with no free parameter. A free parameter the scenario's truth has no value for fails the call.
Outcome RunCalibrationConsistency(const MonteCarloOptions& options, ConsistencySummary* summary = nullptr);

}  // namespace roamlab::experiment
