// Planar scan matcher: the logical-sensor front end that turns two consecutive 2-D laser scans into the displacement
// of the laser between them, with a covariance (DESIGN.md: logical sensors live in sim/; the estimator sees only
// its output, a scan_matching velocity stream, seed 000 Section VI).
//
// Point-to-line ICP. The reference scan's points q_j and the current scan's points p_i are in their own laser frames.
// The unknown is the pose of the current frame in the reference frame, x = (t_x, t_y, theta): p_i maps to
// p'_i = R(theta) p_i + t. Each iteration pairs p'_i with the nearest reference point q_a among the beams within
// `search_window_beams` of p'_i's bearing, and with the nearer of q_a's neighbours q_b; the pair is kept when
// |p'_i - q_a| is under the gate and q_a, q_b lie on one surface (closer than `max_segment_m`). The residual is the
// distance to the line through q_a and q_b, r_i = n_i . (p'_i - q_a) with n_i the line's unit normal, and one
// Gauss-Newton step solves min sum r_i^2 with
//     dr_i/dt = n_i,   dr_i/dtheta = n_i . (R(theta) [-p_i,y, p_i,x]).
// The gate starts at max_correspondence_m and shrinks to max(min_gate_m, 3 rms) once the step is small.
// Covariance: sigma^2 (J^T J)^-1 with sigma^2 = sum r_i^2 / (n - 3) at the solution, the Gauss-Newton covariance
// of independent point-to-line residuals (it ignores the correlation between neighbouring residuals and the
// correspondence uncertainty, so it is optimistic by a factor that the estimator's configured noise must cover).
#pragma once

#include <vector>

#include <Eigen/Core>

namespace roamlab::sim {

// Beam layout of a planar range finder; beam k points at first_angle_rad + k increment_rad in the laser frame (x
// forward, angles counter-clockwise). A range that is not finite means no return.
struct ScanGeometry {
  int beams = 683;
  double first_angle_rad = -2.0943951023931953;   // -120 deg
  double increment_rad = 0.0061419211213877;      // 240 deg / 682
  double min_range_m = 0.02;
  double max_range_m = 4.0;

  double Angle(int k) const { return first_angle_rad + k * increment_rad; }
};

struct ScanMatcherOptions {
  int max_iterations = 40;
  double max_correspondence_m = 0.4;   // initial gate on the point distance
  double min_gate_m = 0.05;
  double max_segment_m = 0.25;         // two reference points further apart are not one surface
  int search_window_beams = 60;
  int min_correspondences = 30;
  double step_tolerance = 1e-7;        // stop when |dt| [m] + |dtheta| [rad] falls below
};

struct ScanMatch {
  bool ok = false;                                              // converged with enough correspondences
  Eigen::Vector3d pose = Eigen::Vector3d::Zero();               // (t_x [m], t_y [m], theta [rad]): current in
                                                                // the reference frame
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();     // of pose
  int correspondences = 0;
  double rms_m = 0.0;                                           // point-to-line residual at the solution
  int iterations = 0;
};

// Matches `current` against `reference` (ranges [m], one per beam of `geometry`) from `initial_guess`.
ScanMatch MatchScans(const ScanGeometry& geometry, const std::vector<double>& reference,
                     const std::vector<double>& current, const Eigen::Vector3d& initial_guess,
                     const ScanMatcherOptions& options = {});

// Tries each initial guess and keeps the successful match with the most correspondences (then the lowest rms).
ScanMatch MatchScansFrom(const ScanGeometry& geometry, const std::vector<double>& reference,
                         const std::vector<double>& current, const std::vector<Eigen::Vector3d>& initial_guesses,
                         const ScanMatcherOptions& options = {});

}  // namespace roamlab::sim
