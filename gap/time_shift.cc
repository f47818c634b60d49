#include "gap/internal/time_shift.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <vector>

#include <Eigen/Dense>

#include "estimator/covariance.h"

namespace roamlab::gap::internal {
namespace {

// The chi-square on the grid is not smooth: moving a stream by one sample re-pairs its noise with the other streams',
// which adds a jitter to the chi-square. So a parabola chi2(k) = a k^2 + b k + c is fitted by least squares to the
// best point and kHalfWindow points each side, and the standard deviation of its vertex combines the curvature's
// (1 / sqrt(a) grid steps: cost = chi2 / 2 has second derivative a) and the vertex's own spread from the jitter
// (delta method on the fitted a, b).
constexpr int kHalfWindow = 3;

// The largest integrated autocorrelation time (estimator/covariance.h AnalyzeAutocorrelation) of the active residuals
// of the configured streams that read one of `c`'s shifted recording streams, each in time order; 1 without any.
double ShiftedAutocorrelationTime(const TrainingFits& fits, const Candidate& c,
                                  const std::vector<estimator::MeasurementResidual>& residuals) {
  double tau = 1.0;
  for (const auto& [name, stream] : fits.nominal.streams) {
    const bool shifted = std::any_of(stream.sources.begin(), stream.sources.end(), [&](const auto& source) {
      return std::find(c.shifted.begin(), c.shifted.end(), source.second) != c.shifted.end();
    });
    if (!shifted) continue;
    std::vector<const estimator::MeasurementResidual*> rows;
    for (const estimator::MeasurementResidual& r : residuals)
      if (r.active && r.stream == name) rows.push_back(&r);
    std::stable_sort(rows.begin(), rows.end(), [](const auto* x, const auto* y) { return x->t < y->t; });
    std::vector<Eigen::VectorXd> series;
    for (const estimator::MeasurementResidual* r : rows) series.push_back(r->whitened);
    tau = std::max(tau, estimator::AnalyzeAutocorrelation(series).integrated_time);
  }
  return tau;
}

// The training part's chi-square with `c`'s streams shifted by k * period (|k| <= k_max, the time-shift range),
// fitted on demand, each fit warm-started from the nearest shift fitted so far (the poses follow the shifted stream,
// so the unshifted fit is a poor start far from 0).
class ShiftGrid {
 public:
  ShiftGrid(const TrainingFits& fits, const Candidate& c, const State& base)
      : fits_(fits), c_(c), base_(base), k_max_(static_cast<int>(std::floor(fits.margin_s / fits.period))) {
    points_[0] = {base.train_chi2, base.train_values, base.train_trajectory};
  }

  int k_max() const { return k_max_; }
  const SearchPoint& At(int k) const { return points_.at(k); }

  Result<double> Chi2(int k) {
    if (points_.count(k)) return points_[k].chi2;
    const SearchPoint* from = &points_.at(NearestPoint(points_, k));
    FitSpec spec = fits_.WarmFrom(base_, from->values, &from->trajectory);
    for (const std::string& s : c_.shifted) spec.shift_s[s] = k * fits_.period;
    auto fit = fits_.Run(spec);
    if (!fit.ok()) return fit.status();
    points_[k] = {fit.value().chi2, fit.value().values, fit.value().trajectory};
    return fit.value().chi2;
  }

