// The set-point envelope and the feasibility limits of a designed drive (`roamlab design`), per robot kind: what each
// robot can be asked to do and what a drive of it may not exceed. The defaults of design's limits options.
//
//   ackermann            speed 1.5-6 m/s, handlebar +-0.45 rad, a weave of 5-30 s; roll and pitch 25 deg, side slip
//                        0.3 m/s, lateral acceleration 4.4 m/s^2 (0.45 g): an ATV on hills; no velocity-error limit.
//   differential_drive   forward -0.3 to 0.6 m/s, yaw rate +-1.2 rad/s (the square waves of
//                        scenarios/indoor_diffdrive_slip.yaml), periods 4-20 s; roll and pitch 10 deg, side slip
//                        0.05 m/s (the casters' creep), lateral acceleration 1 m/s^2 (0.1 g: a load stays put),
//                        O's velocity within 0.1 m/s of its set-point (no wall, obstacle or slip in the way).
//   omni3                forward +-0.5 m/s, sideways +-0.4 m/s, yaw rate +-1.5 rad/s (scenarios/indoor_omni_slip.yaml);
//                        the rest as differential_drive, no side-slip limit (the sideways speed is commanded).
//   mecanum              forward and sideways +-0.3 m/s, yaw rate +-0.6 rad/s (twice the seed's envelope of
//                        scenarios/deformed_t2_train.yaml); the rest as omni3.
#pragma once

#include <string>

#include "common/status.h"

namespace roamlab::sim {

struct DriveEnvelope {
  double min_speed_mps = 0.0;  // forward set-point: ackermann's speed_mps, body_velocity's linear_mps
  double max_speed_mps = 0.0;
  double max_turn = 0.0;         // |handlebar_rad| (ackermann) or |angular_radps| (body_velocity)
  double max_lateral_mps = 0.0;  // |lateral_mps| (holonomic robots; 0: none)
  double min_period_s = 0.0;     // of the profiles' sines
  double max_period_s = 0.0;
  double max_roll_deg = 0.0;  // of O, over the recording
  double max_pitch_deg = 0.0;
  double max_side_slip_mps = 0.0;       // max |v_y| of O; infinite for holonomic robots
  double max_lateral_accel_mps2 = 0.0;  // max speed x |yaw rate| of O
  // Max |horizontal velocity of O - its set-point| (body_velocity drivers): a wall, an obstacle or slip keeps the
  // robot from its set-points. Infinite for ackermann (its speed set-point is the rear wheels').
  double max_velocity_error_mps = 0.0;
};

// The envelope of robot kind `kind` (sim/scenario.h's robot.kind). Error: a kind no drive family is designed for.
Result<DriveEnvelope> DesignEnvelope(const std::string& kind);

}  // namespace roamlab::sim
