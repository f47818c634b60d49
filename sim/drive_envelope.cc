#include "sim/drive_envelope.h"

#include <limits>

namespace roamlab::sim {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// The indoor robots' shared periods and feasibility limits (the header comment).
DriveEnvelope Indoor(double min_speed_mps, double max_speed_mps, double max_yaw_rate_radps, double max_lateral_mps) {
  DriveEnvelope e;
  e.min_speed_mps = min_speed_mps;
  e.max_speed_mps = max_speed_mps;
  e.max_turn = max_yaw_rate_radps;
  e.max_lateral_mps = max_lateral_mps;
  e.min_period_s = 4.0;
  e.max_period_s = 20.0;
  e.max_roll_deg = 10.0;
  e.max_pitch_deg = 10.0;
  e.max_side_slip_mps = max_lateral_mps > 0.0 ? kInfinity : 0.05;
  e.max_lateral_accel_mps2 = 1.0;
  e.max_velocity_error_mps = 0.1;
  return e;
}

}  // namespace

Result<DriveEnvelope> DesignEnvelope(const std::string& kind) {
  if (kind == "ackermann") {
    DriveEnvelope e;
    e.min_speed_mps = 1.5;
    e.max_speed_mps = 6.0;
    e.max_turn = 0.45;
    e.min_period_s = 5.0;
    e.max_period_s = 30.0;
    e.max_roll_deg = 25.0;
    e.max_pitch_deg = 25.0;
    e.max_side_slip_mps = 0.3;
    e.max_lateral_accel_mps2 = 4.4;
    e.max_velocity_error_mps = kInfinity;
    return e;
  }
  if (kind == "differential_drive") return Indoor(-0.3, 0.6, 1.2, 0.0);
  if (kind == "omni3") return Indoor(-0.5, 0.5, 1.5, 0.4);
  if (kind == "mecanum") return Indoor(-0.3, 0.3, 0.6, 0.3);
  return Status::Error("robot.kind: no drive family for a " + kind +
                       " robot (ackermann, differential_drive, omni3, mecanum)");
}

}  // namespace roamlab::sim