 private:
  const TrainingFits& fits_;
  const Candidate& c_;
  const State& base_;
  int k_max_;
  std::map<int, SearchPoint> points_;
};

// A least-squares parabola a u^2 + b u + c over a window of grid points, with its residual variance and (X^T X)^-1.
struct Parabola {
  double a = 0.0, b = 0.0, c = 0.0, jitter2 = 0.0;
  Eigen::Matrix3d XtX_inv = Eigen::Matrix3d::Zero();
};

// Walks downhill from the first guess `best` in both directions; the best point.
Result<int> WalkDownhill(ShiftGrid* grid, int best) {
  if (auto f = grid->Chi2(best); !f.ok()) return f.status();
  for (int step : {1, -1}) {
    int k = best;
    for (int i = 0; i < 2 * grid->k_max(); ++i) {
      const int next = k + step;
      if (std::abs(next) > grid->k_max()) break;
      auto f = grid->Chi2(next);
      if (!f.ok()) return f.status();
      if (f.value() >= grid->At(k).chi2) break;
      k = next;
    }
    if (grid->At(k).chi2 < grid->At(best).chi2) best = k;
  }
  return best;
}

// The least-squares parabola in u = k - center over the window center +- kHalfWindow (within the range); none with
// fewer than four points.
Result<std::optional<Parabola>> FitWindow(ShiftGrid* grid, int center) {
  std::vector<int> ks;
  for (int k = center - kHalfWindow; k <= center + kHalfWindow; ++k) {
    if (std::abs(k) > grid->k_max()) continue;
    if (auto f = grid->Chi2(k); !f.ok()) return f.status();
    ks.push_back(k);
  }
  if (ks.size() < 4) return std::optional<Parabola>{};
  Eigen::MatrixXd X(static_cast<Eigen::Index>(ks.size()), 3);
  Eigen::VectorXd y(static_cast<Eigen::Index>(ks.size()));
  for (std::size_t i = 0; i < ks.size(); ++i) {
    const double u = ks[i] - center;
    X.row(static_cast<Eigen::Index>(i)) << u * u, u, 1.0;
    y[static_cast<Eigen::Index>(i)] = grid->At(ks[i]).chi2;
  }
  Parabola q;
  q.XtX_inv = (X.transpose() * X).inverse();
  const Eigen::Vector3d abc = q.XtX_inv * X.transpose() * y;
  q.a = abc[0];
  q.b = abc[1];
  q.c = abc[2];
  const double dof = static_cast<double>(ks.size()) - 3.0;
  q.jitter2 = dof > 0.0 ? (y - X * abc).squaredNorm() / dof : 0.0;
  return std::optional<Parabola>{q};
}

// The walk stops at the first step uphill, which the jitter fakes where the minimum is flat, and the window's
// parabola then has its vertex clamped at the window's edge. So while the vertex lies beyond the window's inner
// points, the window moves toward it (by at most kHalfWindow points, three times at most). Updates `best`.
Result<std::optional<Parabola>> CentreWindowOnVertex(ShiftGrid* grid, int* best) {
  auto parabola = FitWindow(grid, *best);
  if (!parabola.ok()) return parabola.status();
  for (int move = 0; move < 3 && parabola.value() && parabola.value()->a > 0.0; ++move) {
    const double u = -parabola.value()->b / (2.0 * parabola.value()->a);
    if (std::abs(u) <= kHalfWindow - 1) break;
    const double reach = kHalfWindow;
    const int next =
        std::clamp(*best + static_cast<int>(std::lround(std::clamp(u, -reach, reach))), -grid->k_max(), grid->k_max());
    if (next == *best) break;
    *best = next;
    parabola = FitWindow(grid, *best);
    if (!parabola.ok()) return parabola.status();
  }
  return parabola;
}

}  // namespace

Result<CandidateFit> FitTimeShift(const TrainingFits& fits, const Candidate& c, const State& base, double guess_s,
                                  CandidateFit cf) {
  EffectEstimate& e = cf.estimate;
  e.dof = 1;
  ShiftGrid grid(fits, c, base);
  // The first guess on the grid, the walk downhill, the window's parabola.
  const int guess = std::clamp(static_cast<int>(std::lround(guess_s / fits.period)), -grid.k_max(), grid.k_max());
  auto walked = WalkDownhill(&grid, guess);
  if (!walked.ok()) return walked.status();
  int best = walked.value();
  auto parabola = CentreWindowOnVertex(&grid, &best);
  if (!parabola.ok()) return parabola.status();

  // The vertex (within the window) and its standard deviation; the best grid point without a parabola.
  double k_hat = best;
  double chi2_min = grid.At(best).chi2;
  double stdev = std::numeric_limits<double>::quiet_NaN();
  if (parabola.value() && parabola.value()->a > 0.0) {
    const Parabola& q = *parabola.value();
    const double u_hat =
        std::clamp(-q.b / (2.0 * q.a), -static_cast<double>(kHalfWindow), static_cast<double>(kHalfWindow));
    k_hat = best + u_hat;
    chi2_min = q.a * u_hat * u_hat + q.b * u_hat + q.c;
    const Eigen::Vector3d J(q.b / (2.0 * q.a * q.a), -1.0 / (2.0 * q.a), 0.0);
    const double vertex_var = q.jitter2 * J.dot(q.XtX_inv * J);
    stdev = fits.period * std::sqrt(1.0 / q.a + vertex_var);
  }
  const double shift = k_hat * fits.period;
  e.parameters[c.shift_parameter] = shift;
  e.std[c.shift_parameter] = stdev;
  e.lr_raw = base.train_chi2 - chi2_min;
  for (const std::string& s : c.shifted) cf.next.shift_s[s] = shift;

  // The state the next rounds build on: an actual fit at the chosen shift. The parabola's vertex chi2 is the test
  // statistic's, but it lies below what any one shift reaches by the jitter, and later candidates compared with it
  // would lose that much of their own drop.
  FitSpec spec = fits.WarmFrom(base, grid.At(best).values, &grid.At(best).trajectory);
  spec.shift_s = cf.next.shift_s;
  const bool hac = estimator::UsesHac(fits.std_method, fits.train);
  spec.keep_residuals = hac;
  auto fit = fits.Run(spec);
  if (!fit.ok()) return fit.status();
  if (hac) e.std[c.shift_parameter] = stdev * std::sqrt(ShiftedAutocorrelationTime(fits, c, fit.value().residuals));
  cf.next.train_values = fit.value().values;
  cf.next.train_trajectory = fit.value().trajectory;
  cf.next.train_chi2 = fit.value().chi2;
  return cf;
}

}  // namespace roamlab::gap::internal
