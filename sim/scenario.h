// A simulation scenario (SCENARIO.yaml): one robot in one world, driven by control profiles, read by sensors with
// noise and true calibration, over a given duration. `roamlab simulate` turns it into a recording.
//
//   name: atv_hills                         # optional free text
//   duration_s: 30.0                        # recorded time [s] > 0; recording time starts at 0
//   seed: 1                                 # sensor-noise seed; `roamlab simulate --seed N` overrides it
//   origin: {latitude_deg: 45.4642, longitude_deg: 9.19, altitude_m: 120.0}   # geodetic position of W's origin
//   ground_truth_rate_hz: 100               # poses of O written to ground_truth.tum
//   robot:
//     kind: ackermann                       # the vehicle family; decides which model names, driver and odometer apply
//     model: ../models/atv.xml              # MJCF file, relative to this scenario file (names: see the model's header)
//     start: {position_m: [0, 0], heading_deg: 0}   # O above (x, y) of W [m], heading from east counter-clockwise
//     speed_controller: {kp_nm_per_mps: 300, ki_nm_per_m: 150, torque_limit_nm: 400}   # ackermann.h
//   world:
//     terrain:
//       type: hills                         # hills | flat
//       seed: 7                             # the terrain's own seed, independent of the noise seed
//       size_m: [300, 300]                  # extent east, north [m], centred on W's origin
//       resolution_m: 1.0                   # heightfield grid spacing [m]
//       relief_m: 4.0                       # peak-to-peak height over the field [m]
//       wavelength_m: [20, 60]              # range of the hills' wavelengths [m]
//       waves: 16                           # number of plane waves summed
//       friction: 0.8                       # ground sliding friction (MuJoCo uses the larger of ground and tire)
//   driver:
//     type: ackermann                       # set-points: speed_mps (rear-wheel speed) and handlebar_rad
//     lead_in_s: 4.0                        # unrecorded start before t = 0 (see below)
//     speed_mps: <profile>                  # sim/profile.h: a number or a list of terms
//     handlebar_rad: <profile>              # bicycle-equivalent steering angle, positive left
//   sensors:                                # a sensor is simulated when its key is present; absent fields take the
//                                           # defaults shown (seed Section V noise, Table I calibration)
//     imu: {rate_hz: 100, gyro_sigma_radps: 0.033, accel_sigma_mps2: 0.067,
//           misalignment: [0.938, 0.104, 0.313, 0.104],   # q_body_imu [w, x, y, z], normalized on load
//           lever_arm_m: [0, 0, 0]}                        # S^(O) of the IMU
//     magnetometer: {rate_hz: 100, sigma: 0.067,           # in the IMU's frame (needs imu); normalized field units
//                    A: [0.87, -0.02, -0.02, 0.0, 0.88, 0.0, -0.02, -0.04, 0.85],   # row-major
//                    b: [-0.008, -0.007, -0.040], field_world: [0.0, 0.5, -0.8660254037844386]}
//     gps: {rate_hz: 5, sigma_m: 0.33, lever_arm_m: [0.57, -0.46, 0.32]}
//     mocap: {rate_hz: 20, position_sigma_m: 0.001, orientation_sigma_rad: 0.005}   # motion capture: stream mocap
//                                           # (type pose, columns x y z qx qy qz qw: O's pose in W, the position
//                                           # with Gaussian noise per axis, the orientation turned by a Gaussian
//                                           # rotation vector; noise position_m, orientation_rad, as the OptiOdom
//                                           # importer states its motion capture)
//     odometer: {rate_hz: 100, speed_sigma_mps: 0.033, steering_sigma_rad: 0.014,     # ackermann: eq. 15
//                kv_over_L: 0.8, k_theta: 1.0, k_gamma: 0.0}
//   effects: []                             # hidden physical effects, each {name: ..., parameters: {...}}; written
//                                           # to truth.yaml only (the recording does not say they are there)
//   faults: []                              # sensor faults on the written streams, each {type: ..., stream: ...,
//                                           # ...} (sim/faults.h: outliers, outage, clock_jump, duplicates, freeze);
//                                           # the ground truth and truth.yaml are untouched; not applied by replay
//
// Coloured sensor noise: `noise_correlation_s` [s] in imu (gyro and accel), magnetometer, gps, odometer (both
// readings) and mocap (position and orientation), in [0, 3600], default 0 (white), makes that sensor's noise a first-order Gauss-Markov process per axis
// with the same stationary sigma: e(k+1) = a e(k) + sigma sqrt(1 - a^2) n, a = exp(-period / noise_correlation_s),
// e(0) ~ N(0, sigma^2) (sim/noise.h GaussMarkovNoise). At 0 the sensor draws exactly the white noise it draws without
// the key.
//
// Effects. Each lives where it physically belongs; parameters not given take the default shown,
// unknown names or parameters are errors. The sensor effects apply to any robot with the sensor (the IMU and GPS
// synthesis is shared); steering_offset and magnetometer_motor_interference to Ackermann robots only:
//   gps_latency {latency_s: 0}             the fix stamped t is the antenna's position at t - latency_s
//                                          (receiver latency); latency_s in [0, 1], a whole number of physics steps
//   imu_time_offset {offset_s: 0}          the IMU row stamped t holds the reading taken at t - offset_s (the IMU's
//                                          clock runs offset_s ahead); |offset_s| <= 0.5, whole physics steps
//   pose_time_offset {offset_s: 0}         the motion capture's pose stamped t is O's pose at t - offset_s: positive,
//                                          the pose stream is stamped late against the drive and the other sensors
//                                          (equivalently, they read offset_s ahead of it); negative, the wheel
//                                          encoders read |offset_s| behind it. |offset_s| <= 0.5, whole physics
//                                          steps; needs sensors.mocap (the estimator's time shift of the same name,
//                                          gap/diagnose.h, means the same: stamps moved to t - offset_s)
//   drive_time_offset {offset_s: 0, drift_ppm: 0}   a replay's recorded drive inputs (sim/replay.h) stamped t were
//                                          the robot's at t - offset_s: positive, the drive readings are stamped late
//                                          against the other sensors (an odometry that lags the IMU), and the twin
//                                          takes at recording time t0 + t the inputs stamped t0 + t + offset_s +
//                                          drift_ppm 1e-6 t (t0 the replay's start): the drive's clock runs drift_ppm
//                                          parts per million faster than the others', its rates read per unit of it.
//                                          |offset_s| <= 0.5, |drift_ppm| <= 10000; a simulation of the scenario's own
//                                          drive refuses non-zero values
//   steering_offset {offset_rad: 0}        the front wheels' angle when the handlebar sensor reads zero: eq. 15's
//                                          k_gamma becomes k_gamma + offset_rad
//   gyro_scale_error {scale_x: 1, scale_y: 1, scale_z: 1}   per-axis gain of the gyroscope in its own frame
//                                          (the estimator's gyroscope.scale, eq. 11 with k_s)
//   gyro_bias_drift {initial_x: 0, initial_y: 0, initial_z: 0, random_walk: 0}   a gyroscope bias [rad/s] (sensor
//                                          frame) that starts at `initial` and walks: b(t_k+1) = b(t_k) +
//                                          random_walk sqrt(dt) n, n ~ N(0, I), random_walk [rad/s/sqrt(s)] (rate
//                                          random walk of a warming MEMS gyro); its own seeded generator
//   magnetometer_motor_interference {b_per_nm_x: 0, b_per_nm_y: 0, b_per_nm_z: 0}   a magnetometer bias (sensor
//                                          frame, normalized field units) proportional to the rear drive torque
//                                          per wheel [N m] applied at the sample instant (motor current)
//   odometry_scale_error {scale: 1}       the odometry reads `scale` times the true motion, scale in [0.5, 1.5] (a
//                                          drive-scale error: a wrong gear ratio or encoder resolution, a controller's
//                                          mis-scaled speeds): each wheel encoder's cumulative angle before the tick
//                                          quantization, the wheel odometry's twist, the Ackermann rear-wheel speed
//                                          before its noise; needs sensors.wheel_encoders or sensors.odometer. A
//                                          replay (sim/replay.h) divides the drive it takes from these readings by
//                                          `scale`, so that its twin drives the true motion (recorded commands are not
//                                          divided). A candidate of the twin diagnosis (gap/twin.h), not of the
//                                          estimator-side one (there a wheel radius absorbs it)
// Out-of-library effects (none of the diagnosis's candidates models them; gap-benchmark's decoys):
//   accelerometer_scale_error {scale_x: 1, scale_y: 1, scale_z: 1}   per-axis gain of the accelerometer in its own
//                                          frame, each in [0.5, 1.5] (eq. 13's k_s, which the nominal models fix at 1)
//   gps_multipath {sigma_m: 0, correlation_s: 5}   a slowly varying error of the GPS fix (reflections near the
//                                          antenna): per ENU axis a first-order Gauss-Markov process, stationary
//                                          std sigma_m in [0, 10] m, correlation time correlation_s in [0.1, 600]:
//                                          e(t_k+1) = a e(t_k) + sigma_m sqrt(1 - a^2) n, a = exp(-dt /
//                                          correlation_s), e(0) ~ N(0, sigma_m^2); its own seeded generator
//   tire_growth {growth_per_mps2: 0}       ackermann: the rear tires' rolling radius grows with speed (centrifugal
//                                          growth), r(v) = r0 (1 + c v^2), c in [0, 0.01] s^2/m^2: at ground speed v
//                                          the wheel turns at v / r(v) and the speed sensor (calibrated for r0)
//                                          under-reads by the factor 1 / (1 + c v^2). MuJoCo's tire is rigid, so the
//                                          effect is applied to the rate the sensor reads, v = r0 omega_MuJoCo
//   longitudinal_slip {slip_per_mps2: 0}  ackermann: the driven (rear) tires slip in proportion to their traction
//                                          force: the wheel turns faster than the ground passes by the factor
//                                          1 + s f_x, f_x = a_x + g sin(pitch) O's forward specific force (the
//                                          traction per unit mass; negative when braking or coasting downhill), s in
//                                          [0, 0.2] s^2/m, on top of whatever MuJoCo's soft contacts slip; applied
//                                          to the rate the rear-wheel sensor reads, r0 omega_MuJoCo (1 + s f_x)
//                                          (estimator: the ackermann model's slip_per_mps2)
//   slope_slip {slip_per_mps2: 0}          ackermann: as longitudinal_slip, but following the slope alone: 1 + s g
//                                          sin(pitch), pitch O's forward axis above the horizontal, s in [0, 0.2]
//                                          s^2/m (a soil that gives way under the tires on slopes; estimator:
//                                          slope_slip_per_mps2)
//   lateral_slip {contact_time_scale: 1}  ackermann: softer tires, in MuJoCo's contacts: the four tires' contact time
//                                          constant (solref[0], 0.04 s in models/atv.xml) times contact_time_scale in
//                                          [1, 4] (AckermannVehicle::SoftenTires). A soft contact carries a sideways
//                                          force by a slip velocity proportional to it and to the time constant, so
//                                          the cornering compliance (c_rear: v_y at the rear contact over a_y)
//                                          grows about linearly with contact_time_scale; the tires also sink more
//                                          (vertical softness); the diagnosis's candidate is lateral_slip
// Wheeled indoor robots (below); in the compiled MuJoCo model after the robot is bound, so that the recording's
// platform geometry and the driver's inverse kinematics stay nominal; truth.yaml's odometer geometry is the true one:
//   wheel_radius_asymmetry {ratio_right_left: 1}   differential_drive: the right tire's radius (wheel_1) times the
//                                          ratio rho = r_R / r_L in [0.8, 1.2] (WheelDeformation.radius_scale);
//                                          driving straight at equal wheel rates omega it turns at
//                                          r_L omega (rho - 1) / B
//   wheel_radius_scale {scale: 1}         differential_drive, skid_steer, omni3, mecanum: every wheel's radius times
//                                          scale in [0.8, 1.2] (WheelDeformation.radius_scale; a roller wheel's
//                                          rollers moved radially, WheeledRobot::ScaleRollerWheel; worn or inflated
//                                          tires, a wrong stated diameter): the robot travels scale times the
//                                          distance its encoders' nominal radius says, and turns scale times as fast
//   track_width_error {track_error_m: 0}   differential_drive, mecanum: the wheel bodies moved apart along O's y by
//                                          track_error_m in [-0.1, 0.1] m, half on each side (a turn at a given wheel-
//                                          rate difference is B_nom / B_true of the nominal one); truth: baseline +
//                                          track_error_m (mecanum: lx_plus_ly + track_error_m / 2)
//   skid_steer_track {track_ratio: 1}     skid_steer: the effective track B_eff, the track of the differential drive
//                                          that turns as the skid steer does at the same wheel rates, times
//                                          track_ratio in [0.7, 1.5]. Four equally loaded contacts with isotropic
//                                          Coulomb friction at (+-L/2, +-B/2) turn with B_eff = B + L^2 / B (models/
//                                          husky.xml), so the front and rear wheel bodies are moved along O's x to
//                                          +-L'/2, L'^2 = B (track_ratio (B + L^2 / B) - B): the scrub of a ground
//                                          whose sideways resistance differs from its rolling one (grass, soil,
//                                          lugged tires); the platform geometry, the driver and truth's odometer
//                                          baseline stay nominal (WheeledRobot::MoveWheels)
//   wheel_deformation {wheel: 0, ovality_m: 0}   differential_drive (sphere tires): the tire of wheel `wheel`
//                                          made oval by ovality_m in [0, 0.02] m at the same mean rolling radius
//                                          (WheelDeformation.keep_mean_radius: the rolling radius varies twice per
//                                          revolution about its nominal mean); adds to robot.wheel_deformation
//   axle_misalignment {wheel: 0, yaw_deg: 0}   any wheeled kind: wheel `wheel` turned about z by yaw_deg within
//                                          +-20 (WheelMountingChange; unlike robot.wheel_mounting, the driver does not
//                                          know it). ackermann: the rear axle's thrust angle, both rear wheels turned
//                                          about z by yaw_deg within +-5 (positive counter-clockwise; no `wheel`):
//                                          the rear axle rolls along yaw_deg, so the vehicle crabs (course = heading
//                                          + yaw_deg) and at zero handlebar turns at -v tan(yaw) / L
//                                          (AckermannVehicle::TurnRearAxle; the estimator's odometer.thrust_angle)
// `wheel` is a whole wheel index of the kind (differential_drive 0 left, 1 right; omni3 0-2; mecanum 0-3).
//
// Streams written (names fixed, as tests/support/synthetic.h): imu (wx wy wz ax ay az), magnetometer (mx my mz,
// normalized), gps (latitude longitude altitude), rear_wheel (wheel_encoders, column rear, m/s) and steering (angle,
// rad); truth.yaml names gps.lever_arm, imu.misalignment, magnetometer.A, magnetometer.b, odometer.kv_over_L,
// odometer.k_theta, odometer.k_gamma (and imu.lever_arm when it is not zero).
//
// Time. Physics runs at the model's timestep (models/atv.xml: 1 ms). Every rate must give a period that is a whole
// number of physics steps. Sample k of a stream is at t_k = k * period for 0 <= t_k <= duration_s. The lead-in runs
// from -lead_in_s to 0 and is not recorded: the vehicle is set on the ground at the start pose, rests for the first
// quarter of the lead-in, then the set-points ramp linearly from zero to the profiles' values at t = 0, so that the
// recording starts in motion (the Ackermann odometer, eq. 15, cannot see a turn at standstill).
//
// Wheeled indoor robots (seed Section VI; scenarios/indoor_diffdrive_slip.yaml). `robot.kind: differential_drive`
// with a model that follows models/diffdrive.xml (sim/wheeled_robot.h); no speed_controller (the wheels are velocity
// servos). The world adds a static MJCF file to the flat floor:
//   world:
//     terrain: {type: flat, friction: 0.6}
//     model: ../models/indoor_room.xml      # optional: walls and clutter (geom group 0, what the laser sees)
//   driver:
//     type: body_velocity                   # set-points of O's velocity, turned into wheel speeds by the robot's
//     lead_in_s: 1.0                        # inverse kinematics
//     linear_mps: <profile>                 # forward speed v_x [m/s], e.g. a square wave
//     angular_radps: <profile>              # yaw rate [rad/s]
//   sensors:
//     imu: {...}                            # as above (vibration comes from the physics)
//     wheel_encoders: {rate_hz: 100, ticks_per_revolution: 2048}
//     laser: {rate_hz: 10, beams: 683, fov_deg: 240, min_range_m: 0.02, max_range_m: 4.0, sigma_m: 0.01,
//             store_scans: false}
//     camera: {rate_hz: 15, width_px: 320, height_px: 240, store_images: false}   # rate 10-30 Hz; 320x240 or 640x480
// Streams written: imu; wheel_encoders (wheel_encoders: one column per wheel, "left" "right", the cumulative wheel
// angle quantized to whole ticks and written in rad, attributes.ticks_per_revolution; angle 0 at t = 0);
// scan_matching (scan_matching: the velocity of the laser frame between consecutive scans, from the project's scan
// matcher (frontend/scan_matching_stream.h) on the ray-cast scans (sim/laser.h) with Gaussian range noise sigma_m,
// stamped at the middle of the scan interval, vz = wx = wy = 0; mounting = the laser site in O). store_scans: true
// also writes the noisy scans themselves as a laser_scan stream named laser_scan (recording.h; beam k at
// -fov / 2 + k fov / (beams - 1), no return written as 0; mounting = the laser site in O), from which
// `roamlab frontend scan` reproduces the scan_matching stream. The platform geometry (wheel_radius_m, baseline_m) is
// measured on the model. truth.yaml: imu.misalignment, scan_matching.lever_arm,
// scan_matching.misalignment, odometer.radius_left, odometer.radius_right, odometer.baseline (the true geometry, the
// names the differential_drive estimator model uses when its stream is called odometer).
// visual_odometry (sensors.camera; any wheeled kind whose model has a camera named "camera"): the model's camera
// rendered offscreen (sim/render.h) and fed to the monocular visual odometry (sim/simulated_camera.h, scale
// from the camera's height over the floor measured at the start pose): the velocity of the camera frame C (OpenCV:
// x right, y down, z forward) between consecutive frames, stamped at the middle of the frame pair, with the 21
// covariance columns and the intrinsics; mounting = the camera's pose in O. Frame k is taken at the first physics
// step at or after k / rate_hz (a 15 Hz camera on a 1 ms step: pairs of 66 or 67 ms); a failed pair writes no row
// (simulate prints the counts by reason). store_images: true also writes every frame as a PNG into the recording,
// listed by a camera stream visual_odometry_images (needs the recording directory: SimulateOptions::
// image_directory) whose attributes hold the intrinsics and the VO's floor reference (camera_height_m,
// floor_normal_x/y/z), from which `roamlab frontend vo` reproduces the visual_odometry stream. truth.yaml:
// visual_odometry.lever_arm, visual_odometry.misalignment.
//
// Holonomic robots: `robot.kind: omni3` (models/omni3.xml, Triskar2-like: three omni wheels at 120 deg) and
// `robot.kind: mecanum` (models/mecanum.xml: four mecanum wheels, X layout), scenarios/indoor_omni_slip.yaml. As the
// differential drive, plus:
//   robot:
//     wheel_mounting: [{wheel: 1, yaw_deg: 2.0, tilt_deg: 0.0}]   # optional: wheel bodies turned about their centre
//                                           # (yaw about z: axle misaligned; tilt about the rolling direction: camber)
//     wheel_deformation: [{wheel: 0, radius_scale: 1.0, ovality_m: 0.003}]   # optional, any wheeled kind with sphere
//                                           # tires (differential_drive): the tire radius times radius_scale (in
//                                           # [0.8, 1.2]), stretched into an oval by ovality_m in [0, 0.02] m (a taped
//                                           # wheel: the rolling radius varies with the wheel angle; WheelDeformation
//                                           # in sim/wheeled_robot.h). platform geometry stays nominal; truth.yaml's
//                                           # odometer radius is the mean rolling radius (perimeter / 2 pi).
//     wheel_offset: [{wheel: 1, offset_m: [-0.03, 0.0]}]   # optional, any wheeled kind: the wheel body moved along
//                                           # O's x and y by offset_m (each component within +-0.05 m; each wheel at
//                                           # most once): a wheel off its nominal position, an assembly error
//                                           # (WheelOffset in sim/wheeled_robot.h). Applied after binding, like the
//                                           # effects: the platform geometry and the driver's inverse kinematics stay
//                                           # nominal (unlike wheel_mounting, which the driver knows); truth.yaml's
//                                           # baseline / distance / lx_plus_ly follow the moved wheels' yaw lever arms.
//   driver:
//     lateral_mps: <profile>                # sideways speed v_y [m/s] (default 0; only for omni3 and mecanum)
// wheel_encoders has one column per wheel: omni3 "wheel_0" "wheel_1" "wheel_2", mecanum and skid_steer "front_left"
// "front_right" "rear_left" "rear_right". Platform geometry: omni3 wheel_radius_m, wheel_distance_m (L); mecanum
// wheel_radius_m, half_length_m, half_width_m. truth.yaml: odometer.radius_<i> for every wheel, and odometer.distance
// (omni3) or odometer.lx_plus_ly (mecanum), the names of the omni3_drive and mecanum_drive estimator models; the radii
// are each wheel's travel per radian, measured on the physics (sim/rolling_radius.h: below the rollers' envelope, the
// axle dips between rollers), and odometer.radius_envelope_<i> the envelope.
//
// Real robots (scenarios/real/, docs/scenarios.md "Real robots"): a simulated recording that reads like an imported
// one names its encoder columns and geometry keys as the importer does:
//   robot:
//     kind: skid_steer                      # 4 wheels front_left, front_right, rear_left, rear_right
//     (models/husky.xml),
//                                           # driven as a differential drive of the two sides; geometry wheel_radius_m,
//                                           # baseline_m (the distance between the left and right contact lines)
//     encoder_columns: [{wheel: 1, name: right}, {wheel: 0, name: left}]   # optional: the wheel_encoders columns in
//                                           # this order, column `name` the angle of wheel_<wheel>; wheels left out
//                                           # have no encoder (a skid steer's rear wheels, geared to the front ones).
//                                           # Default: every wheel, under the names above
//     geometry_keys: per_wheel              # nominal (default: the keys above) | per_wheel: the per-wheel keys of
//                                           # recording/wheel_kinematics.h (wheel_radius_<column>_m; differential_drive
//                                           # and skid_steer track_m; omni3 wheel_distance_m, wheel_angle_<column>_rad,
//                                           # wheel_direction_<column>); needs every wheel in encoder_columns. An omni3
//                                           # model off the 60/180/300 deg counter-clockwise layout needs per_wheel
//     geometry: {gear_ratio: 43.7}          # optional: keys stated as given (not measured on the model); a key the
//                                           # model's geometry has is an error
//   sensors:
//     wheel_encoders: {name: wheels, ...}   # the stream's name (default wheel_encoders)
// Physical effects go in `effects`. Each is a new key or value, so existing scenarios keep their meaning.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/status.h"
#include "recording/recording.h"
#include "sim/ackermann.h"
#include "sim/faults.h"
#include "sim/profile.h"
#include "sim/terrain.h"
#include "sim/wheeled_robot.h"

