// The scan matcher as a recording stream: scans in (AddScan, in time order), a scan_matching stream out.
//
// From the second scan on, the displacement of the laser since the previous scan (scan_matcher.h, from two initial
// guesses: no motion, and the previous match's rates times the interval) becomes one row stamped at the middle of the
// interval dt = t_k - t_k-1:
//
//   t, vx, vy, vz [m/s], wx, wy, wz [rad/s]     with vz = wx = wy = 0
//
// in the laser frame at the earlier scan. The velocities follow the estimator's eq. 7 motion (rotate half, translate,
// rotate half): omega = theta / dt, v = R(-theta / 2) t / dt. A pair that does not match writes no row and is counted.
// The stream's nominal noise (noise: sigma_mps, sigma_radps) is the matcher's mean standard deviation of t_x / dt and
// theta / dt over the matched pairs.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/time.h"
#include "frontend/scan_matcher.h"
#include "recording/recording.h"

namespace roamlab::frontend {

class ScanMatchingStream {
 public:
  ScanMatchingStream(std::string name, double rate_hz, const ScanMatcherOptions& options = {});

  // The scan taken at t (after the previous one) with the ranges of `geometry`'s beams (not finite: no return).
  // Returns whether it was matched against the previous scan (false for the first scan and a failed match).
  bool AddScan(Time t, const ScanGeometry& geometry, std::vector<double> ranges);

  // The stream so far (name, rate, columns, units m/s,rad/s, noise; no mounting).
  recording::Stream TakeStream() const;
  int failed_matches() const { return failed_matches_; }

 private:
  std::string name_;
  double rate_hz_ = 0.0;
  ScanMatcherOptions options_;
  std::optional<Time> t_previous_;
  std::vector<double> previous_scan_;
  Eigen::Vector3d previous_velocity_ = Eigen::Vector3d::Zero();  // (x, y, theta) rates of the last match
  std::vector<Time> t_;
  std::vector<std::array<double, 6>> rows_;
  Eigen::Vector2d sigma_sum_ = Eigen::Vector2d::Zero();
  int failed_matches_ = 0;
};

}  // namespace roamlab::frontend
