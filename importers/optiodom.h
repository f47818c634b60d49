// Importer for the OptiOdom recordings (Sousa et al., J Intell Robot Syst 2022): wheel encoder ticks synchronized
// with OptiTrack motion capture; differential-drive, 3- and 4-wheel omnidirectional and tricycle robots.
//
// Input files (no header row):
//   <set>_run-NN.csv       t [s], x [m], y [m], theta [rad], then per control cycle that ends at t:
//                          diff: ticks of the right, left wheels; omni3: ticks of wheels 1, 2, 3; omni4: ticks of
//                          wheels 1-4; tricyc: ticks of the front wheel, then the steering angle [rad] (the measured
//                          angle in steps of pi/400, not a count; positive turns the robot counter-clockwise)
//   <set>_metadata.csv     key, values...: type (diff | omni3 | omni4 | tricyc), ngear (gear ratio), encRes (ticks
//                          per motor revolution), Li [m] (diff: axle track; omni3: wheel distance from the centre;
//                          omni4: l1 l2, the front-to-back and left-to-right distances between the wheels; tricyc:
//                          front wheel to rear axle), Di [m] (wheel diameters in column order: 2 diff, 3 omni3, 4
//                          omni4, 1 tricyc), Thi (tricyc: the steering offset [rad], any sign; required; empty
//                          for the others); N, L, imarkers, gt_ti, gt_tf, odo_ti, odo_tf are accepted and not
//                          used; other keys, a key given twice, a wrong number of Li or Di values, a missing key or a
//                          value outside its range (ngear <= 1e4, encRes <= 1e7, Li and Di <= 100 m, |Thi| <= 3.15
//                          rad) are errors naming the file and line; a run's time beyond +-9e9 s is an error naming
//                          the row
// The recording written (recording.h):
//   platform.kind        differential_drive | omni3 | omni4 | tricycle
//   platform.geometry    gear_ratio, encoder_ticks_per_motor_revolution, wheel_radius_<wheel>_m (Di / 2), and
//                        diff: track_m (Li); omni3: wheel_distance_m (Li), wheel_angle_<wheel>_rad and
//                        wheel_direction_<wheel> (the OptiOdom layout: wheels 1, 2, 3 at -60, 60 and 180 deg from the
//                        body x axis, a positive tick count turning the robot clockwise: direction -1; read off a
//                        least-squares fit of motion-capture displacements on the ticks of the circular runs);
//                        omni4: wheelbase_m (l1), track_m (l2): wheels 1-4 are front_left, front_right, rear_left,
//                        rear_right at (+-l1/2, +-l2/2), turned 45 deg (the X layout), a positive tick count
//                        turning the robot clockwise; per positive wheel revolution the rim pushes the body along
//                        (1, -1)/sqrt 2, (-1, -1)/sqrt 2, (1, 1)/sqrt 2, (-1, 1)/sqrt 2 (recording/wheel_kinematics.h,
//                        omni4). Read off a least-squares fit of the motion-capture displacements (body frame, 0.2 s
//                        steps) on the ticks of all circular and square runs: rim travel = (0.89, -0.93, -0.183),
//                        (-0.89, -0.94, -0.182), (0.89, 0.93, -0.183), (-0.89, 0.93, -0.183) . (dx, dy, dtheta):
//                        directions at 45 deg and a lever of 0.1414 |d| = (l1 + l2) / (2 sqrt 2) |d|, with |d| = 1.29,
//                        not 1: a counted revolution moves the contact point by about pi Di / 1.29 (an effective
//                        radius near 0.023 m, not the nominal 0.03 m; that is the learner's to find);
//                        tricycle: wheel_to_axle_m (Li), steering_offset_rad (Thi). The steering angle's sign
//                        (positive: counter-clockwise) was read off the same kind of fit: yaw increments against rim
//                        travel x sin(steering + offset) over the circular and square runs
//   wheel_encoders       stream `wheel_encoders`, columns right, left | w1, w2, w3 | front_left, front_right,
//                        rear_left, rear_right | front: cumulative wheel angle [rad]
//                        = 2 pi (running sum of ticks) / (ngear encRes); attributes.ticks_per_revolution = ngear encRes
//   steering             tricycle only: stream `steering` (type steering, column angle) [rad], the measured angle
//                        (the true one is angle + steering_offset_rad)
//   mocap                stream `mocap` of type pose: the motion-capture pose (z = 0, yaw only), nominal noise
//                        position_m 0.001, orientation_rad 0.005. It stands in for the exteroceptive sensor (a scan
//                        matcher in seed 001) when learning odometry.
//   ground_truth.tum     the same poses: the reference for ATE/RPE and `roamlab evaluate`.
// The manufacturer values are what the metadata says; the real robot differs (unequal wheel diameters, a wider
// effective track, a time offset between encoders and motion capture), and finding that
// is the learner's job, not the importer's.
#pragma once

#include <string>

#include "common/status.h"
#include "recording/recording.h"

namespace roamlab::importers {

// The metadata file next to a run: "<dir>/<set>_run-NN.csv" -> "<dir>/<set>_metadata.csv"; "" when the name does not
// follow that pattern.
std::string OptiOdomMetadataPath(const std::string& run_csv);

// Reads one run and its metadata. Errors are one line naming the file (and line) and the problem.
Result<recording::Recording> ImportOptiOdom(const std::string& run_csv, const std::string& metadata_csv);

}  // namespace roamlab::importers
