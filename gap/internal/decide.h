// Deciding on the candidates (gap/diagnose.h, step 3) and the verdict: the likelihood-ratio statistic against the
// nominal model or the baseline (Score), the held-out evaluation of a state, the tests in order of Delta BIC that
// keep at most one candidate per round, and the verdict from what stays inconsistent.
#pragma once

#include <map>
#include <set>
#include <string>
#include <vector>

#include "common/status.h"
#include "estimator/config.h"
#include "gap/diagnose.h"
#include "gap/internal/candidate_fit.h"
#include "gap/locate.h"
#include "recording/recording.h"
#include "recording/trajectory.h"

namespace roamlab::gap::internal {

// The likelihood-ratio test and BIC of a fitted candidate, and its parameters relative to the baseline.
// Without a baseline the null hypothesis is the nominal model (parameters at their neutral values): LR = the chi2 drop
// ~ chi2(k). With one, the nominal model's own structure already moves the candidate's parameters on MuJoCo data
// without any effect (e.g. the tires' cornering compliance on the nominal ATV simulation): the null hypothesis is
// then "the parameters take the baseline's values theta_0", and LR is its quadratic (Wald) form about the fit,
// sum ((theta - theta_0)^2 / (sigma^2 + sigma_0^2)) with both fits' standard deviations, ~ chi2(k); a theta_0 within
// 2 sigma_0 of neutral shows no structure, and the test is then against neutral with the fit's own variance (one
// noisy draw of nothing would only blur it). The parameters are always reported as departures from theta_0 plus the
// neutral value, both variances added (so that the reported std covers the error).
// p = 1 - F_chi2(k)(LR), Delta BIC = -LR + k ln n with n the training part's measurements.
void Score(const Baseline* baseline, int measurements, EffectEstimate* e);

// A fit of the held-out part: chi2, per stream and per component (ComponentKey).
struct HeldOut {
  double chi2 = 0.0;
  std::map<std::string, StreamFit> streams;
  std::map<std::string, ComponentLevel> components;
};

// Fits the held-out part with every parameter fixed at a state's training values (poses only), each fit after the
// first warm-started at the first one's poses.
class HeldoutEvaluator {
 public:
  HeldoutEvaluator(const estimator::EstimatorConfig& nominal, const recording::Recording& test, int* fits)
      : nominal_(nominal), test_(test), fits_(fits) {}
  Result<HeldOut> Evaluate(const State& s);

 private:
  const estimator::EstimatorConfig& nominal_;
  const recording::Recording& test_;
  int* fits_;
  Trajectory trajectory_;
};

// What a round's candidates are judged against.
struct RoundRules {
  const DiagnoseOptions& options;
  const State& state;                                   // the effects kept so far
  const std::vector<std::string>& located_keys;         // the components Locate found inconsistent
  const std::map<std::string, double>& heldout_levels;  // the nominal model's held-out level per component
  // The held-out chi2 of the nominal model: the share is of the effects kept so far and the candidate together
  // (their held-out drop from the nominal model), so that a later effect that refines an explained mismatch is not
  // judged against the whole remainder alone.
  double nominal_heldout_chi2 = 0.0;
};

// In order of Delta BIC (`fits` sorted), the first candidate that passes the likelihood-ratio test, BIC, the time-shift
// range and the held-out tests is kept (its decision "accepted", its state's held-out fit filled); the others get the
// reason they failed. One that fails a held-out test (a structure of the training part only, e.g. a clock offset that
// jumps within the run) does not hide the next one, and goes into `dropped` (not tried again in the later rounds).
// With options.heldout_all_candidates in round 0, the candidates after the kept one that pass p and BIC are evaluated
// on the held-out part for the record (decisions unchanged). Returns the kept candidate, or null.
CandidateFit* DecideRound(const RoundRules& rules, int round, HeldoutEvaluator* heldout,
                          std::vector<CandidateFit>* fits, std::set<std::string>* dropped);

// The verdict and the unexplained components (Diagnosis::verdict, unexplained) from the located components, the
// accepted effects and the held-out fit with them. Without an accepted effect every inconsistent component is
// unexplained. With accepted effects, an inconsistent component stays unexplained when the held-out part, fitted with
// the effects, is still inconsistent in it against the nominal model's held-out level (the baseline's; Locate's
// rule) by an excess the stated noise can tell from noise (SignificantExcess): structure that the named effects do
// not account for (an out-of-library effect can pull a library parameter by a little and pass the tests, as an
// accelerometer gain error passes on to the attitude and a gyroscope scale), so the verdict is then "unknown". The
// excess test keeps components whose level is far below 1 (an oval tire's roll on a diff drive's gyroscope x) from
// overruling an effect that explains what the likelihood sees.
void Verdict(const std::map<std::string, double>& heldout_levels, Diagnosis* out);

}  // namespace roamlab::gap::internal
