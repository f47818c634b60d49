// Fitting the nominal model, with a candidate effect's parameters freed or its streams' stamps shifted, on a part of
// a recording: the one calibration call every step of the diagnosis (gap/diagnose.h) makes.
#pragma once

#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "estimator/calibration.h"
#include "estimator/config.h"
#include "recording/recording.h"
#include "recording/trajectory.h"

namespace roamlab::gap::internal {

// How the fit treats the calibration parameters.
enum class FitMode {
  kStaged,  // the configuration's stages from its initial values
  kWarm,    // one stage, every free parameter plus the candidate's, from given values
  kFixed,   // every parameter fixed at given values; poses only
};

struct FitSpec {
  FitMode mode = FitMode::kStaged;
  std::map<std::string, Eigen::VectorXd> values;  // warm / fixed values (names absent: the configuration's)
  std::set<std::string> extra_free;               // freed on top of the configuration's free parameters
  std::map<std::string, double> shift_s;          // recording stream -> seconds subtracted from its stamps
  bool keep_residuals = false;
  bool observability = false;
  estimator::CalibrationOptions::StdMethod std_method = estimator::CalibrationOptions::StdMethod::kAuto;
  const Trajectory* initial = nullptr;  // warm-start poses (estimator/calibration.h)
};

struct FitOutcome {
  double chi2 = 0.0;
  int measurements = 0;
  std::map<std::string, Eigen::VectorXd> values;  // every configured parameter (free ones estimated)
  std::map<std::string, Eigen::VectorXd> std;     // free ones, when observability was asked for
  std::vector<estimator::MeasurementResidual> residuals;
  Trajectory trajectory;
};

// Calibrates `nominal` as `spec` says on `recording`; chi2 = 2 * the final cost (estimator/solver.h).
Result<FitOutcome> Fit(const estimator::EstimatorConfig& nominal, const recording::Recording& recording,
                       const FitSpec& spec);

// The part of a recording in [t0, t1], cut so that a time shift up to margin_s never changes which measurements
// attach (a changing count would move the chi-square by whole measurements): the master stream's sources (the poses)
// lose margin_s at both ends, so that shifted samples of the other streams on the master's grid still find as many
// poses; streams in `position` (fixes attached to one pose, which constrain no attitude) lose 2 margin_s before any
// shift, so that they all stay inside the poses' span.
recording::Recording Slice(const recording::Recording& in, double t0, double t1, const std::set<std::string>& master,
                           const std::set<std::string>& position, double margin_s);

// The recording with the stamps of the streams in `shift_s` moved: t' = t - shift.
recording::Recording Shifted(const recording::Recording& in, const std::map<std::string, double>& shift_s);

// The value of parameter `name` in a configuration (its initial value, or the model slot's default).
std::optional<Eigen::VectorXd> ConfiguredValue(const estimator::EstimatorConfig& config, const std::string& name);

// The parameter a stream's slot maps to.
std::string SlotParameter(const std::string& stream, const estimator::StreamConfig& sc, const std::string& slot);

// The master stream's sample period [s] (the pose grid).
double MasterPeriod(const estimator::EstimatorConfig& config, const recording::Recording& recording);

}  // namespace roamlab::gap::internal
