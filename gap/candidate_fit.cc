#include "gap/internal/candidate_fit.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "gap/internal/time_shift.h"

namespace roamlab::gap::internal {
namespace {

// A clock offset fitted as a parameter (imu_time_offset): the largest the first-order model is trusted with. The fit
// is of the streams' timing conventions too (the estimator holds a gyroscope reading over the interval after its
// stamp, the simulator reads the rate at it), so the range holds those plus the offsets the benchmark draws; a
// smaller range sends the small offsets to the grid.
constexpr double kFirstOrderOffsetS = 0.1;
constexpr double kProfileStepS = 0.01;  // the profile's step: a master period of the 100 Hz drives

// A parameter-slot candidate: its parameters freed with the full solver, warm-started at `base`.
Result<CandidateFit> FitSlots(const TrainingFits& fits, const Candidate& c, const State& base, CandidateFit cf) {
  EffectEstimate& e = cf.estimate;
  e.dof = c.free_dof;
  FitSpec spec = fits.WarmFrom(base, base.train_values, &base.train_trajectory);
  spec.extra_free.insert(c.free.begin(), c.free.end());
  spec.observability = true;
  auto fit = fits.Run(spec);
  if (!fit.ok()) return fit.status();
  c.describe(fit.value().values, fit.value().std, &e);
  e.lr_raw = base.train_chi2 - fit.value().chi2;
  cf.next.extra_free = spec.extra_free;
  cf.next.train_values = fit.value().values;
  cf.next.train_trajectory = fit.value().trajectory;
  cf.next.train_chi2 = fit.value().chi2;
  return cf;
}

// The training part's chi-square with a clock offset held at start + j * kProfileStepS, fitted on demand, each fit
// warm-started from the nearest offset fitted so far.
class OffsetProfile {
 public:
  OffsetProfile(const TrainingFits& fits, const State& base, const std::string& parameter)
      : fits_(fits),
        base_(base),
        parameter_(parameter),
        start_(base.train_values.count(parameter) ? base.train_values.at(parameter)[0] : 0.0) {
    points_[0] = {base.train_chi2, base.train_values, base.train_trajectory};
  }

  double Offset(double j) const { return start_ + j * kProfileStepS; }
  bool Has(int j) const { return points_.count(j) > 0; }
  const SearchPoint& At(int j) const { return points_.at(j); }

  Result<double> Chi2(int j) {
    if (points_.count(j)) return points_[j].chi2;
    const SearchPoint& warm = points_.at(NearestPoint(points_, j));
    FitSpec spec = fits_.WarmFrom(base_, warm.values, &warm.trajectory);
    spec.values[parameter_] = Eigen::VectorXd::Constant(1, Offset(j));
    auto f = fits_.Run(spec);
    if (!f.ok()) return f.status();
    points_[j] = {f.value().chi2, f.value().values, f.value().trajectory};
    return f.value().chi2;
  }

  // Walks downhill from 0 in both directions within the first-order range; the best point.
  Result<int> Walk() {
    int best = 0;
    for (int direction : {1, -1}) {
      int j = best;
      while (std::abs(Offset(j + direction)) <= kFirstOrderOffsetS + 0.5 * kProfileStepS) {
        auto f = Chi2(j + direction);
        if (!f.ok()) return f.status();
        if (f.value() >= points_.at(j).chi2) break;
        j += direction;
      }
      if (points_.at(j).chi2 < points_.at(best).chi2) best = j;
    }
    return best;
  }

