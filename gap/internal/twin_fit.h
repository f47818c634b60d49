// The twin diagnosis's fit of one candidate effect by running the twin again (gap/twin.h, step 3): the library of
// the simulator's effects as candidates, the parallel evaluation of perturbed twin runs, Levenberg-Marquardt over a
// candidate's parameters and the time-shift search on the physics step grid.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "gap/internal/twin_residuals.h"
#include "gap/twin.h"
#include "sim/scenario.h"

namespace roamlab::gap::internal {

struct TwinParameter {
  std::string name;  // as the simulator's effect (sim/scenario.h)
  double neutral = 0.0;
  double step = 0.0;  // finite-difference step, and the scale of the parameter in the solve
  double lo = 0.0, hi = 0.0;
};

// One candidate: a simulator effect, or a composite of several fitted together (`parts`, each a single effect's
// candidate; its `free` the parts' free parameters concatenated in order, their names distinct).
struct TwinCandidate {
  std::string label;   // the effect's name, with the wheel for axle_misalignment ("axle_misalignment wheel 1")
  std::string effect;  // the simulator's effect (a composite: its label)
  std::map<std::string, double> fixed;  // labels, not fitted (axle_misalignment's wheel); a composite's: its held
                                        // parameters, for the report (its parts hold them)
  std::vector<TwinParameter> free;
  bool time_shift = false;             // one parameter on the physics step grid, searched
  std::vector<TwinCandidate> parts{};  // a composite's effects; empty for a single effect
  // The Jacobian by central differences however many threads: a forward difference's slope is the secant over a step,
  // off by half the step times the curvature, and where the parameters trade against each other that bias moves the
  // fit's minimum by a good part of a step.
  bool central = false;
  // Tried by default only on several training runs: on one run, of one kind of motion, its parameters trade against
  // each other or against another candidate's (gap/twin.cc DefaultCandidate).
  bool several_runs = false;
};

// The candidates `nominal` supports (its sensors and robot kind; the scenario validates with each).
std::vector<TwinCandidate> TwinCandidates(const sim::Scenario& nominal, double max_shift_s);

// The effects one twin run adds to the evaluator's base scenario.
using Patch = std::vector<sim::EffectOptions>;

// The effects of `c` at parameter values `theta` (in c.free's order): one, or a composite's parts' in order.
Patch EffectsAt(const TwinCandidate& c, const Eigen::VectorXd& theta);

// The simulator's effects `c` sets (a composite's parts').
std::vector<std::string> SimulatorEffects(const TwinCandidate& c);

// One recording the fit runs the twin of: its real recording, the twin's runner, the layout of its training part and
// the twin's duration (s after the recording's first stamp).
struct FitRun {
  std::string name;  // prefixes its series' names when the fit runs on more than one recording
  const recording::Recording* real = nullptr;
  const TwinRunner* runner = nullptr;
  Layout layout;
  double duration_s = 0.0;
  double scale = 1.0;  // its whitened residuals' factor in the fit (gap/twin.h TwinDiagnoseOptions::train_weight)
};

// A layout's summed chi-square weight: its entries, each its series' weight squared.
double SummedWeight(const Layout& layout);

// Per run (summed weights S_r > 0, in order) the residuals' factor sqrt(S / (R S_r)) that makes every run's summed
// weight S / R, S the total and R the runs' number.
std::vector<double> EqualRunScales(const std::vector<double>& summed_weights);

// The runs' layouts as one residual vector: the series concatenated in the runs' order, their offsets moved, and with
// more than one run each series' name prefixed "NAME: " so that the HAC covariance (ComputeTwinCovariance) treats
// each run's series as independent of the others'.
Layout CombinedLayout(const std::vector<FitRun>& runs);

// The runs' whitened training residuals, each run's times its scale, concatenated as CombinedLayout, for their twins
// (one per run, in order).
Eigen::VectorXd CombinedResiduals(const std::vector<FitRun>& runs, const std::vector<recording::Recording>& twins);

// Runs the twin of patched scenarios (the base with a patch's effects each) for every run, the runs x patches in
// parallel, and returns the whitened training residuals of each patch (CombinedLayout's entries, each run's times its
// scale; NaN where a twin has no sample). A patch fails when any run's twin fails.
class TwinEvaluator {
 public:
  TwinEvaluator(const sim::Scenario& base, const std::vector<FitRun>& runs, int threads)
      : base_(base), runs_of_(runs), layout_(CombinedLayout(runs)), threads_(threads) {
    for (const FitRun& run : runs)
      entry_weights_.insert(entry_weights_.end(), static_cast<std::size_t>(run.layout.size), run.scale * run.scale);
  }
  std::vector<Result<Eigen::VectorXd>> Run(const std::vector<Patch>& patches);
  int runs() const { return runs_; }
  const Layout& layout() const { return layout_; }
  // Per entry of the layout: its run's chi-square weight (FitRun::scale squared).
  const std::vector<double>& entry_weights() const { return entry_weights_; }

