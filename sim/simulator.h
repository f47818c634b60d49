// The simulator: runs a scenario (scenario.h) in MuJoCo and returns the recording it produces, with the true
// calibration and statistics of the drive.
//
// What happens, in order:
//   1. The world document is composed in memory: the robot's MJCF (robot.model) is included as a file of a MuJoCo
//      virtual file system, next to the terrain's asset and ground geom (terrain.h); the heightfield samples are
//      copied into the compiled model.
//   2. The vehicle is set at rest on the ground at the start pose and the unrecorded lead-in runs (scenario.h, Time).
//   3. Every physics step (the model's timestep) the driver evaluates the profiles, the speed controller turns the
//      speed set-point into rear-wheel torque and the steering servos receive the Ackermann wheel angles
//      (ackermann.h); then MuJoCo steps.
//   4. At every sample instant t_k the state at t_k is completed with mj_forward and mj_rnePostConstraint (so that
//      accelerations and MuJoCo's own acceleration sensors are current), the kinematics of O are read and every
//      stream due at t_k is synthesized (sensors.h) and corrupted by its own noise stream (noise.h).
//   5. The scenario's faults (faults.h) are applied to the recorded streams (not to a replay's).
// MuJoCo adds no noise and the simulation is single-threaded, so the same scenario and seed give the same recording,
// byte for byte once written.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <mujoco/mujoco.h>

#include "common/status.h"
#include "common/time.h"
#include "frontend/visual_odometry.h"
#include "recording/recording.h"
#include "recording/truth.h"
#include "sim/replay_schedule.h"
#include "sim/scenario.h"

namespace roamlab::sim {

struct SimulateOptions {
  std::optional<std::uint64_t> seed;  // overrides scenario.seed (the sensor noise)
  bool noise = true;                  // false: every noise source off; calibration effects stay
  // Called with the fraction done in [0, 1], about every 1 % and at the end.
  std::function<void(double fraction)> progress;
  // Called at every sample instant of any stream or of the ground truth, with the state at t completed as in step 4
  // above (sensordata included), before the step that leaves t. For tests and tools that compare with MuJoCo.
  std::function<void(Time t, const mjModel* model, const mjData* data)> observer;
  // The recording directory, where sensors.camera.store_images writes its PNGs (required when it is set).
  std::string image_directory;
  // A replay (sim/replay.h): the drive inputs replace the scenario's driver and the scheduled streams are sampled at
  // the recording's stamps (sim/replay_schedule.h). The stamps "mocap" sample the scenario's motion capture (O in W,
  // the simulator's one pose stream) at the recording's stamps; the stamps "odometry" ask for one more stream, for the
  // wheeled kinds: `odometry` (type odometry, O's wheel odometry: the twist the nominal kinematics gives for the
  // wheels' rates, least squares, in O). The outputs are in recording time (simulation time + schedule t0).
  std::shared_ptr<const ReplaySchedule> replay;
};

struct SimulationStats {
  double simulated_s = 0.0;      // lead-in + recorded time [s]
  double wall_s = 0.0;           // [s]
  double realtime_factor = 0.0;  // simulated_s / wall_s
  long physics_steps = 0;
  double distance_m = 0.0;         // path length of O over the recording (from the ground-truth samples)
  double max_abs_pitch_rad = 0.0;  // of O, over the recording
  double max_abs_roll_rad = 0.0;
  double path_height_range_m = 0.0;    // max - min height of O over the recording
  double terrain_relief_m = 0.0;       // peak-to-peak over the whole heightfield (0 on a flat floor)
  double max_lateral_speed_mps = 0.0;  // max |v_y| of O: side slip, which eq. 15 assumes to be zero
  double max_wheel_slip_mps = 0.0;     // max |omega_rear r - v_x| of O (wheeled robots: of every driven wheel's
                                       // rim against the ground point below it): longitudinal slip and creep
  int failed_scan_matches = 0;         // scan pairs the scan matcher could not match (no scan_matching sample)
  std::optional<frontend::VoCounters> visual_odometry;  // sensors.camera: frames, pairs, estimates, failures by reason
  double camera_height_m = 0.0;       // sensors.camera: the floor height the VO uses (measured at rest)
  std::vector<std::string> warnings;  // MuJoCo warnings, if any
  std::vector<std::string> faults;    // the scenario's faults, one line each: what they changed (sim/faults.h)
  std::vector<std::string> left_out;  // a replay (sim/replay.h): the recorded streams the twin does not hold,
                                      // "<stream>: <reason>"
};

struct Simulation {
  recording::Recording recording;  // streams, ground truth, platform, origin, provenance
  recording::Truth truth;          // true calibration (names in scenario.h), effects
  SimulationStats stats;
};

// A scenario compiled into MuJoCo, ready to run once.
class Simulator {
 public:
  // Validates the scenario, composes and compiles the world, binds the robot and places it at the start. Errors (one
  // line) are bad input: an invalid scenario (naming the key), a model that does not compile or lacks the elements
  // its kind needs (naming the model file), a rate that is not a whole number of physics steps.
  static Result<std::unique_ptr<Simulator>> Create(const Scenario& scenario, const SimulateOptions& options = {});
  ~Simulator();
  Simulator(const Simulator&) = delete;
  Simulator& operator=(const Simulator&) = delete;

  // Runs the lead-in and the recorded drive. Errors (one line, with the time) are run-time failures: the vehicle
  // leaves the terrain or rolls over, MuJoCo reports an error or the simulation diverges. Call once.
  Result<Simulation> Run();
  // The platform geometry the recording will state (recording/wheel_kinematics.h keys), measured on the bound model
  // without the effects. Before Run.
  std::map<std::string, double> PlatformGeometry() const;
  // The Ackermann vehicle's mass [kg] on the bound model (0 for other robots). Before Run.
  double VehicleMassKg() const;
  // The compiled model's physics step [s] (time shifts of effects are whole numbers of it). Before Run.
  double PhysicsStepS() const;

 private:
  class Impl;
  explicit Simulator(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// The nominal robot's platform geometry (Simulator::PlatformGeometry of the scenario without its effects and camera):
// what a user who believes the scenario believes about the wheels.
Result<std::map<std::string, double>> NominalPlatformGeometry(const Scenario& scenario);
// The nominal Ackermann vehicle's mass [kg] (Simulator::VehicleMassKg of the scenario without its effects and camera).
Result<double> NominalVehicleMassKg(const Scenario& scenario);

// Create and Run in one call.
Result<Simulation> Simulate(const Scenario& scenario, const SimulateOptions& options = {});

}  // namespace roamlab::sim
