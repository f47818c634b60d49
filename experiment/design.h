// The step of `roamlab design`: an Ackermann drive chosen so that every calibration parameter is calibrated to its
// target (docs/methods-information.md, the design section).
//
// The family: the speed set-point v(t) = v_mean + v_swing cos(4 pi t / P) and the handlebar
// delta(t) = delta_offset + delta_amp sin(2 pi t / P) (one weave of period P: the vehicle is slowest where the
// handlebar is turned most), and the start heading. The terrain, the start position and the sensors stay the
// scenario's. The objective of a drive: max over the free parameters' tangent components of CRB std / target (the
// Cramer-Rao bound of estimator/information.h on the noise-free drive, at its truth). A drive is feasible when it
// simulates (it neither leaves the terrain nor rolls over) within the roll, pitch, side-slip and lateral-acceleration
// limits. The search: the scenario's own drive (mapped into the family), a coarse grid of headings and handlebar
// offsets, then a pattern search over the six normalized coordinates, within an evaluation budget.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "experiment/steps.h"
#include "sim/scenario.h"

namespace roamlab::experiment {

// One drive of the family (the header comment).
struct DriveDesign {
  double speed_mean_mps = 3.5;
  double speed_swing_mps = 0.0;  // amplitude of the cos(4 pi t / P) term
  double handlebar_amplitude_rad = 0.0;
  double handlebar_period_s = 10.0;  // P
  double handlebar_offset_rad = 0.0;
  double heading_deg = 0.0;  // start heading, from east counter-clockwise
};

// The bounds of the family and the feasibility limits.
struct DesignLimits {
  double min_speed_mps = 1.5;  // the set-point stays in [min, max]
  double max_speed_mps = 6.0;
  double max_handlebar_rad = 0.45;  // |offset| + amplitude
  double min_period_s = 5.0;        // P
  double max_period_s = 30.0;
  double max_roll_deg = 25.0;  // of O, over the recording
  double max_pitch_deg = 25.0;
  double max_side_slip_mps = 0.3;       // max |v_y| of O (sim::SimulationStats)
  double max_lateral_accel_mps2 = 4.4;  // max speed x |yaw rate| of O over 0.1 s steps (0.45 g)
  // Empty when valid, otherwise "--option: problem".
  std::string Validate() const;
};

struct DesignRequest {
  std::string scenario;                   // SCENARIO.yaml, driver type ackermann
  std::string config;                     // EST.yaml
  std::string out;                        // DESIGNED.yaml; design.json is written beside it
  double duration_s = 0.0;                // the designed drive's recorded duration; 0: the scenario's
  std::map<std::string, double> targets;  // free parameter -> target CRB std of each of its tangent components
  DesignLimits limits;
  int budget = 60;                                // drives simulated and analysed, at least 1
  std::function<void(double fraction)> progress;  // optional: the budget's fraction spent
};

// One drive tried.
struct DesignCandidate {
  DriveDesign drive;
  std::string stage;                                    // "start", "grid" or "pattern"
  std::string infeasible;                               // why the drive is not feasible; empty when feasible
  double objective = 0.0;                               // max CRB std / target; +inf when infeasible
  std::string worst;                                    // the component that sets the objective
  std::vector<std::pair<std::string, double>> crb_std;  // per component label (empty when infeasible)
  double max_roll_deg = 0.0, max_pitch_deg = 0.0, max_side_slip_mps = 0.0, max_lateral_accel_mps2 = 0.0;
  double distance_m = 0.0;
  double seconds = 0.0;  // wall time of the evaluation
};

struct DesignResult {
  std::vector<DesignCandidate> candidates;  // in the order tried
  double duration_s = 0.0;                  // of the designed drive [s]
  int best = -1;                            // index of the feasible candidate with the least objective; -1: none
  std::string designed_yaml;                // the text written to DESIGNED.yaml
};

// The scenario with `drive` as its driver and start heading (the values as written).
sim::Scenario WithDrive(const sim::Scenario& scenario, const DriveDesign& drive);
// The scenario's own drive mapped into the family (its constant and first sine terms), clamped to `limits`.
DriveDesign StartDrive(const sim::Scenario& scenario, const DesignLimits& limits);

// Bad input: a scenario or configuration that does not load, a scenario whose driver is not ackermann, a target that
// is not a free parameter of the configuration or not > 0, no target, invalid limits, a duration or budget out of
// range, a configuration that does not fit the simulated recording. Failures: no feasible drive, writing the files.
Outcome DesignToFile(const DesignRequest& request, DesignResult* result = nullptr);

// design.json (docs/commands.md): the request, every candidate and the chosen one.
nlohmann::json DesignJson(const DesignRequest& request, const DesignResult& result);

}  // namespace roamlab::experiment