 private:
  const sim::Scenario& base_;
  const std::vector<FitRun>& runs_of_;
  Layout layout_;
  std::vector<double> entry_weights_;
  int threads_;
  int runs_ = 0;
};

struct CandidateOutcome {
  Eigen::VectorXd theta;       // fitted (time shifts: the parabola's vertex, sub-step); the uninformed at neutral
  std::vector<bool> informed;  // per parameter (c.free's order): fitted; the others are held at their neutral values
  TwinCovariance covariance;   // of the informed parameters of theta, in order, white and HAC (gap/twin.h)
  Patch effects;               // as applied (time shifts in whole steps)
  double chi2 = 0.0;           // training part, at `effects`
  Eigen::VectorXd residuals;   // training part, at `effects`
  int iterations = 0;
};

struct FitSettings {
  int max_iterations = 8;
  double physics_step_s = 0.001;
  int threads = 2;
};

// Fits `c` starting at its neutral values, whose residuals (the base twin's) are `base`. Only the parameters the data
// informs are fitted: from the Jacobian at the neutral values, a parameter whose conditional white std (the others
// fitted along) exceeds 5 % of its range (hi - lo), such as a gyroscope's x scale on a planar drive, is held at its
// neutral value, reported as not informed, and the others are fitted without it. The covariance from the rows
// at the fit (ComputeTwinCovariance): a least-squares fit's residuals and last Jacobian; a time shift's residuals at
// the best step moved to the parabola's vertex to first order, r_b + J (theta - b step), with J the central difference
// over the neighbouring steps.
Result<CandidateOutcome> FitCandidate(const TwinCandidate& c, const Eigen::VectorXd& base, TwinEvaluator* evaluator,
                                      const FitSettings& settings);

// Kept effects refitted together: Levenberg-Marquardt as FitCandidate over the free parameters of every part at once,
// concatenated in the parts' order, from `start` (whose residuals are `at_start`), the evaluator's base holding none of
// the parts. Its covariance is the joint one, so each parameter's std is marginal over the others (a part fitted on
// top of another frozen one reports a std conditional on it). Time-shift parts are refused.
struct JointOutcome {
  Eigen::VectorXd theta;       // concatenated as the parts' free parameters
  TwinCovariance covariance;   // of theta
  std::vector<Patch> effects;  // one per part, as applied
  double chi2 = 0.0;           // training part, at `effects`
  int iterations = 0;
};
Result<JointOutcome> FitJointly(const std::vector<TwinCandidate>& parts, const Eigen::VectorXd& start,
                                const Eigen::VectorXd& at_start, TwinEvaluator* evaluator, const FitSettings& settings);

// `c` with the parameters not `informed` (c.free's order) held at their neutral values (moved to c.fixed; a composite's
// to its parts' fixed, and to its own for the report).
TwinCandidate Reduced(const TwinCandidate& c, const std::vector<bool>& informed);

// The score test's chi-square drop: the Gauss-Newton step's predicted decrease from the neutral values, g^T H^+ g
// with the Jacobian there over the informed parameters (as FitCandidate; a time shift: by one step from zero);
// ~ chi2(dof) when the candidate is absent, dof the informed parameters.
struct ScoreTest {
  double drop = 0.0;
  int dof = 0;
};
Result<ScoreTest> PredictedDrop(const TwinCandidate& c, const Eigen::VectorXd& base, TwinEvaluator* evaluator,
                                const FitSettings& settings);

// A time shift's spread along the run, by batch means: each series' entries cut by stamp into `batches` spans of equal
// duration, span k's own best shift theta_k among the evaluated ones (`residuals_at_step`, the whitened residuals at
// shift s * step_s, NaN where the twin has no sample; the vertex of the parabola through its best and the nearest
// evaluated shift on each side) and its information h_k (the sum of `jacobian`'s squares over the span's entries);
// with w_k = h_k / sum h over the spans with h_k > 0, theta_bar = sum w_k theta_k and K_eff = 1 / sum w_k^2,
//   var = K_eff / (K_eff - 1) sum_k w_k^2 (theta_k - theta_bar)^2
// (unbiased when span k's best shift has variance proportional to 1 / h_k; K / (K - 1) for K equal spans), widened by
// t_0.975(K_eff - 1) / 1.96. Where the chi-square is not smooth at the step's scale (a twin's contact chatter in its
// accelerometer), the step-wide curvature and the HAC sandwich around it pin the shift far tighter than the spans' own
// best shifts agree. Returns the std [s]; 0 with K_eff below 3 (too few informed spans to say).
double BatchShiftStd(const Layout& layout, const std::map<long, Eigen::VectorXd>& residuals_at_step, double step_s,
                     const Eigen::VectorXd& jacobian, int batches);

// Runs fn(0..n-1) on up to `threads` threads.
void ParallelFor(int n, int threads, const std::function<void(int)>& fn);

}  // namespace roamlab::gap::internal
