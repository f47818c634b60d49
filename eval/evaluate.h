// `roamlab evaluate`: an estimate against a reference trajectory: the truth of its recording, a plain trajectory file,
// or, on real data without ground truth, an absolute sensor stream of the recording.
//
// Reads
//   the estimate   a directory EST with trajectory.tum (required), covariance.csv (3x3 world-frame position covariance
//                  per pose, optional; `roamlab track` writes it) and calibration.json (estimated parameters,
//                  optional; `roamlab calibrate` writes it), or a plain trajectory file (eval/trajectory_file.h: TUM,
//                  KITTI, EuRoC CSV); covariance_file gives the covariances of either (required then, and a timed
//                  estimate: rows are matched to poses by stamp).
//   the reference  in this order: reference_file (a plain trajectory file); REC/ground_truth.tum; the recording's
//                  stream reference_stream, or without ground truth its first gps, position or pose stream. A gps
//                  stream is converted to East-North-Up at the recording's origin; gps and position streams carry no
//                  orientation, so rotation errors and RPE are then left out. A stream measures a sensor, not O: the
//                  estimate is moved to the sensor by the lever arm (and, for pose streams, the mounting rotation)
//                  from the calibration's "<stream>.lever_arm" when it has one, else from the stream's mounting in
//                  recording.yaml, else the lever arm is ignored (metrics.json says which).
//   REC/recording.yaml + streams, REC/truth.yaml (optional: true calibration). Evaluation is the only part of roamlab
//   that reads truth.yaml.
//
// Computes (eval/metrics.h, nees.h, parameters.h)
//   association   estimate poses paired with reference poses by time (tolerance max_time_difference_s) after adding
//                 time_offset_s to the estimate's stamps; by index when either side has no time (KITTI).
//   alignment     by default kNone when the recording has an absolute sensor (a gps, position or pose stream): the
//                 estimator then expresses its poses in the recording's own world frame (ENU at the origin), and any
//                 offset or rotation is an error that alignment would hide. kSe3 for a recording without one:
//                 the world frame is wherever the estimator put it (the seed fixes it at the first pose, Section
//                 III-A), and the comparison is only meaningful after removing a rigid transform. kNone for two plain
//                 files without a recording (as evo). kYawTranslation, kSim3 and kOrigin on request. The alignment is
//                 computed on all matched poses, the first align_first_n, or those whose reference stamp lies in
//                 align_window_s (seconds since the reference's first pose), and applied to all.
//   ATE           position error after the alignment: RMSE (and mean, median, std, min, max)       -> ate_m, ate
//                 rotation error angle(R_ref^T R_aligned_est)                           -> ate_rot_deg, ate_rotation
//                 per axis of the reference frame, horizontal and vertical                         -> ate_axes
//   RPE by step   pairs k poses apart, k = round(rpe_delta_s / median sample period): RMSE of the translation and
//                 rotation errors (on the aligned estimate: a sim3 scale applies)                  -> rpe_trans_m,
//                                                                                                     rpe_rot_deg
//   RPE by distance  segments of rpe_distance_m along the reference                                 -> rpe_distance
//   NEES          eq. 16 per pose with the covariance rotated by the alignment (s^2 R Sigma R^T); mean over the poses
//                 and the fraction of poses inside the single-run 95 % band of chi-square(3)     -> nees_mean, nees
//   parameters    the table of eval/parameters.h for every estimated parameter with a true value   -> parameters
//   velocity      wheeled platforms with a wheel_encoders stream and ground truth (eval/velocity.h): linear and
//                 angular velocity RMSE and rotational RPE (by step, as rpe_rot_deg) of the fused estimate and of the
//                 encoders' forward kinematics alone                        -> velocity.{fused, encoders_only}
//
// Several estimates against one reference: each is evaluated alone, then WriteComparison writes one table and the
// overlaid figures.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "common/status.h"
#include "eval/alignment.h"
#include "eval/association.h"
#include "eval/metrics.h"
#include "eval/nees.h"
#include "eval/parameters.h"
#include "eval/plots.h"
#include "eval/trajectory_file.h"
#include "eval/velocity.h"
#include "recording/recording.h"

