// The step of `roamlab information`: the Cramer-Rao bound of a scenario's calibration and where its information comes
// from (estimator/information.h, docs/methods-information.md). The scenario is simulated with every sensor noise off
// and analysed at its truth; the figure shows each component's share per time window above the drive.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "estimator/information.h"
#include "experiment/steps.h"

namespace roamlab::experiment {

struct InformationRequest {
  std::string scenario;  // SCENARIO.yaml
  std::string config;    // EST.yaml
  std::string out;       // receives information.json and the figure information.png (with its .gp and .dat files)
  double window_s = 1.0;
  std::function<void(double fraction)> progress;  // optional: the simulation's fraction done
};

// The drive along the windows, from the true poses: means over each window.
struct WindowDrive {
  double begin_s = 0.0, end_s = 0.0;  // since the first pose
  double speed_mps = 0.0;             // mean |velocity of O|
  double yaw_rate_radps = 0.0;        // mean |omega_z| of O
  double pitch_deg = 0.0;             // mean pitch of O's x axis above the horizontal
};

struct InformationRun {
  estimator::InformationResult result;
  std::vector<WindowDrive> windows;
  std::string plot_warning;  // why the figure was not drawn (gnuplot missing or failing), else empty
};

// Bad input: a scenario or configuration that does not load, a window that is not > 0, a configuration that does not
// fit the simulated recording, an output directory that cannot be made. Failures: the simulation, the analysis,
// writing information.json. `run` (optional) receives the result.
Outcome InformationToDirectory(const InformationRequest& request, InformationRun* run = nullptr);

// information.json (docs/commands.md): per parameter its truth and per component the CRB std, observability and the
// shares by stream, by window and by stream and window; the windows with the drive; the weak and unobservable
// directions.
nlohmann::json InformationJson(const InformationRequest& request, const InformationRun& run);

}  // namespace roamlab::experiment
