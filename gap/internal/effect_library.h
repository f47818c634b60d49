// The library of candidate effects (gap/diagnose.h, step 3): which candidates apply to a nominal configuration, what
// each frees or shifts, and how its fitted values read as the simulator's effect parameters (sim/scenario.h).
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "estimator/calibration.h"
#include "estimator/config.h"
#include "gap/diagnose.h"
#include "gap/locate.h"

namespace roamlab::gap::internal {

// One candidate of the library, as it applies to a configuration.
struct Candidate {
  std::string name;
  std::string stream;  // configured stream whose dispersion scales its statistic
  // A parameter-slot effect: estimator parameters freed, and how their values become the effect's parameters.
  std::vector<std::string> free;
  std::function<void(const std::map<std::string, Eigen::VectorXd>& value,
                     const std::map<std::string, Eigen::VectorXd>& std, EffectEstimate* out)>
      describe;
  // A time-shift effect: recording streams whose stamps move by the parameter (t' = t - shift). With `free` as well,
  // a clock offset fitted as a parameter (imu_time_offset: the IMU's time_offset_s, models/imu_time_offset.h), the
  // stamps moving by whole master periods only when the offset is beyond the first-order model's range.
  std::vector<std::string> shifted;
  std::string shift_parameter;
  double guess_s = 0.0;  // first guess of the shift
  int free_dof = 0;      // tangent dimension of `free`
};

// The candidates of CandidateNames() that apply to `config`, in that order.
std::vector<Candidate> Library(const estimator::EstimatorConfig& config);

// Sets the gps_latency candidate's first guess from the nominal fit's residuals: the fix stamped t is p(t - tau), so
// e = z_hat - z ~ tau v(t) (eq. 9), and tau is the least-squares slope of the residuals on the horizontal velocity.
void GuessGpsLatency(const estimator::EstimatorConfig& config,
                     const std::vector<estimator::MeasurementResidual>& residuals, const Conditions& conditions,
                     std::vector<Candidate>* library);

}  // namespace roamlab::gap::internal
