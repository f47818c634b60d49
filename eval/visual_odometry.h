// Accuracy of a visual_odometry stream against the ground truth (the targets: median rotation error per frame
// pair, failure rate), without the estimator.
//
// A row stamped at t holds the camera's mean velocity over the frame pair [t - T/2, t + T/2], T = 1 / rate_hz, in
// the camera frame C at the pair's start (frontend/visual_odometry.h, step 5). The truth over the same interval: the
// poses of O interpolated at both ends (linear in position, slerp in orientation) and carried to C by the stream's
// mounting (R_OC, p_OC):
//   R_true = R_OC^T R_a^T R_b R_OC,   p_true = R_OC^T (R_a^T (p_b - p_a) + (R_a^T R_b - I) p_OC)
// Per row: rotation error = angle(Exp(omega T)^T R_true) [deg]; speed ratio |v| / (|p_true| / T) (the scale, only
// when the camera moves over 0.05 m/s); the velocity error [v - v_true; omega - omega_true] with v_true =
// Exp(-omega_true T / 2) p_true / T and its NEES under the row's covariance when the stream has the covariance columns.
// Failure rate: 1 - rows / pairs, with pairs = the frame pairs that fit in the ground truth's time span at rate_hz.
#pragma once

#include <optional>
#include <vector>

#include <nlohmann/json.hpp>

#include "eval/metrics.h"
#include "recording/recording.h"
#include "recording/trajectory.h"

namespace roamlab::eval {

struct VisualOdometryErrors {
  int pairs = 0;                 // frame pairs expected over the truth's span
  int rows = 0;                  // rows compared
  double failure_rate = 0.0;     // 1 - rows / pairs
  ErrorStatistics rotation_deg;  // per pair
  ErrorStatistics speed_ratio;   // |v| / |v_true| over the moving pairs (count: how many)
  std::vector<double> nees;      // per row, with covariance columns
  ErrorStatistics nees_statistics;
};

// Compares the stream with the truth; nullopt when the stream is not visual_odometry-like (6 velocity columns, a
// mounting and a rate) or the truth has fewer than two poses.
std::optional<VisualOdometryErrors> CompareVisualOdometry(const recording::Stream& stream, const Trajectory& truth);

// {"pairs", "rows", "failure_rate", "rotation_error_deg": {...}, "speed_ratio": {...}, "nees": {...}}.
nlohmann::json VisualOdometryJson(const VisualOdometryErrors& errors);

}  // namespace roamlab::eval
