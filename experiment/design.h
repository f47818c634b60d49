// The step of `roamlab design`: a drive chosen so that every calibration parameter is calibrated to its target
// (docs/methods-information.md, the design section).
//
// The family of drives is the scenario's driver type's (experiment/drive_family.h: the Ackermann weave, or the indoor
// robots' body-velocity sines), bounded by the robot's envelope (sim/drive_envelope.h) unless the limits say
// otherwise. The terrain, the start position and the sensors stay the scenario's. The objective of a drive: max over
// the free parameters' tangent components of CRB std / target (the Cramer-Rao bound of estimator/information.h on the
// noise-free drive, at its truth). A drive is feasible when it simulates (it neither leaves the terrain nor rolls
// over) within the roll, pitch, side-slip, lateral-acceleration and (body velocity) velocity-error limits. The search:
// the scenario's own drive (mapped into the family), the family's coarse grid around it, then a pattern search over the
// normalized coordinates, within an evaluation budget.
#pragma once

#include <functional>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "experiment/drive_family.h"
#include "experiment/steps.h"
#include "sim/scenario.h"

namespace roamlab::experiment {

// The bounds of the family and the feasibility limits; NaN: the robot's (sim/drive_envelope.h).
struct DesignLimits {
  double min_speed_mps = kRobotDefault;  // the forward set-point stays in [min, max]
  double max_speed_mps = kRobotDefault;
  double max_handlebar_rad = kRobotDefault;   // ackermann: |offset| + amplitude of the handlebar
  double max_yaw_rate_radps = kRobotDefault;  // body_velocity: |offset| + amplitude of the yaw rate
  double max_lateral_mps = kRobotDefault;     // body_velocity, holonomic robots: amplitude of the sideways speed
  double min_period_s = kRobotDefault;        // of the profiles' sines
  double max_period_s = kRobotDefault;
  double max_roll_deg = kRobotDefault;  // of O, over the recording
  double max_pitch_deg = kRobotDefault;
  double max_side_slip_mps = kRobotDefault;       // max |v_y| of O (sim::SimulationStats)
  double max_lateral_accel_mps2 = kRobotDefault;  // max speed x |yaw rate| of O over 0.1 s steps
  double max_velocity_error_mps = kRobotDefault;  // max |v of O - set-point| over 0.1 s steps (body_velocity)
  static constexpr double kRobotDefault = std::numeric_limits<double>::quiet_NaN();
  // Empty when valid for a drive of `driver_type` (ackermann: 0 < min speed), otherwise "--option: problem".
  std::string Validate(const std::string& driver_type) const;
};

// `given` with every NaN limit replaced by the robot's. Error: a robot kind without an envelope.
Result<DesignLimits> WithRobotDefaults(const DesignLimits& given, const sim::Scenario& scenario);

struct DesignRequest {
  std::string scenario;     // SCENARIO.yaml, driver type ackermann or body_velocity
  std::string config;       // EST.yaml
  std::string out;          // DESIGNED.yaml; design.json is written beside it
  double duration_s = 0.0;  // the designed drive's recorded duration; 0: the scenario's
  // Free parameter -> target CRB std of each of its tangent components; joined by the configuration's target_std
  // entries (estimator/config.h) for the parameters not given here.
  std::map<std::string, double> targets;
  DesignLimits limits;                            // NaN entries: the robot's
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
  double max_velocity_error_mps = 0.0;  // body_velocity drivers: largest |horizontal v of O - its set-point|
  double distance_m = 0.0;
  double seconds = 0.0;  // wall time of the evaluation
};

struct DesignResult {
  std::vector<DesignCandidate> candidates;  // in the order tried
  double duration_s = 0.0;                  // of the designed drive [s]
  DesignLimits limits;                      // those used (the robot's where the request's were NaN)
  std::map<std::string, double> targets;    // those used (the request's, the configuration's where not given)
  std::string formula;                      // the family's (DriveFamily::Formula)
  std::string best_drive;                   // the best drive in words (DriveFamily::Describe); empty: none
  int best = -1;                            // index of the feasible candidate with the least objective; -1: none
  std::string designed_yaml;                // the text written to DESIGNED.yaml
};

// The scenario's own drive mapped into its family (bounded by `limits`, the robot's where NaN). Error: a driver type
// or robot kind without a family.
Result<DriveDesign> StartDrive(const sim::Scenario& scenario, const DesignLimits& limits);

// Bad input: a scenario or configuration that does not load, a scenario whose driver or robot has no drive family, a
// target that is not a free parameter of the configuration or not > 0, no target (given or in the configuration),
// invalid limits, a duration or budget out of range, a configuration that does not fit the simulated recording.
// Failures: no feasible drive, writing the files.
Outcome DesignToFile(const DesignRequest& request, DesignResult* result = nullptr);

// design.json (docs/commands.md): the request, every candidate and the chosen one.
nlohmann::json DesignJson(const DesignRequest& request, const DesignResult& result);

}  // namespace roamlab::experiment
