#include "eval/association.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>

#include "common/check.h"

namespace roamlab::eval {
namespace {

std::vector<Time> Stamps(const Trajectory& trajectory) {
  std::vector<Time> t;
  t.reserve(trajectory.size());
  for (const StampedPose& pose : trajectory) t.push_back(pose.t);
  return t;
}

bool StrictlyIncreasing(const std::vector<Time>& t) {
  for (std::size_t i = 1; i < t.size(); ++i)
    if (!(t[i - 1] < t[i])) return false;
  return true;
}

std::int64_t AbsoluteDifferenceNs(Time a, Time b) { return std::llabs(a.nanoseconds() - b.nanoseconds()); }

}  // namespace

std::string AssociationOptions::Validate() const {
  if (!std::isfinite(max_time_difference_s) || max_time_difference_s < 0.0)
    return "max_time_difference_s must be finite and >= 0";
  return "";
}

Association AssociateByTime(const std::vector<Time>& estimate, const std::vector<Time>& reference,
                            const AssociationOptions& options) {
  const std::string problem = options.Validate();
  ROAMLAB_CHECK(problem.empty(), problem);
  ROAMLAB_CHECK(StrictlyIncreasing(estimate), "estimate stamps are not strictly increasing");
  ROAMLAB_CHECK(StrictlyIncreasing(reference), "reference stamps are not strictly increasing");
  const std::int64_t tolerance_ns = std::llround(options.max_time_difference_s * 1e9);

  Association association;
  association.estimate_size = estimate.size();
  association.reference_size = reference.size();
  std::vector<std::int64_t> difference_ns;  // of each pair, to recompute the maximum after replacements
  std::size_t r = 0;
  for (std::size_t e = 0; e < estimate.size(); ++e) {
    // Nearest reference stamp: advance while the next one is at least as close (stamps increase on both sides).
    if (reference.empty()) break;
    while (r + 1 < reference.size() &&
           AbsoluteDifferenceNs(reference[r + 1], estimate[e]) <= AbsoluteDifferenceNs(reference[r], estimate[e]))
      ++r;
    const std::int64_t d = AbsoluteDifferenceNs(reference[r], estimate[e]);
    if (d > tolerance_ns) continue;
    // One-to-one: a reference pose already taken by the previous estimate pose goes to the closer of the two.
    if (!association.reference_index.empty() && association.reference_index.back() == r) {
      if (d < difference_ns.back()) {
        association.estimate_index.back() = e;
        difference_ns.back() = d;
      }
      continue;
    }
    association.estimate_index.push_back(e);
    association.reference_index.push_back(r);
    difference_ns.push_back(d);
  }
  std::int64_t max_ns = 0;
  for (std::int64_t d : difference_ns) max_ns = std::max(max_ns, d);
  association.max_time_difference_s = static_cast<double>(max_ns) * 1e-9;
  return association;
}

Association AssociateByTime(const Trajectory& estimate, const Trajectory& reference,
                            const AssociationOptions& options) {
  return AssociateByTime(Stamps(estimate), Stamps(reference), options);
}

MatchedTrajectories SelectMatched(const Trajectory& estimate, const Trajectory& reference,
                                  const Association& association) {
  MatchedTrajectories matched;
  matched.estimate.reserve(association.matched());
  matched.reference.reserve(association.matched());
  for (std::size_t i = 0; i < association.matched(); ++i) {
    ROAMLAB_CHECK(association.estimate_index[i] < estimate.size() && association.reference_index[i] < reference.size(),
                  "association does not fit the trajectories");
    matched.estimate.push_back(estimate[association.estimate_index[i]]);
    matched.reference.push_back(reference[association.reference_index[i]]);
  }
  return matched;
}

}  // namespace roamlab::eval
