// Importer for the OptiOdom recordings (Sousa et al., J Intell Robot Syst 2022): wheel
// encoder ticks synchronized with OptiTrack motion capture, differential-drive and 3-wheel omnidirectional robots.
//
// Input files (no header row):
//   <set>_run-NN.csv       t [s], x [m], y [m], theta [rad], then the encoder ticks counted in the control cycle that
//                          ends at t (50 ms diff, 40 ms omni3): diff: right, left; omni3: wheels 1, 2, 3
//   <set>_metadata.csv     key, values...: type (diff | omni3), ngear (gear ratio), encRes (ticks per motor
//                          revolution), Li (diff: axle track; omni3: wheel distance from the centre) [m], Di (wheel
//                          diameters, one per wheel, in column order) [m]; Thi, N, L, imarkers, gt_ti, gt_tf, odo_ti,
//                          odo_tf are accepted and not used; other keys are errors
// The recording written (recording.h):
//   platform.kind        differential_drive | omni3
//   platform.geometry    gear_ratio, encoder_ticks_per_motor_revolution, wheel_radius_<wheel>_m (Di / 2), and
//                        diff: track_m (Li); omni3: wheel_distance_m (Li), wheel_angle_<wheel>_rad and
//                        wheel_direction_<wheel> (the OptiOdom layout: wheels 1, 2, 3 at -60, 60 and 180 deg from the
//                        body x axis, a positive tick count turning the robot clockwise: direction -1; read off a
//                        least-squares fit of motion-capture displacements on the ticks of the circular runs)
//   wheel_encoders       stream `wheel_encoders`, columns right, left | w1, w2, w3: cumulative wheel angle [rad]
//                        = 2 pi (running sum of ticks) / (ngear encRes); attributes.ticks_per_revolution = ngear encRes
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
