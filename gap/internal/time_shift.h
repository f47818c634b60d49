// The time-shift search of a candidate (gap/diagnose.h, step 3): the chi-square of the training part at stamp shifts
// on the master period's grid k * period (where the shifted stamps fall on poses, so the nominal attachment is exact),
// walked downhill from a first guess, then a parabola through the best point and its neighbours; its curvature gives
// the standard deviation.
#pragma once

#include "common/status.h"
#include "gap/internal/candidate_fit.h"
#include "gap/internal/effect_library.h"

namespace roamlab::gap::internal {

// Searches the shift of `c`'s streams on top of `base` from `guess_s` [s]; `candidate` carries the estimate so far
// (its name and dof) and receives the shift, its std, the chi-square drop and the state at the chosen shift.
// Errors: a fit failed.
Result<CandidateFit> FitTimeShift(const TrainingFits& fits, const Candidate& c, const State& base, double guess_s,
                                  CandidateFit candidate);

}  // namespace roamlab::gap::internal