 private:
  const TrainingFits& fits_;
  const State& base_;
  std::string parameter_;
  double start_;
  std::map<int, SearchPoint> points_;
};

// The offset fitted as a parameter, from the vertex of the parabola through the profile's best point and its
// neighbours: the estimate, its std from the solver's covariance, and the state with it accepted.
Status FitOffsetAtVertex(const TrainingFits& fits, const Candidate& c, const State& base, const OffsetProfile& profile,
                         int best, CandidateFit* cf) {
  const std::string& p = c.free.front();
  const double y0 = profile.At(best - 1).chi2, y1 = profile.At(best).chi2, y2 = profile.At(best + 1).chi2;
  const double curvature = y0 - 2.0 * y1 + y2;
  const double vertex =
      profile.Offset(best + (curvature > 0.0 ? std::clamp(0.5 * (y0 - y2) / curvature, -1.0, 1.0) : 0.0));
  FitSpec spec = fits.WarmFrom(base, profile.At(best).values, &profile.At(best).trajectory);
  spec.values[p] = Eigen::VectorXd::Constant(1, vertex);
  spec.extra_free.insert(p);
  spec.observability = true;
  auto f = fits.Run(spec);
  if (!f.ok()) return f.status();
  const FitOutcome& fit = f.value();
  EffectEstimate& e = cf->estimate;
  const double coarse = base.shift_s.count(c.shifted.front()) ? base.shift_s.at(c.shifted.front()) : 0.0;
  e.parameters[c.shift_parameter] = coarse + fit.values.at(p)[0];
  e.std[c.shift_parameter] = fit.std.count(p) ? fit.std.at(p)[0] : std::numeric_limits<double>::quiet_NaN();
  e.lr_raw = base.train_chi2 - fit.chi2;
  cf->next.extra_free = base.extra_free;
  cf->next.extra_free.insert(p);
  cf->next.train_values = fit.values;
  cf->next.train_trajectory = fit.trajectory;
  cf->next.train_chi2 = fit.chi2;
  return Status::Ok();
}

// An offset far beyond the first-order range is not reached from inside it: the reading moved along its smoothed
// slope is a poor time shift there, and the fit settles on a small offset. So the stamp shifts at the range's ends
// are fitted too: the one that beats `chi2` (the continuous fit's), or 0 when neither does.
Result<double> EdgeShiftBeating(const TrainingFits& fits, const Candidate& c, const State& base, double chi2) {
  const int k_edge = std::min(static_cast<int>(std::floor(fits.margin_s / fits.period)),
                              static_cast<int>(std::ceil(kFirstOrderOffsetS / fits.period)));
  double edge_s = 0.0, edge_chi2 = chi2;
  for (int side : {-1, 1}) {
    FitSpec edge = fits.WarmFrom(base, base.train_values, &base.train_trajectory);
    for (const std::string& s : c.shifted) edge.shift_s[s] = side * k_edge * fits.period;
    auto g = fits.Run(edge);
    if (!g.ok()) return g.status();
    if (g.value().chi2 < edge_chi2) {
      edge_chi2 = g.value().chi2;
      edge_s = side * k_edge * fits.period;
    }
  }
  return edge_s;
}

// A clock offset as a parameter, fitted with the full solver (the pairing of the samples never changes, so the
// chi-square is smooth in it; std from the solver's covariance). Every pose follows the IMU's timing, and
// Levenberg-Marquardt started at 0 creeps toward the offset (it can stay near 0 up to the iteration cap), so it starts
// from a profile: fits with the offset held at multiples of kProfileStepS, walked downhill, and the vertex of the
// parabola through the best three. When the walk reaches the first-order model's range (kFirstOrderOffsetS), or a
// stamp shift at the range's ends fits better, the offset is searched on the grid of stamp shifts instead (beyond its
// range the first-order term is no time shift): then false, with `guess_s` the grid search's first guess and `cf`'s
// state back at `base`.
Result<bool> FitClockOffset(const TrainingFits& fits, const Candidate& c, const State& base, CandidateFit* cf,
                            double* guess_s) {
  cf->estimate.dof = 1;
  OffsetProfile profile(fits, base, c.free.front());
  auto best = profile.Walk();
  if (!best.ok()) return best.status();
  if (!profile.Has(best.value() - 1) || !profile.Has(best.value() + 1)) return false;
  if (Status s = FitOffsetAtVertex(fits, c, base, profile, best.value(), cf); !s.ok()) return s;
  auto edge_s = EdgeShiftBeating(fits, c, base, cf->next.train_chi2);
  if (!edge_s.ok()) return edge_s.status();
  if (edge_s.value() == 0.0) return true;
  *guess_s = edge_s.value();
  cf->next = base;
  return false;
}

}  // namespace

int NearestPoint(const std::map<int, SearchPoint>& points, int k) {
  int nearest = 0;
  for (const auto& [j, point] : points)
    if (std::abs(j - k) < std::abs(nearest - k)) nearest = j;
  return nearest;
}

Result<FitOutcome> TrainingFits::Run(const FitSpec& spec_in) const {
  FitSpec spec = spec_in;
  spec.std_method = std_method;
  auto fit = Fit(nominal, train, spec);
  ++*fits;
  return fit;
}

void TrainingFits::Say(const std::string& line) const {
  if (progress) progress(line);
}

FitSpec TrainingFits::WarmFrom(const State& base, const std::map<std::string, Eigen::VectorXd>& values,
                               const Trajectory* trajectory) const {
  FitSpec spec;
  spec.mode = FitMode::kWarm;
  spec.values = values;
  spec.extra_free = base.extra_free;
  spec.shift_s = base.shift_s;
  spec.initial = trajectory;
  return spec;
}

Result<CandidateFit> FitCandidate(const TrainingFits& fits, const Candidate& c, const State& base) {
  CandidateFit cf;
  cf.next = base;
  cf.estimate.name = c.name;
  if (c.shifted.empty()) return FitSlots(fits, c, base, std::move(cf));
  double guess_s = c.guess_s;  // a time shift's first guess on the grid
  if (!c.free.empty()) {
    auto done = FitClockOffset(fits, c, base, &cf, &guess_s);
    if (!done.ok()) return done.status();
    if (done.value()) return cf;
    fits.Say("candidate " + c.name + ": beyond the first-order range, searched on the grid of stamp shifts");
  }
  return FitTimeShift(fits, c, base, guess_s, std::move(cf));
}

}  // namespace roamlab::gap::internal
