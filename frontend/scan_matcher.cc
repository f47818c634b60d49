#include "frontend/scan_matcher.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Dense>

namespace roamlab::frontend {
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

// The reference surface around each point: a total-least-squares line through 2w + 1 consecutive reference points
// on one surface (a chain of neighbours closer than `max_segment_m`) that contain the point, as its centroid c and
// unit normal n (the eigenvector of the scatter matrix's smaller eigenvalue). The window centred on the point is kept
// unless one ending at the point (on either side) has a mean squared distance to its line (lambda_min / (count - 2))
// kOneSidedPenalty times smaller: next to a corner the line then lies on the point's own face, not across the
// corner, while on a flat surface the centred window wins (a one-sided window's centroid lies w beams away, and its
// normal's noise times that offset adds to the residual). Windows of fewer than three points give no line.
struct Lines {
  std::vector<Eigen::Vector2d> centroid;
  std::vector<Eigen::Vector2d> normal;
  std::vector<bool> valid;
};

constexpr double kOneSidedPenalty = 4.0;  // a corner makes the straddling fit's mse grow far more than 4x

Lines FitLines(const Points& ref, int half_window, double max_segment_m) {
  const int n = static_cast<int>(ref.xy.size());
  // Start and end of each point's surface chain.
  std::vector<int> chain_begin(ref.xy.size()), chain_end(ref.xy.size());
  const double max_segment2 = max_segment_m * max_segment_m;
  for (int j = 0; j < n; ++j) {
    const bool joined =
        j > 0 && ref.valid[j] && ref.valid[j - 1] && (ref.xy[j] - ref.xy[j - 1]).squaredNorm() <= max_segment2;
    chain_begin[j] = joined ? chain_begin[j - 1] : j;
  }
  for (int j = n - 1; j >= 0; --j) {
    const bool joined =
        j < n - 1 && ref.valid[j] && ref.valid[j + 1] && (ref.xy[j] - ref.xy[j + 1]).squaredNorm() <= max_segment2;
    chain_end[j] = joined ? chain_end[j + 1] : j;
  }
  Lines lines;
  lines.centroid.assign(ref.xy.size(), Eigen::Vector2d::Zero());
  lines.normal.assign(ref.xy.size(), Eigen::Vector2d::Zero());
  lines.valid.assign(ref.xy.size(), false);
  for (int j = 0; j < n; ++j) {
    if (!ref.valid[j]) continue;
    double best_mse = std::numeric_limits<double>::infinity();
    for (const int shift : {0, -half_window, half_window}) {
      const int lo = std::max(chain_begin[j], j + shift - half_window);
      const int hi = std::min(chain_end[j], j + shift + half_window);
      const int count = hi - lo + 1;
      if (count < 3) continue;
      Eigen::Vector2d c = Eigen::Vector2d::Zero();
      for (int k = lo; k <= hi; ++k) c += ref.xy[k];
      c /= count;
      Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
      for (int k = lo; k <= hi; ++k) scatter += (ref.xy[k] - c) * (ref.xy[k] - c).transpose();
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(scatter);
      const double mse = eigen.eigenvalues()[0] / (count - 2);  // eigenvalues ascending
      if (!(eigen.eigenvalues()[1] > 0.0) || !(mse * (shift == 0 ? 1.0 : kOneSidedPenalty) < best_mse)) continue;
      best_mse = mse * (shift == 0 ? 1.0 : kOneSidedPenalty);
      lines.centroid[j] = c;
      lines.normal[j] = eigen.eigenvectors().col(0);
      lines.valid[j] = true;
    }
  }
  return lines;
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
  const Lines lines = FitLines(ref, o.line_half_window_beams, o.max_segment_m);
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
      const int centre =
          static_cast<int>(std::lround((std::atan2(p.y(), p.x()) - g.first_angle_rad) / g.increment_rad));
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
      if (a < 0 || !lines.valid[a]) continue;
      const Eigen::Vector2d& normal = lines.normal[a];
      const double r = normal.dot(p - lines.centroid[a]);
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

}  // namespace roamlab::frontend
