// The rows of a stream after a gap in its source (an outage, or a clock that jumped forward, which stamps every later
// row late): tracking (tracking.cc) and calibration (calibration.cc) hold an absolute stream's rows after a gap out of
// a solve and admit each on its innovation at the estimate solved without it (docs/methods-estimator.md, outlier
// gating).
#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/time.h"
#include "estimator/config.h"
#include "estimator/internal/linearization.h"
#include "recording/recording.h"

namespace roamlab::estimator::internal {

// Per configured stream with a single recording source, the stamps at which that source's rows resume after a gap
// (recording::CheckStreamHealth), in time order; with absolute_only, only the streams whose model places the pose in
// the world frame (a motion-capture pose, a GPS fix).
std::map<std::string, std::vector<Time>> GapResumes(const EstimatorConfig& config, const recording::Recording& rec,
                                                    bool absolute_only);

// The innovation test of a measurement left out of the solve that reached the current estimate: its whitened error r
// (wf, linearized at that estimate with the Jacobians of its variables `free`, indices into its variables) against
// I + J P J^T, J those whitened Jacobians side by side and P the variables' joint marginal covariance (tangent, stacked
// in the same order). Tested after a solve that includes it, the error of an absolute measurement shrinks by the
// estimate's uncertainty against its noise: where dead reckoning has left a pose centimetres uncertain, a millimetre
// measurement pulls the estimate onto itself and then fits, whatever it says. True when r^T (I + J P J^T)^-1 r is
// within the chi-square quantile `probability` of r's dimension.
bool InnovationWithin(double probability, const WhitenedFactor& wf, const std::vector<int>& free,
                      const Eigen::MatrixXd& covariance);

}  // namespace roamlab::estimator::internal
