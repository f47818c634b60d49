#include "sim/scan_matcher.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

namespace roamlab::sim {
namespace {

struct Points {
  std::vector<Eigen::Vector2d> xy;
  std::vector<bool> valid;
};

Points ToPoints(const ScanGeometry& g, const std::vector<double>& ranges) {
  Points p;
  p.xy.resize(ranges.size());
  p.valid.resize(ranges.size());
  for (std::size_t k = 0; k < ranges.size(); ++k) {
    const double r = ranges[k];
    p.valid[k] = std::isfinite(r) && r >= g.min_range_m && r <= g.max_range_m;
    const double a = g.Angle(static_cast<int>(k));
    p.xy[k] = p.valid[k] ? Eigen::Vector2d(r * std::cos(a), r * std::sin(a)) : Eigen::Vector2d::Zero();
  }
  return p;
}

Eigen::Matrix2d Rotation(double theta) {
  const double c = std::cos(theta), s = std::sin(theta);
  return (Eigen::Matrix2d() << c, -s, s, c).finished();
}

}  // namespace

ScanMatch MatchScans(const ScanGeometry& g, const std::vector<double>& reference, const std::vector<double>& current,
                     const Eigen::Vector3d& initial_guess, const ScanMatcherOptions& o) {
  const Points ref = ToPoints(g, reference);
  const Points cur = ToPoints(g, current);
  const int n_ref = static_cast<int>(ref.xy.size());
  ScanMatch match;
  Eigen::Vector3d x = initial_guess;
  double gate = o.max_correspondence_m;
  Eigen::Matrix3d JtJ = Eigen::Matrix3d::Zero();
  double sum_r2 = 0.0;
  int used = 0;
  bool small_step = false;

  for (int iteration = 0; iteration < o.max_iterations; ++iteration) {
    const Eigen::Matrix2d R = Rotation(x[2]);
    JtJ.setZero();
    Eigen::Vector3d Jtr = Eigen::Vector3d::Zero();
    sum_r2 = 0.0;
    used = 0;
    for (std::size_t i = 0; i < cur.xy.size(); ++i) {
      if (!cur.valid[i]) continue;
      const Eigen::Vector2d p = R * cur.xy[i] + x.head<2>();
      // Nearest reference point among the beams around p's bearing.
      const int centre = static_cast<int>(std::lround((std::atan2(p.y(), p.x()) - g.first_angle_rad) /
                                                      g.increment_rad));
      const int lo = std::max(0, centre - o.search_window_beams);
      const int hi = std::min(n_ref - 1, centre + o.search_window_beams);
      int a = -1;
      double best = gate * gate;
      for (int j = lo; j <= hi; ++j) {
        if (!ref.valid[j]) continue;
        const double d2 = (ref.xy[j] - p).squaredNorm();
        if (d2 < best) {
          best = d2;
          a = j;
        }
      }
      if (a < 0) continue;
      // Its nearer neighbour on the same surface.
      int b = -1;
      for (int j : {a - 1, a + 1}) {
        if (j < 0 || j >= n_ref || !ref.valid[j]) continue;
        if ((ref.xy[j] - ref.xy[a]).squaredNorm() > o.max_segment_m * o.max_segment_m) continue;
        if (b < 0 || (ref.xy[j] - p).squaredNorm() < (ref.xy[b] - p).squaredNorm()) b = j;
      }
      if (b < 0) continue;
      const Eigen::Vector2d along = ref.xy[b] - ref.xy[a];
      if (along.norm() < 1e-9) continue;
      const Eigen::Vector2d normal = Eigen::Vector2d(-along.y(), along.x()).normalized();
      const double r = normal.dot(p - ref.xy[a]);
      const Eigen::Vector2d dp_dtheta = R * Eigen::Vector2d(-cur.xy[i].y(), cur.xy[i].x());
      const Eigen::Vector3d J(normal.x(), normal.y(), normal.dot(dp_dtheta));
      JtJ += J * J.transpose();
      Jtr += J * r;
      sum_r2 += r * r;
      ++used;
    }
    match.iterations = iteration + 1;
    if (used < o.min_correspondences) break;
    const Eigen::Vector3d step = -JtJ.ldlt().solve(Jtr);
    if (!step.allFinite()) break;
    x += step;
    const double rms = std::sqrt(sum_r2 / used);
    if (step.head<2>().norm() + std::abs(step[2]) < o.step_tolerance) {
      if (small_step && gate <= std::max(o.min_gate_m, 3.0 * rms) + 1e-12) break;
      small_step = true;
    }
    if (small_step || iteration >= 10) gate = std::clamp(3.0 * rms, o.min_gate_m, gate);
  }

  match.correspondences = used;
  match.pose = x;
  match.ok = used >= o.min_correspondences && x.allFinite();
  if (match.ok) {
    match.rms_m = std::sqrt(sum_r2 / used);
    const double sigma2 = sum_r2 / std::max(used - 3, 1);
    match.covariance = sigma2 * JtJ.inverse();
    match.ok = match.covariance.allFinite();
  }
  return match;
}

ScanMatch MatchScansFrom(const ScanGeometry& geometry, const std::vector<double>& reference,
                         const std::vector<double>& current, const std::vector<Eigen::Vector3d>& initial_guesses,
                         const ScanMatcherOptions& options) {
  ScanMatch best;
  for (const Eigen::Vector3d& guess : initial_guesses) {
    const ScanMatch m = MatchScans(geometry, reference, current, guess, options);
    if (!m.ok) continue;
    if (!best.ok || m.correspondences > best.correspondences ||
        (m.correspondences == best.correspondences && m.rms_m < best.rms_m))
      best = m;
  }
  return best;
}

}  // namespace roamlab::sim
