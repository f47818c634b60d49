// Association of an estimated trajectory with a reference (ground-truth) trajectory by time stamp.
//
// Each estimate pose is paired with the reference pose nearest in time when |t_estimate - t_reference| does not exceed
// the tolerance (0: identical stamps only). Pairs are one-to-one and increasing in both indices: when two consecutive
// estimate poses pick the same reference pose, the closer one keeps it. Nothing is interpolated, so a tolerance of a
// few sample periods adds the motion over the stamp difference to every error; report max_time_difference_s with the
// metrics.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "common/time.h"
#include "recording/trajectory.h"

namespace roamlab::eval {

struct AssociationOptions {
  double max_time_difference_s = 0.0;  // [s], >= 0; 0 accepts identical stamps only

  // Empty when usable, otherwise what is wrong.
  std::string Validate() const;
};

struct Association {
  std::vector<std::size_t> estimate_index;   // i-th pair: estimate[estimate_index[i]] ...
  std::vector<std::size_t> reference_index;  // ... with reference[reference_index[i]]
  double max_time_difference_s = 0.0;        // largest |t_estimate - t_reference| over the pairs [s]
  std::size_t estimate_size = 0;             // poses offered on each side
  std::size_t reference_size = 0;

  std::size_t matched() const { return estimate_index.size(); }
};

// Pairs the stamps. Both lists must be strictly increasing (CHECK); options must validate (CHECK).
Association AssociateByTime(const std::vector<Time>& estimate, const std::vector<Time>& reference,
                            const AssociationOptions& options);
Association AssociateByTime(const Trajectory& estimate, const Trajectory& reference, const AssociationOptions& options);

// The paired poses as two trajectories of equal length (each keeps its own stamps).
struct MatchedTrajectories {
  Trajectory estimate;
  Trajectory reference;
};
MatchedTrajectories SelectMatched(const Trajectory& estimate, const Trajectory& reference,
                                  const Association& association);

}  // namespace roamlab::eval
