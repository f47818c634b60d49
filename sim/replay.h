// The MuJoCo twin of a recording: the nominal scenario driven by the recording's own inputs, sampled at the
// recording's own stamps, without sensor noise (`roamlab replay`, experiment/steps.h ReplayToDirectory). The twin
// is what the nominal model predicts for the drive that was recorded, stream by stream, so that it can be compared
// with the recording sample by sample.
//
// Drive inputs (DriveInputsFrom), the first that the recording has:
//   1. An `inputs` stream (type inputs) with the driver's columns: ackermann speed_mps and handlebar_rad; the wheeled
//      kinds linear_mps and angular_radps, lateral_mps optional (sim/scenario.h, driver). Recorded commands: each
//      row holds until the next.
//   2. Wheeled kinds: a wheel_encoders stream in rad (cumulative angles) or rad/s. Angles are differentiated over a
//      centred window of +-kRateHalfWindowS (the mean rate over the window, so a tick of quantization moves a rate by
//      at most one tick per 2 kRateHalfWindowS and the integral of the rates stays the measured angle); each model
//      wheel's velocity servo is set to the rate of the recorded column MatchWheelColumns gives it, linear between
//      rows.
//   3. Wheeled kinds: an odometry stream (the robot's wheel odometry: the velocity of its frame in its frame), turned
//      into O's body velocity through the stream's mounting and fed to the driver's inverse kinematics (each wheel's
//      servo set to the rate the nominal kinematics gives), linear between rows.
//   4. Ackermann: the rear-wheel speed (a one-column wheel_encoders stream in m/s) and the steering angle (a steering
//      stream), each averaged over the same window, turned into set-points with the nominal odometer calibration
//      (sim/sensors.h, eq. 15 inverted: speed = z_v kv_over_L L, handlebar = k_theta z_theta + k_gamma; the
//      scenario's sensors.odometer or its defaults): the speed controller tracks the measured rear-wheel speed and
//      travel (sim/replay_schedule.h).
// The readings among these (2-4, not recorded commands) are taken back through the scenario's effects on them
// (sim/scenario.h), so that a patched scenario replays the true drive and its readings are the recorded ones: divided
// by odometry_scale_error's scale; an Ackermann handlebar plus steering_offset's offset; an Ackermann speed divided by
// the drive tires' slip factor of longitudinal_slip and slope_slip, at the twin's own traction as it drives
// (sim/replay_schedule.h).
// Window: [from, to] in the recording's time [s] (default: the drive inputs' first and last stamps).
// Start (ReplayStartOf): the first absolute reading at or after `from`: the first pose stream's pose (its mounting
// taken off, so O's pose; an odometry's `<name>_pose`, recording/odometry_pose.h, is not one); else GPS (or a position
// stream) with the heading of the first >= kStartMotionM of motion within kStartMotionWindowS (the lever arm taken
// off), or the scenario's start when it does not move that far; with GPS or a position stream the start is then
// refined: the scenario (its effects removed) is replayed over the first kStartAlignS from it, and the planar rigid
// motion (a rotation about the vertical and a translation) that best fits that twin's track to the recorded one
// moves the start (one fix's noise, e.g. 0.33 m on a 5 m baseline, would otherwise turn the heading by about 0.1
// rad); a translation alone when the recorded track spans less than kStartAlignMinExtentM there. Else the scenario's
// start. The robot is placed there on the ground and the scenario's lead-in runs (rest, then a ramp to the first
// inputs) before the first sample.
//
// Twin streams: each recorded stream the simulator synthesizes keeps its name, type, columns, units, rate, mounting,
// noise and attributes and its stamps within [from, to] (the physics step nearest each stamp, sim/replay_schedule.h):
// imu, magnetometer and gps (when the nominal scenario has the sensor; the scenario's mounting and calibration: the
// nominal belief), wheel_encoders in rad (wheeled kinds; the scenario's encoder columns read the model wheels,
// robot.encoder_columns, and each recorded column is matched to them by MatchWheelColumns; the scenario's encoder
// resolution, else the recording's ticks_per_revolution when whole, else 2048; a recorded column driven by several
// model wheels reads their mean; each column starts at the recorded value at the first stamp), the ackermann odometer's
// rear-wheel speed and steering (when the nominal has an odometer), one pose stream (the first of the recording that is
// not an odometry's pose; the simulator's motion capture sampled at its stamps, a scenario without sensors.mocap given
// one: the pose of the stream's mounting in W) and, for the wheeled kinds, one odometry stream (the wheel odometry: the
// twist the nominal kinematics gives for the twin's wheel rates, as the stream's frame moves); a gps or odometry
// stream's covariance columns are copied from the recording. Left out, with the reason in SimulationStats::left_out
// ("<stream>: <reason>"): every other stream (visual_odometry, scan_matching, position, laser_scan, camera, inputs, a
// second stream of a kind) and the laser and camera of the scenario (too slow for a replay; the scenario's static world
// model is dropped with them, so the robot meets no walls). Noise: every sensor-noise source off
// (SimulateOptions::noise = false); the scenario's effects are applied, so a patched scenario replays with its effects.
// truth.yaml's `replay` entry says so (recording/truth.h). Same scenario and recording give the same twin, byte for
// byte once written.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "recording/recording.h"
#include "sim/replay_schedule.h"
#include "sim/scenario.h"
#include "sim/simulator.h"