namespace roamlab::eval {

struct EvaluateOptions {
  std::string estimate_dir;                          // a directory (trajectory.tum, ...) or a plain trajectory file
  std::string recording_dir;                         // optional when reference_file is set
  std::string reference_file;                        // a plain trajectory file as the reference
  std::string reference_stream;                      // a gps, position or pose stream of the recording as the reference
  std::string calibration_file;                      // calibration.json for the lever arm and the parameter table
                                                     // ("": EST/calibration.json when the estimate is a directory)
  std::string covariance_file;                       // covariance.csv of the estimate's position covariances ("":
                                                     // EST/covariance.csv of a directory, none for a plain file)
  std::optional<TrajectoryFormat> reference_format;  // nullopt: detected
  std::optional<TrajectoryFormat> estimate_format;   // nullopt: detected (plain files only)
  std::optional<AlignmentKind> alignment;            // nullopt: the default (see the top of this file)
  std::size_t align_first_n = 0;                     // align on the first N matched poses; 0: all
  std::optional<std::pair<double, double>> align_window_s;  // align on the poses in [start, end] s since the
                                                            // reference's first pose
  double max_time_difference_s = 0.01;                      // association tolerance [s], >= 0
  double time_offset_s = 0.0;                               // added to the estimate's stamps before the association [s]
  double rpe_delta_s = 1.0;                                 // RPE by step: time spanned by the pose pairs [s], > 0
  double rpe_distance_m = 10.0;  // RPE by distance: segment length along the reference [m], > 0
  double nees_t0_s = 0.0;        // poses in the first t0 seconds are left out of the NEES in-band fraction

  // Empty when usable, otherwise what is wrong.
  std::string Validate() const;
};

// kNone when the recording has a gps, position or pose stream, kSe3 otherwise (see the top of this file).
AlignmentKind DefaultAlignment(const recording::Recording& recording);

// Positions of every absolute sensor stream in the recording's world frame: gps converted from latitude, longitude and
// altitude to East-North-Up at the recording's origin (GeographicLib::LocalCartesian), position and pose streams as
// given. These are sensor (antenna) positions, not positions of O: lever arms are not removed.
std::vector<PositionFixes> AbsoluteFixes(const recording::Recording& recording);

struct Evaluation {
  nlohmann::json metrics;  // the content of metrics.json

  // What the figures draw.
  Time t_origin;  // first reference stamp
  AlignmentKind alignment = AlignmentKind::kNone;
  Trajectory reference;                      // whole
  std::string reference_label;               // "ground truth", "GPS fixes (gps)", "reference (gt.txt)"
  bool reference_has_orientation = true;     // false for gps and position streams
  Trajectory aligned_estimate;               // whole estimate, mapped by the alignment
  std::vector<Time> matched_t;               // stamps of the matched estimate poses
  std::vector<Eigen::Vector3d> error_world;  // aligned estimate - reference at the matched poses [m]
  std::vector<double> rotation_error_deg;    // per matched pose (empty when the reference has no orientation)
  std::vector<Eigen::Vector3d> sigma_world;  // per-axis std [m] at the matched poses (NaN without a covariance row);
                                             // empty without covariance.csv
  std::vector<PositionFixes> fixes;
  std::optional<MonteCarloNees> nees;  // single-run NEES of the poses that have one (runs = 1)
  std::string estimate_name;           // the estimate's directory or file name, e.g. "tracking"
  std::string estimate_label;          // e.g. "estimate (tracking)"
  // Wheeled platforms with encoders: velocities of the fused estimate and of the encoders against the truth, and the
  // rotational RPE per pair (stamp of the pair's first pose, seconds since t_origin).
  struct Velocity {
    VelocityErrors fused, encoders_only;
    std::vector<double> rpe_t_fused_s, rpe_rot_fused_deg, rpe_t_encoders_s, rpe_rot_encoders_deg;
  };
  std::optional<Velocity> velocity;
};

// Reads the inputs and computes every metric. Errors are bad input, one line naming the file and the problem: a
// missing or malformed file, no pose matched, invalid options.
Result<Evaluation> Evaluate(const EvaluateOptions& options);

struct WrittenEvaluation {
  std::string metrics_path;         // OUT/metrics.json
  std::string report_path;          // OUT/report.html (eval/report.h)
  std::vector<std::string> images;  // PNGs drawn
  std::string note;                 // one line when the figures could not be drawn (gnuplot missing), else empty
};

// Writes OUT/metrics.json, then the figures' data and scripts (trajectory, position_error, and nees when there is a
// covariance) and draws them with gnuplot when it is installed (otherwise `note` says so; metrics.json is written
// anyway), then OUT/report.html with the figures embedded. Errors: the output cannot be written, or gnuplot fails.
Result<WrittenEvaluation> WriteEvaluation(const Evaluation& evaluation, const std::string& out_dir, bool plots = true);

// Several estimates against the same reference: OUT/metrics.json = {"reference": ..., "table": [{"name", "ate_m",
// "ate_rot_deg", "rpe_trans_m", "rpe_rot_deg", "matched"}], "estimates": {NAME: metrics of the estimate}}, the
// overlaid top view trajectory.png and ate_over_time.png (position error norm and rotation error of every estimate
// against time), OUT/report.html (the table, the overlaid figures, then every estimate's tables and figures) and each
// estimate's own evaluation in OUT/NAME/. Names must be unique (CHECK).
Result<WrittenEvaluation> WriteComparison(const std::vector<Evaluation>& evaluations, const std::string& out_dir,
                                          bool plots = true);

}  // namespace roamlab::eval