namespace roamlab::sim {

// One column of the wheel_encoders stream: the angle of wheel `wheel` (the model's wheel_<wheel>) under `name`.
struct EncoderColumn {
  int wheel = 0;
  std::string name;
};

struct RobotOptions {
  std::string kind = "ackermann";
  std::string model_file;  // path as resolved (relative to the scenario file's directory, or absolute)
  std::string model_xml;   // when non-empty, the MJCF text used instead of model_file (tests, generated models)
  Eigen::Vector2d start_position_m = Eigen::Vector2d::Zero();
  double start_heading_rad = 0.0;
  SpeedControllerOptions speed_controller;
  std::vector<WheelMountingChange> wheel_mounting;  // wheeled robots: wheels turned off their nominal mounting
  std::vector<WheelDeformation> wheel_deformation;  // wheeled robots with sphere tires: deformed tires
  std::vector<WheelOffset> wheel_offset;            // wheeled robots: wheels moved off their nominal positions
  std::vector<EncoderColumn> encoder_columns;       // wheeled robots: the encoder stream's columns; empty: the kind's
  bool per_wheel_geometry = false;                  // geometry_keys: per_wheel
  std::map<std::string, double> stated_geometry;    // robot.geometry: keys stated as given, beside the measured ones
};

struct DriverOptions {
  std::string type = "ackermann";
  double lead_in_s = 4.0;                          // >= 0
  Profile speed_mps = Profile::Constant(0.0);      // ackermann
  Profile handlebar_rad = Profile::Constant(0.0);  // ackermann
  Profile linear_mps = Profile::Constant(0.0);     // body_velocity: v_x of O
  Profile angular_radps = Profile::Constant(0.0);  // body_velocity: omega_z
  Profile lateral_mps = Profile::Constant(0.0);    // body_velocity: v_y of O (omni3, mecanum)
};

struct ImuOptions {
  double rate_hz = 100.0;
  double gyro_sigma_radps = 0.033;
  double accel_sigma_mps2 = 0.067;
  Eigen::Quaterniond misalignment{0.938, 0.104, 0.313, 0.104};  // q_body_imu, normalized by the loader
  Eigen::Vector3d lever_arm_m = Eigen::Vector3d::Zero();
  double noise_correlation_s = 0.0;  // Gauss-Markov correlation time of the gyro and accel noise; 0: white
};

struct MagnetometerOptions {
  double rate_hz = 100.0;
  double sigma = 0.067;                                          // normalized field units
  Eigen::Matrix3d A = (Eigen::Matrix3d() << 0.87, -0.02, -0.02,  //
                       0.00, 0.88, 0.00,                         //
                       -0.02, -0.04, 0.85)
                          .finished();
  Eigen::Vector3d b{-0.008, -0.007, -0.040};
  Eigen::Vector3d field_world{0.0, 0.5, -0.8660254037844386};
  double noise_correlation_s = 0.0;  // Gauss-Markov correlation time of the noise; 0: white
};

struct GpsOptions {
  double rate_hz = 5.0;
  double sigma_m = 0.33;
  Eigen::Vector3d lever_arm_m{0.57, -0.46, 0.32};
  double noise_correlation_s = 0.0;  // Gauss-Markov correlation time of the fix noise; 0: white
};

// Motion capture: the pose of O in W (noise: position per axis, orientation a rotation vector per axis).
struct MocapOptions {
  double rate_hz = 20.0;
  double position_sigma_m = 0.001;
  double orientation_sigma_rad = 0.005;
  double noise_correlation_s = 0.0;  // Gauss-Markov correlation time of the position and orientation noise; 0: white
};

struct OdometerOptions {
  double rate_hz = 100.0;
  double speed_sigma_mps = 0.033;     // on z_v
  double steering_sigma_rad = 0.014;  // on z_theta
  double kv_over_L = 0.8;             // 1/m, > 0
  double k_theta = 1.0;               // nonzero
  double k_gamma = 0.0;               // rad
  double noise_correlation_s = 0.0;   // Gauss-Markov correlation time of both readings' noise; 0: white
};

struct WheelEncoderOptions {
  std::string name = "wheel_encoders";  // the stream's name
  double rate_hz = 100.0;
  double ticks_per_revolution = 2048.0;  // > 0 (motor ticks times a gear ratio need not be whole)
};

struct LaserOptions {
  double rate_hz = 10.0;
  int beams = 683;
  double fov_deg = 240.0;  // centred on the laser's x axis
  double min_range_m = 0.02;
  double max_range_m = 4.0;
  double sigma_m = 0.01;     // Gaussian range noise
  bool store_scans = false;  // the raw scans in the recording (laser_scan stream)
};

struct CameraOptions {
  double rate_hz = 15.0;  // in [10, 30]
  int width_px = 320;     // 320x240 or 640x480
  int height_px = 240;
  bool store_images = false;  // PNGs in the recording (visual_odometry_images stream)
};

struct SensorOptions {
  std::optional<ImuOptions> imu;
  std::optional<MagnetometerOptions> magnetometer;
  std::optional<GpsOptions> gps;
  std::optional<MocapOptions> mocap;
  std::optional<OdometerOptions> odometer;
  std::optional<WheelEncoderOptions> wheel_encoders;
  std::optional<LaserOptions> laser;
  std::optional<CameraOptions> camera;
};

struct EffectOptions {
  std::string name;
  std::map<std::string, double> parameters;
};

// The effects the simulator implements, with their parameters' defaults (the header comment above).
const std::map<std::string, std::map<std::string, double>>& KnownEffects();
// The value of `parameter` of the effect `name` in `effects` (its default when the effect omits it); `fallback` when
// the effect is absent.
double EffectParameter(const std::vector<EffectOptions>& effects, const std::string& name, const std::string& parameter,
                       double fallback);

struct Scenario {
  std::string source_file;  // for messages and provenance; empty when built in code
  std::string name;
  double duration_s = 30.0;
  std::uint64_t seed = 1;
  recording::GeodeticOrigin origin{45.4642, 9.19, 120.0};
  double ground_truth_rate_hz = 100.0;
  RobotOptions robot;
  TerrainOptions terrain;
  std::string world_model_file;  // world.model as resolved; empty: none
  DriverOptions driver;
  SensorOptions sensors;
  std::vector<EffectOptions> effects;
  std::vector<FaultOptions> faults;  // sensor faults applied to the written streams (sim/faults.h)

  // The names of the streams the scenario's sensors write (the `stream` a fault may name).
  std::vector<std::string> StreamNames() const;

  // Drops the sensors that cost most to simulate, the ray-cast laser and the rendered camera, when none of the streams
  // they write is in `read` and no fault names one: for runs whose recording only an estimator reads. The other
  // streams keep their noise (each sensor draws from a generator of its own); the physics can differ in its last
  // digits, as a camera frame's step solves the forward dynamics once more.
  void DropUnreadCostlySensors(const std::set<std::string>& read);

  // The first problem, if any: the key path as written in the YAML (e.g. "sensors.gps.rate_hz") and what is wrong.
  // Checks values only; files are checked by LoadScenario and the model by the simulator.
  struct Problem {
    std::string key;
    std::string message;
  };
  std::optional<Problem> Validate() const;
};

// Reads and validates a scenario file. Errors are one line naming the file, the line and the key:
// "scenarios/x.yaml:12: sensors.imu.rate_hz: must be > 0", "...: robot.model: no such file '../models/y.xml'".
Result<Scenario> LoadScenario(const std::string& path);

}  // namespace roamlab::sim