namespace roamlab::sim {

inline constexpr double kRateHalfWindowS = 0.05;      // the measured rates' centred averaging window, half width [s]
inline constexpr double kStartMotionM = 5.0;          // GPS start: the heading of the first displacement this long [m]
inline constexpr double kStartMotionWindowS = 60.0;   // searched for this long after the start [s]
inline constexpr double kStartAlignS = 10.0;          // the refining replay's span [s]
inline constexpr double kStartAlignMinExtentM = 1.0;  // the recorded track's extent that tells the heading [m]

// O's planar start pose in W and where it came from (truth.yaml's replay note).
struct ReplayStart {
  Eigen::Vector2d p_m = Eigen::Vector2d::Zero();
  double yaw_rad = 0.0;
  std::string source;
};

struct ReplayOptions {
  std::optional<double> from_s, to_s;  // the recording's time [s]
  std::optional<ReplayStart> start;    // default: ReplayStartOf(nominal, real, from_s)
  std::function<void(double)> progress;
};

// The replay's start for the recording from `from_s` on (default: the drive inputs' first stamp), as described above.
// Errors: no drive inputs, a refining replay that fails.
Result<ReplayStart> ReplayStartOf(const Scenario& nominal, const recording::Recording& real,
                                  std::optional<double> from_s = std::nullopt);

// For each model wheel (`model_columns`, in wheel index order: its name in the scenario's robot.encoder_columns, else
// WheeledRobot::EncoderColumns of the kind), the index of the recorded column that drives
// it: the column of the same name; else, for a model wheel whose name ends in "left" or "right" (front_left,
// rear_right), a recorded column named "left" or "right" (a two-column recording of a four-wheel skid steer drives
// both wheels of a side alike). Errors (one line): a model wheel without a recorded column, naming both lists.
Result<std::vector<int>> MatchWheelColumns(const std::vector<std::string>& recorded_columns,
                                           const std::vector<std::string>& model_columns);

// The drive inputs a replay needs, from the recording (above; in recording time). Errors, one line: the recording
// has none of the inputs a replay of this robot kind needs (naming them), or they cannot be read (a wheel column
// that matches no model wheel, too few rows).
Result<DriveInputs> DriveInputsFrom(const recording::Recording& real, const Scenario& nominal);

// The nominal scenario (with its effects) driven by the recording's inputs over [from, to]: the twin recording,
// its ground truth and truth (the nominal's calibration and effects, the `replay` note) and the run's statistics.
// Errors (one line): no drive inputs, an empty or inverted window, a scenario that does not simulate, a run that
// fails (the robot leaves the terrain).
Result<Simulation> Replay(const Scenario& nominal, const recording::Recording& real, const ReplayOptions& options = {});

}  // namespace roamlab::sim
