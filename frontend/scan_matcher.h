// Planar scan matcher: the logical-sensor front end that turns two consecutive 2-D laser scans into the displacement
// of the laser between them, with a covariance (the estimator sees only its output, a scan_matching velocity stream,
// seed 000 Section VI; scan_matching_stream.h builds that stream).
//
// Point-to-line ICP. The reference scan's points q_j and the current scan's points p_i are in their own laser frames.
// The unknown is the pose of the current frame in the reference frame, x = (t_x, t_y, theta): p_i maps to
// p'_i = R(theta) p_i + t. Each iteration pairs p'_i with the nearest reference point q_a among the beams within
// `search_window_beams` of p'_i's bearing, kept when |p'_i - q_a| is under the gate. The residual is the distance to
// the reference surface at q_a, r_i = n_a . (p'_i - c_a), where the line (c_a, n_a) is the total-least-squares fit
// through the reference points within `line_half_window_beams` of q_a on one surface (consecutive points closer
// than `max_segment_m`), and one Gauss-Newton step solves min sum r_i^2 with
//     dr_i/dt = n_i,   dr_i/dtheta = n_i . (R(theta) [-p_i,y, p_i,x]).
// Why a fitted line and not the line through q_a and its nearer neighbour (Censi's PLICP): with range noise sigma
// and beam spacing h = range x increment (h ~ sigma at 1-2 m for the URG-04LX) the two-point normal is off by
// ~sqrt(2) sigma / h rad, the residual then mixes in the tangential offset to the nearest point, and the cost gets
// a minimum where the two scans' beam grids line up, at zero motion: the matcher under-reads the displacement (by
// 1-3 % at sigma = 1 cm, tests/frontend/scan_matcher_test.cc). A line over 2w + 1 points has a slope error
// ~sigma / (h sqrt(w (w + 1) (2w + 1) / 3)) (least-squares slope), 7x smaller for w = 3, and averages the
// reference point's noise.
// The gate starts at max_correspondence_m and shrinks to max(min_gate_m, 3 rms) once the step is small.
// Covariance: sigma^2 (J^T J)^-1 with sigma^2 = sum r_i^2 / (n - 3) at the solution, the Gauss-Newton covariance
// of independent point-to-line residuals (it ignores the correlation between neighbouring residuals and the
// correspondence uncertainty, so it is optimistic by a factor that the estimator's configured noise must cover).
#pragma once

#include <vector>

#include <Eigen/Core>

namespace roamlab::frontend {

// Beam layout of a planar range finder; beam k points at first_angle_rad + k increment_rad in the laser frame (x
// forward, angles counter-clockwise). A range that is not finite means no return.
struct ScanGeometry {
  int beams = 683;
  double first_angle_rad = -2.0943951023931953;  // -120 deg
  double increment_rad = 0.0061419211213877;     // 240 deg / 682
  double min_range_m = 0.02;
  double max_range_m = 4.0;

  double Angle(int k) const { return first_angle_rad + k * increment_rad; }
};

struct ScanMatcherOptions {
  int max_iterations = 40;
  double max_correspondence_m = 0.4;  // initial gate on the point distance
  double min_gate_m = 0.05;
  double max_segment_m = 0.25;     // two reference points further apart are not one surface
  int line_half_window_beams = 3;  // the reference line at q_a fits q_a and up to this many beams either side
  int search_window_beams = 60;
  int min_correspondences = 30;
  double step_tolerance = 1e-7;  // stop when |dt| [m] + |dtheta| [rad] falls below
};

struct ScanMatch {
  bool ok = false;                                           // converged with enough correspondences
  Eigen::Vector3d pose = Eigen::Vector3d::Zero();            // (t_x [m], t_y [m], theta [rad]): current in
                                                             // the reference frame
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();  // of pose
  int correspondences = 0;
  double rms_m = 0.0;  // point-to-line residual at the solution
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

}  // namespace roamlab::frontend
