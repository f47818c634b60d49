// `roamlab evaluate`: an estimate directory against the truth of its recording.
//
// Reads
//   EST/trajectory.tum      the estimate (required)
//   EST/covariance.csv      3x3 world-frame position covariance per pose (optional; `roamlab track` writes it)
//   EST/calibration.json    estimated parameters (optional; `roamlab calibrate` writes it)
//   REC/recording.yaml + streams, REC/ground_truth.tum (required), REC/truth.yaml (optional: true calibration).
// Evaluation is the only part of roamlab that reads truth.yaml.
//
// Computes (eval/metrics.h, nees.h, parameters.h)
//   association   estimate poses paired with ground-truth poses by time (tolerance max_time_difference_s)
//   alignment     by default kNone when the recording has an absolute sensor (a gps, position or pose stream): the
//                 estimator then expresses its poses in the recording's own world frame (ENU at the origin), and any
//                 offset or rotation is an error that alignment would hide. Otherwise kSe3: without absolute sensor the
//                 world frame is wherever the estimator put it (the seed fixes it at the first pose, Section III-A),
//                 and the comparison is only meaningful after removing a rigid transform. kYawTranslation on request.
//   ATE           RMSE (and mean, median, max) of the position error after the alignment            -> ate_m
//   RPE by step   pairs k poses apart, k = round(rpe_delta_s / median sample period): RMSE of the translation and
//                 rotation errors                                                                    -> rpe_trans_m,
//                                                                                                       rpe_rot_deg
//   RPE by distance  segments of rpe_distance_m along the ground truth                               -> rpe_distance
//   NEES          eq. 16 per pose with the covariance rotated by the alignment (R Sigma R^T); mean over the poses and
//                 the fraction of poses inside the single-run 95 % band of chi-square(3)          -> nees_mean, nees
//   parameters    the table of eval/parameters.h for every estimated parameter with a true value   -> parameters
//   velocity      wheeled platforms with a wheel_encoders stream (eval/velocity.h): linear and angular velocity
//                 RMSE and rotational RPE (by step, as rpe_rot_deg) of the fused estimate and of the encoders'
//                 forward kinematics alone                                  -> velocity.{fused, encoders_only}
#pragma once

#include <optional>
#include <string>
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
#include "eval/velocity.h"
#include "recording/recording.h"

namespace roamlab::eval {

struct EvaluateOptions {
  std::string estimate_dir;
  std::string recording_dir;
  std::optional<AlignmentKind> alignment;  // nullopt: DefaultAlignment(recording)
  double max_time_difference_s = 0.01;     // association tolerance [s], >= 0
  double rpe_delta_s = 1.0;                // RPE by step: time spanned by the pose pairs [s], > 0
  double rpe_distance_m = 10.0;            // RPE by distance: segment length along the ground truth [m], > 0
  double nees_t0_s = 0.0;                  // poses in the first t0 seconds are left out of the NEES in-band fraction

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
  Time t_origin;  // first ground-truth stamp
  AlignmentKind alignment = AlignmentKind::kNone;
  Trajectory ground_truth;                   // whole
  Trajectory aligned_estimate;               // whole estimate, mapped by the alignment
  std::vector<Time> matched_t;               // stamps of the matched estimate poses
  std::vector<Eigen::Vector3d> error_world;  // aligned estimate - truth at the matched poses [m]
  std::vector<Eigen::Vector3d> sigma_world;  // per-axis std [m] at the matched poses (NaN without a covariance row);
                                             // empty without covariance.csv
  std::vector<PositionFixes> fixes;
  std::optional<MonteCarloNees> nees;  // single-run NEES of the poses that have one (runs = 1)
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
  std::vector<std::string> images;  // PNGs drawn
  std::string note;                 // one line when the figures could not be drawn (gnuplot missing), else empty
};

// Writes OUT/metrics.json, then the figures' data and scripts (trajectory, position_error, and nees when there is a
// covariance) and draws them with gnuplot when it is installed (otherwise `note` says so; metrics.json is written
// anyway). Errors: the output cannot be written, or gnuplot fails.
Result<WrittenEvaluation> WriteEvaluation(const Evaluation& evaluation, const std::string& out_dir, bool plots = true);

}  // namespace roamlab::eval
