// Fitting one candidate of the library on the training part (gap/diagnose.h, step 3), on top of the effects accepted
// so far: a parameter slot freed with the full solver, a clock offset fitted as a parameter from a profile over it,
// or a time shift searched on the master period's grid (gap/internal/time_shift.h).
#pragma once

#include <functional>
#include <map>
#include <set>
#include <string>

#include <Eigen/Core>

#include "common/status.h"
#include "estimator/config.h"
#include "gap/diagnose.h"
#include "gap/internal/effect_library.h"
#include "gap/internal/fit.h"
#include "gap/locate.h"
#include "recording/recording.h"
#include "recording/trajectory.h"

namespace roamlab::gap::internal {

// The state the rounds build on: accepted effects and their fits.
struct State {
  std::set<std::string> extra_free;
  std::map<std::string, double> shift_s;
  std::map<std::string, Eigen::VectorXd> train_values;
  Trajectory train_trajectory;
  double train_chi2 = 0.0;
  int train_measurements = 0;
  double heldout_chi2 = 0.0;
  std::map<std::string, StreamFit> heldout;
  std::map<std::string, ComponentLevel> heldout_components;
};

// A candidate fitted on the training part on top of a state: its estimate, and the state with it accepted.
struct CandidateFit {
  EffectEstimate estimate;
  State next;
};

// A fit of the training part at one point of a 1-D search (a clock offset's profile, a stream's time shift): its
// chi-square and where the next point's fit starts from.
struct SearchPoint {
  double chi2 = 0.0;
  std::map<std::string, Eigen::VectorXd> values;
  Trajectory trajectory;
};

// The key of `points` nearest `k` (the smallest on ties; 0 when none is nearer), the warm start of k's fit.
int NearestPoint(const std::map<int, SearchPoint>& points, int k);

// What every fit of a candidate shares: the nominal model, the training part, the pose grid, the time-shift range,
// the count of calibrations run and the progress lines.
struct TrainingFits {
  const estimator::EstimatorConfig& nominal;
  const recording::Recording& train;
  double period = 0.01;   // the master stream's sample period [s]
  double margin_s = 0.0;  // the time-shift range (DiagnoseOptions::max_shift_s)
  int* fits = nullptr;    // incremented by every fit
  std::function<void(const std::string&)> progress;
  estimator::CalibrationOptions::StdMethod std_method = estimator::CalibrationOptions::StdMethod::kAuto;

  // Fits the training part as `spec` says, counting the fit.
  Result<FitOutcome> Run(const FitSpec& spec) const;
  void Say(const std::string& line) const;
  // A warm fit from `base` (its extra free parameters and shifts, warm-started at `values` and `trajectory`).
  FitSpec WarmFrom(const State& base, const std::map<std::string, Eigen::VectorXd>& values,
                   const Trajectory* trajectory) const;
};

// Fits candidate `c` on top of `base`. Errors: a fit failed (the candidate is then rejected).
Result<CandidateFit> FitCandidate(const TrainingFits& fits, const Candidate& c, const State& base);

}  // namespace roamlab::gap::internal
