#include "eval/montecarlo.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>

namespace roamlab::eval {

RunNees MatchedNees(const Trajectory& estimate, const std::vector<Eigen::Matrix3d>& position_covariance,
                    const Trajectory& truth) {
  RunNees r;
  std::size_t j = 0;
  double sq = 0.0;
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    while (j < truth.size() && truth[j].t < estimate[i].t) ++j;
    if (j == truth.size() || truth[j].t != estimate[i].t) continue;
    const Eigen::Vector3d e = estimate[i].p_world_body - truth[j].p_world_body;
    r.t.push_back(estimate[i].t);
    r.nees.push_back(PositionNees(e, position_covariance[i]));
    sq += e.squaredNorm();
  }
  if (r.t.empty()) return r;
  r.ate_m = std::sqrt(sq / r.t.size());
  double sum = 0.0;
  for (double n : r.nees) sum += n;
  r.mean_nees = sum / r.nees.size();
  return r;
}

Result<MonteCarloNees> AggregateRunNees(const std::vector<RunNees>& runs, double t0_s) {
  // The common time grid.
  std::vector<Time> grid = runs.front().t;
  for (const RunNees& r : runs) {
    std::vector<Time> common;
    std::set_intersection(grid.begin(), grid.end(), r.t.begin(), r.t.end(), std::back_inserter(common));
    grid = std::move(common);
  }
  if (grid.empty()) return Status::Error("the runs share no time stamp");

  // Each run's series on the grid.
  std::vector<std::vector<double>> series;
  for (const RunNees& r : runs) {
    std::vector<double> s;
    std::size_t j = 0;
    for (Time t : grid) {
      while (r.t[j] != t) ++j;
      s.push_back(std::isnan(r.nees[j]) ? std::numeric_limits<double>::infinity() : r.nees[j]);
    }
    series.push_back(std::move(s));
  }
  return AggregateNees(grid, series, 3, t0_s);
}

}  // namespace roamlab::eval
