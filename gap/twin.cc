#include "gap/twin.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <map>
#include <set>

#include "common/chi_square.h"
#include "common/interrupt.h"
#include "eval/velocity.h"
#include "gap/internal/decide.h"
#include "gap/internal/twin_fit.h"
#include "gap/internal/twin_residuals.h"
#include "recording/wheel_kinematics.h"
#include "sim/simulator.h"

namespace roamlab::gap {
namespace {

using internal::Layout;
using internal::TwinCandidate;

// Locate's inconsistency ratio, against the stated noise.
constexpr double kInconsistencyRatio = 1.3;

// The motion conditions from the real recording's own streams: a pose stream's poses, else the wheel encoders' dead
// reckoning (nominal geometry), else none.
Conditions RealConditions(const recording::Recording& real) {
  Trajectory poses;
  for (const recording::Stream& s : real.streams) {
    if (s.info.type != recording::StreamType::kPose || s.values.cols() < 7 || s.t.size() < 3) continue;
    for (std::size_t i = 0; i < s.t.size(); ++i) {
      const auto v = s.values.row(static_cast<Eigen::Index>(i));
      poses.push_back({s.t[i], Eigen::Vector3d(v[0], v[1], v[2]), Eigen::Quaterniond(v[6], v[3], v[4], v[5])});
      poses.back().q_world_body.normalize();
    }
    break;
  }
  if (poses.empty() && recording::IsWheeledPlatform(real.platform.kind)) {
    auto odometry = eval::EncoderOnlyOdometry(real);
    if (odometry.ok()) poses = odometry.value().dead_reckoning;
  }
  if (poses.size() < 3) return {};
  return ComputeConditions(poses, real);
}

std::map<std::string, double> Values(const TwinCandidate& c, const Eigen::VectorXd& theta) {
  std::map<std::string, double> out = c.fixed;
  for (std::size_t j = 0; j < c.free.size(); ++j) out[c.free[j].name] = theta[static_cast<Eigen::Index>(j)];
  return out;
}

// e's std of parameter `name` from the covariances' diagonal entry k; the reported one is the largest of the white,
// the HAC and (a time shift's) the batch-means std when `hac`, else the white.
void SetStd(const std::string& name, const TwinCovariance& covariance, Eigen::Index k, bool hac, TwinEffect* e) {
  e->std_white[name] = std::sqrt(std::max(0.0, covariance.white(k, k)));
  e->std_hac[name] = std::sqrt(std::max(0.0, covariance.hac(k, k)));
  e->estimate.std[name] = hac ? std::max(e->std_white[name], e->std_hac[name]) : e->std_white[name];
  if (covariance.batch.size() == 0) return;
  e->std_batch[name] = std::sqrt(std::max(0.0, covariance.batch(k, k)));
  if (hac) e->estimate.std[name] = std::max(e->estimate.std[name], e->std_batch[name]);
}

// Whether `c` is among the candidates tried by default on `runs` training runs: the geometry composite and the drive's
// clock drift only on several. On one run, of one kind of motion, their parameters trade against each other (on a
// square's in-place turns the track against the scale and the ratio; on a straight line the clock's rate against the
// scale), and the combination that fits that run carries over to other motions worse than one effect does; they are
// tried there when named.
bool DefaultCandidate(const TwinCandidate& c, std::size_t runs) { return !c.several_runs || runs > 1; }

// A drive's clock shifts the recorded inputs of a replay; a plain simulation drives the scenario's own schedule.
bool Applies(const TwinCandidate& c, const std::vector<TwinTrainingRun>& runs) {
  return c.effect != "drive_time_offset" ||
         std::all_of(runs.begin(), runs.end(), [](const TwinTrainingRun& r) { return r.replayed; });
}

// `options` comparing the absolute values (the located components and the unexplained ones are judged per sample).
TwinResidualOptions Absolute(TwinResidualOptions options) {
  options.increment_window_s = 0.0;
  return options;
}

// What one round judges the candidates against: the effects kept so far.
struct State {
  std::vector<sim::EffectOptions> effects;  // kept
  Eigen::VectorXd residuals;                // the runs' training parts (internal::CombinedLayout)
  double chi2 = 0.0;
  std::vector<TwinComparison> heldout;      // per run, its held-out part
  std::vector<recording::Recording> twins;  // per run, the whole recording's twin
};

// The runs' held-out chi-square, each run's weighted as its training residuals (FitRun::scale squared).
double Chi2(const std::vector<TwinComparison>& heldout, const std::vector<internal::FitRun>& runs) {
  double sum = 0.0;
  for (std::size_t i = 0; i < heldout.size(); ++i) sum += runs[i].scale * runs[i].scale * heldout[i].chi2;
  return sum;
}

// A training run's span: its first and last stamps and the end of its training part.
struct RunSpan {
  Time first, last, train_end;
  double whole_s = 0.0, train_s = 0.0;  // the twin's durations since `first`: whole recording, training part
};

class Diagnoser {
 public:
  Diagnoser(const sim::Scenario& nominal, const std::vector<TwinTrainingRun>& runs, const TwinDiagnoseOptions& options)
      : nominal_(nominal), runs_in_(runs), real_(*runs.front().real), options_(options) {}
  Result<TwinDiagnosis> Run();

 private:
  void Progress(const std::string& what) const {
    if (options_.progress) options_.progress(what);
  }
  Status Span();
  // The nominal scenario with `effects`.
  sim::Scenario Base(const std::vector<sim::EffectOptions>& effects) const {
    sim::Scenario s = nominal_;
    s.effects = effects;
    return s;
  }
  // Each run's twin of its whole recording with `effects`, in parallel.
  Result<std::vector<recording::Recording>> RunWhole(const std::vector<sim::EffectOptions>& effects);
  // Each run's twin compared with its held-out part.
  std::vector<TwinComparison> HeldOut(const std::vector<recording::Recording>& twins) const;
  // screen: fitted only when the score test (PredictedDrop) passes alpha.
  Result<TwinEffect> Fit(const TwinCandidate& c, const State& state, double step_s, bool screen);
  // The kept effects other than time shifts refitted together with `c` (its informed parameters, from its own fit
  // `e`); on success e takes the joint values and std and the refit is recorded for Round. Returns whether it was.
  bool RefitWithKept(const TwinCandidate& c, double step_s, TwinEffect* e);
  // The kept effects split for a joint fit: time shifts into the base scenario, the others as candidates over the
  // parameters their rounds fitted, with their kept values.
  struct KeptParts {
    sim::Scenario base;
    std::vector<TwinCandidate> parts;
    std::vector<std::size_t> kept;  // per part, its index in out_.effects
    std::vector<double> start;      // the parts' free parameters at their kept values, concatenated
    std::vector<std::string> held;  // the time shifts' names
  };
  KeptParts Kept() const;
  internal::FitSettings Settings(double step_s) const {
    internal::FitSettings settings;
    settings.max_iterations = options_.max_iterations;
    settings.physics_step_s = step_s;
    settings.threads = options_.threads;
    return settings;
  }
  Result<bool> Round(int round, const std::vector<TwinCandidate>& pool, double step_s, State* state,
                     std::vector<TwinEffect>* scored);
  void FitJointly(const State& state, double step_s);
  void Finish(const State& state);

  const sim::Scenario& nominal_;
  const std::vector<TwinTrainingRun>& runs_in_;
  const recording::Recording& real_;  // the diagnosed recording, the first run
  const TwinDiagnoseOptions& options_;
  TwinDiagnosis out_;
  std::vector<RunSpan> spans_;                  // per run
  std::vector<internal::FitRun> fit_runs_;      // per run, its training part
  std::vector<TwinResidualOptions> residuals_;  // per run: its fit's and held-out comparison's
  int measurements_ = 0;
  int runs_ = 0;
  bool hac_ = false;                    // the std reported is the HAC one
  std::vector<TwinCandidate> library_;  // every candidate the nominal scenario supports
  // Per candidate of the current round refitted with the kept effects: the whole patch with it, and the kept effects'
  // refitted records (index into out_.effects, record).
  struct Refit {
    std::vector<sim::EffectOptions> patch;
    std::vector<std::pair<std::size_t, TwinEffect>> kept;
  };
  std::map<std::string, Refit> refits_;
};

Status Diagnoser::Span() {
  if (!(options_.train_fraction > 0.0 && options_.train_fraction < 1.0))
    return Status::Error("the training fraction must be in (0, 1)");
  for (const TwinTrainingRun& run : runs_in_) {
    const std::string name = spans_.empty() ? std::string() : run.recording + ": ";
    RunSpan span;
    span.first = Time::FromNanoseconds(std::numeric_limits<std::int64_t>::max());
    span.last = Time::FromNanoseconds(std::numeric_limits<std::int64_t>::min());
    for (const recording::Stream& s : run.real->streams) {
      if (s.t.empty()) continue;
      span.first = std::min(span.first, s.t.front());
      span.last = std::max(span.last, s.t.back());
    }
    if (span.last <= span.first) return Status::Error(name + "the recording has no span of samples to compare");
    const double seconds = SecondsBetween(span.first, span.last);
    residuals_.push_back(run.replayed ? ReplayedResidualOptions(nominal_, *run.real, options_.increment_window_s)
                                      : TwinResidualOptions{});
    span.train_end = Time::FromSeconds(span.first.seconds() + options_.train_fraction * seconds);
    // A further training run whose last part is too short to hold one of its windows gives the held-out test nothing:
    // it trains whole.
    const double window_s = residuals_.back().increment_window_s;
    if (!spans_.empty() && window_s > 0.0 &&
        (1.0 - options_.train_fraction) * seconds < internal::kShortestWindowShare * window_s)
      span.train_end = span.last;
    span.whole_s = std::max(seconds, 1.0);
    span.train_s = std::min(span.whole_s, SecondsBetween(span.first, span.train_end) + 0.05);
    internal::FitRun fit{run.recording, run.real, &run.runner,
                         internal::MakeLayout(*run.real, span.first, span.train_end, residuals_.back()), span.train_s};
    if (fit.layout.size == 0) return Status::Error(name + "the recording has no stream with a stated noise to compare");
    spans_.push_back(span);
    fit_runs_.push_back(std::move(fit));
  }
  if (options_.train_weight == TwinDiagnoseOptions::TrainWeight::kRuns) {
    std::vector<double> summed;
    for (const internal::FitRun& run : fit_runs_) summed.push_back(internal::SummedWeight(run.layout));
    const std::vector<double> scales = internal::EqualRunScales(summed);
    for (std::size_t i = 0; i < fit_runs_.size(); ++i) fit_runs_[i].scale = scales[i];
    out_.train_weight = "runs";
  }
  for (const internal::FitRun& run : fit_runs_) out_.run_weights.push_back(run.scale * run.scale);
  out_.train_end_s = spans_.front().train_end.seconds();
  return Status::Ok();
}

Result<std::vector<recording::Recording>> Diagnoser::RunWhole(const std::vector<sim::EffectOptions>& effects) {
  const int n = static_cast<int>(runs_in_.size());
  std::vector<Result<recording::Recording>> twins(runs_in_.size(), Status::Error("not run"));
  internal::ParallelFor(n, options_.threads, [&](int i) {
    const std::size_t run = static_cast<std::size_t>(i);
    sim::Scenario s = Base(effects);
    s.duration_s = spans_[run].whole_s;
    try {
      twins[run] = runs_in_[run].runner(s);
    } catch (const std::exception& e) {
      twins[run] = Status::Error(std::string("the twin runner failed: ") + e.what());
    }
  });
  runs_ += n;
  std::vector<recording::Recording> out;
  for (std::size_t i = 0; i < twins.size(); ++i) {
    if (!twins[i].ok())
      return n == 1 ? twins[i].status() : Status::Error(runs_in_[i].recording + ": " + twins[i].status().message());
    out.push_back(std::move(twins[i]).value());
  }
  return out;
}

std::vector<TwinComparison> Diagnoser::HeldOut(const std::vector<recording::Recording>& twins) const {
  std::vector<TwinComparison> out;
  for (std::size_t i = 0; i < twins.size(); ++i)
    out.push_back(CompareTwin(*runs_in_[i].real, twins[i], spans_[i].train_end.seconds(), spans_[i].last.seconds(),
                              options_.drift, residuals_[i]));
  return out;
}

Result<TwinEffect> Diagnoser::Fit(const TwinCandidate& c, const State& state, double step_s, bool screen) {
  const sim::Scenario base = Base(state.effects);
  internal::TwinEvaluator evaluator(base, fit_runs_, options_.threads);
  const internal::FitSettings settings = Settings(step_s);
  if (screen) {
    auto drop = internal::PredictedDrop(c, state.residuals, &evaluator, settings);
    runs_ += evaluator.runs();
    if (!drop.ok()) return drop.status();
    const internal::ScoreTest& test = drop.value();
    if (test.dof == 0 || !(1.0 - ChiSquareCdf(test.drop, static_cast<double>(test.dof)) < options_.alpha)) {
      TwinEffect e;
      e.runs = evaluator.runs();
      e.chi2_before = e.chi2_after = state.chi2;
      e.estimate.name = c.label;
      e.estimate.dof = test.dof;
      e.estimate.lr_raw = test.drop;
      internal::Score(nullptr, measurements_, &e.estimate);
      e.estimate.decision = "not significant by the score test (not fitted)";
      return e;
    }
  }
  auto fit = internal::FitCandidate(c, state.residuals, &evaluator, settings);
  runs_ += evaluator.runs();
  if (!fit.ok()) return fit.status();
  TwinEffect e;
  e.applied = fit.value().effects;
  e.chi2_before = state.chi2;
  e.chi2_after = fit.value().chi2;
  e.iterations = fit.value().iterations;
  e.runs = evaluator.runs();
  e.estimate.name = c.label;
  e.estimate.parameters = Values(c, fit.value().theta);
  const TwinCovariance& covariance = fit.value().covariance;
  Eigen::Index k = 0;  // the informed parameters' index in the covariance
  for (std::size_t j = 0; j < c.free.size(); ++j) {
    const std::string& name = c.free[j].name;
    if (!fit.value().informed[j]) {
      e.not_informed.push_back(name);
      continue;
    }
    SetStd(name, covariance, k++, hac_, &e);
  }
  e.estimate.dof = static_cast<int>(k);
  e.hac_lags = covariance.lags;
  if (k > 0 && !c.time_shift) RefitWithKept(internal::Reduced(c, fit.value().informed), step_s, &e);
  e.estimate.lr_raw = state.chi2 - e.chi2_after;
  internal::Score(nullptr, measurements_, &e.estimate);
  if (k == 0) e.estimate.decision = "not fitted: the data informs none of its parameters";
  return e;
}

Diagnoser::KeptParts Diagnoser::Kept() const {
  KeptParts out{Base({}), {}, {}, {}, {}};
  for (std::size_t i = 0; i < out_.effects.size(); ++i) {
    const TwinEffect& x = out_.effects[i];
    const auto c = std::find_if(library_.begin(), library_.end(),
                                [&](const TwinCandidate& y) { return y.label == x.estimate.name; });
    if (c == library_.end() || c->time_shift) {
      out.base.effects.insert(out.base.effects.end(), x.applied.begin(), x.applied.end());
      out.held.push_back(x.estimate.name);
      continue;
    }
    std::vector<bool> informed;
    for (const internal::TwinParameter& p : c->free)
      informed.push_back(std::find(x.not_informed.begin(), x.not_informed.end(), p.name) == x.not_informed.end());
    out.parts.push_back(internal::Reduced(*c, informed));
    for (const internal::TwinParameter& p : out.parts.back().free)
      out.start.push_back(x.estimate.parameters.at(p.name));
    out.kept.push_back(i);
  }
  return out;
}

// Forward selection with refit: the candidate is judged as the nested model "kept effects + candidate, all free"
// against "kept effects", so that an effect whose signature overlaps a kept one's (a clock's rate and a wheel scale on
// straight runs) is not judged against a kept one that has already absorbed part of it. Time shifts, searched on the
// step grid, stay at their kept values.
bool Diagnoser::RefitWithKept(const TwinCandidate& c, double step_s, TwinEffect* e) {
  auto [base, parts, kept, start, held] = Kept();
  if (parts.empty()) return false;
  parts.push_back(c);
  for (const internal::TwinParameter& p : c.free) start.push_back(e->estimate.parameters.at(p.name));
  // The start's residuals: the candidate's own fit is on top of the kept effects at their values.
  internal::Patch at_start;
  for (std::size_t i : kept)
    at_start.insert(at_start.end(), out_.effects[i].applied.begin(), out_.effects[i].applied.end());
  at_start.insert(at_start.end(), e->applied.begin(), e->applied.end());
  internal::TwinEvaluator evaluator(base, fit_runs_, options_.threads);
  auto residuals = evaluator.Run({at_start});
  const Eigen::VectorXd theta0 =
      Eigen::Map<const Eigen::VectorXd>(start.data(), static_cast<Eigen::Index>(start.size()));
  Result<internal::JointOutcome> fit =
      residuals.front().ok()
          ? internal::FitJointly(parts, theta0, residuals.front().value(), &evaluator, Settings(step_s))
          : Result<internal::JointOutcome>(residuals.front().status());
  runs_ += evaluator.runs();
  e->runs += evaluator.runs();
  if (!fit.ok() || !(fit.value().chi2 <= e->chi2_after)) return false;
  Refit refit{base.effects, {}};
  Eigen::Index k = 0;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const Eigen::Index size = static_cast<Eigen::Index>(parts[i].free.size());
    const internal::Patch& applied = fit.value().effects[i];
    refit.patch.insert(refit.patch.end(), applied.begin(), applied.end());
    TwinEffect& t = i + 1 < parts.size() ? refit.kept.emplace_back(kept[i], out_.effects[kept[i]]).second : *e;
    t.applied = applied;
    t.estimate.parameters = Values(parts[i], fit.value().theta.segment(k, size));
    for (const internal::TwinParameter& p : parts[i].free) SetStd(p.name, fit.value().covariance, k++, hac_, &t);
    t.hac_lags = fit.value().covariance.lags;
    t.refitted = true;
  }
  e->chi2_after = fit.value().chi2;
  e->iterations += fit.value().iterations;
  refits_[c.label] = std::move(refit);
  return true;
}

// Fits the pool on top of `state`, scores them and keeps the first that passes (its held-out run becomes the new
// state). A candidate whose twin fails is dropped with the reason. Returns whether one was kept.
Result<bool> Diagnoser::Round(int round, const std::vector<TwinCandidate>& pool, double step_s, State* state,
                              std::vector<TwinEffect>* scored) {
  refits_.clear();
  for (const TwinCandidate& c : pool) {
    if (InterruptRequested()) return InterruptedError();
    Progress("round " + std::to_string(round + 1) + ": fitting " + c.label);
    auto e = Fit(c, *state, step_s, round > 0);
    if (e.ok()) {
      scored->push_back(std::move(e).value());
      continue;
    }
    // A twin that fails with the candidate (a parameter that throws the robot off the terrain) drops the candidate.
    TwinEffect failed;
    failed.estimate.name = c.label;
    failed.estimate.dof = static_cast<int>(c.free.size());
    failed.estimate.delta_bic = std::numeric_limits<double>::infinity();
    failed.estimate.decision = "not fitted: " + e.status().message();
    scored->push_back(failed);
  }
  std::sort(scored->begin(), scored->end(),
            [](const TwinEffect& a, const TwinEffect& b) { return a.estimate.delta_bic < b.estimate.delta_bic; });
  for (TwinEffect& e : *scored) {
    EffectEstimate& x = e.estimate;
    if (!(x.lr_pvalue < options_.alpha) || !(x.delta_bic < options_.max_delta_bic)) {
      if (!x.decision.empty()) continue;
      x.decision = x.lr_pvalue < options_.alpha ? "Delta BIC not below the threshold" : "p not below alpha";
      continue;
    }
    const auto refit = refits_.find(x.name);
    std::vector<sim::EffectOptions> effects = state->effects;
    effects.insert(effects.end(), e.applied.begin(), e.applied.end());
    if (refit != refits_.end()) effects = refit->second.patch;
    auto twins = RunWhole(effects);
    if (!twins.ok()) {
      x.decision = "the patched twin of the whole recording failed: " + twins.status().message();
      continue;
    }
    std::vector<TwinComparison> heldout = HeldOut(twins.value());
    x.evaluated_heldout = true;
    const double before = Chi2(state->heldout, fit_runs_);
    x.heldout_improvement = before > 0.0 ? 1.0 - Chi2(heldout, fit_runs_) / before : 0.0;
    if (!(x.heldout_improvement > options_.min_heldout_improvement)) {
      x.decision = "the held-out chi-square does not drop";
      continue;
    }
    x.accepted = true;
    x.decision = "accepted";
    state->effects = std::move(effects);
    state->chi2 = e.chi2_after;
    state->heldout = std::move(heldout);
    state->twins = std::move(twins).value();
    state->residuals = internal::CombinedResiduals(fit_runs_, state->twins);
    if (refit != refits_.end())
      for (auto& [i, t] : refit->second.kept) {
        t.estimate.decision = "accepted; refitted with " + x.name;
        out_.effects[i] = t;
      }
    out_.effects.push_back(e);
    for (TwinEffect& other : *scored) {
      EffectEstimate& y = other.estimate;
      if (!y.decision.empty()) continue;
      y.decision = !(y.lr_pvalue < options_.alpha)           ? "p not below alpha"
                   : !(y.delta_bic < options_.max_delta_bic) ? "Delta BIC not below the threshold"
                                                             : "not tried: a candidate before it was kept";
    }
    return true;
  }
  return false;
}

// Step 5 (gap/twin.h): the kept effects other than time shifts, each over the parameters its round fitted, refitted
// together from their kept values on the training part, the time shifts held in the base. A joint fit whose twin fails
// leaves the rounds' figures alone and says why.
void Diagnoser::FitJointly(const State& state, double step_s) {
  auto [base, parts, kept, start, held] = Kept();
  out_.joint.held = held;
  if (parts.size() < 2) {
    out_.joint = {};
    return;
  }
  Progress("joint refit of the kept effects");
  internal::TwinEvaluator evaluator(base, fit_runs_, options_.threads);
  const Eigen::VectorXd theta0 =
      Eigen::Map<const Eigen::VectorXd>(start.data(), static_cast<Eigen::Index>(start.size()));
  auto fit = internal::FitJointly(parts, theta0, state.residuals, &evaluator, Settings(step_s));
  runs_ += evaluator.runs();
  out_.joint.runs = evaluator.runs();
  out_.joint.chi2_before = state.chi2;
  if (!fit.ok()) {
    out_.joint.failed = fit.status().message();
    return;
  }
  out_.joint.chi2_after = fit.value().chi2;
  out_.joint.iterations = fit.value().iterations;
  const TwinCovariance& covariance = fit.value().covariance;
  const Eigen::MatrixXd information = covariance.white.completeOrthogonalDecomposition().pseudoInverse();
  Eigen::Index k = 0;  // the parameter's index in the joint covariance
  for (std::size_t i = 0; i < parts.size(); ++i) {
    TwinEffect e;
    e.applied = fit.value().effects[i];
    e.estimate.name = parts[i].label;
    const Eigen::Index size = static_cast<Eigen::Index>(parts[i].free.size());
    e.estimate.parameters = Values(parts[i], fit.value().theta.segment(k, size));
    e.estimate.dof = static_cast<int>(size);
    e.estimate.decision = "refitted jointly with the other kept effects: marginal std";
    const Eigen::MatrixXd conditional =
        information.block(k, k, size, size).completeOrthogonalDecomposition().pseudoInverse();
    std::map<std::string, double> conditional_std;
    for (Eigen::Index j = 0; j < size; ++j)
      conditional_std[parts[i].free[static_cast<std::size_t>(j)].name] = std::sqrt(std::max(0.0, conditional(j, j)));
    out_.joint.std_white_conditional.push_back(conditional_std);
    for (const internal::TwinParameter& p : parts[i].free) SetStd(p.name, covariance, k++, hac_, &e);
    e.not_informed = out_.effects[kept[i]].not_informed;
    e.hac_lags = covariance.lags;
    e.chi2_before = out_.joint.chi2_before;
    e.chi2_after = out_.joint.chi2_after;
    e.iterations = out_.joint.iterations;
    e.runs = out_.joint.runs;
    out_.joint.effects.push_back(std::move(e));
  }
}

// The held-out figures with the patch, the unexplained components and the verdict.
void Diagnoser::Finish(const State& state) {
  out_.heldout_after = state.heldout.front();
  for (std::size_t i = 1; i < state.heldout.size(); ++i) out_.training_runs[i - 1].heldout_after = state.heldout[i];
  for (const TwinEffect& e : out_.effects) out_.patch.insert(out_.patch.end(), e.applied.begin(), e.applied.end());
  const RunSpan& span = spans_.front();
  const Layout heldout = internal::MakeLayout(real_, span.train_end, span.last, Absolute(residuals_.front()));
  const auto statistics = ComponentStatistics(
      internal::MeasurementResiduals(heldout, internal::WhitenedResiduals(heldout, real_, state.twins.front())));
  for (const auto& [key, level] : statistics)
    if (Inconsistent(level, 1.0, kInconsistencyRatio)) out_.unexplained.push_back(key);
  const bool inconsistent =
      std::any_of(out_.located.begin(), out_.located.end(), [](const LocatedComponent& c) { return c.inconsistent; });
  out_.verdict = !out_.effects.empty() ? "named" : inconsistent ? "unknown" : "none";
}

Result<TwinDiagnosis> Diagnoser::Run() {
  const auto start = std::chrono::steady_clock::now();
  if (Status s = Span(); !s.ok()) return s;
  out_.replayed = options_.replayed;
  if (std::any_of(runs_in_.begin(), runs_in_.end(), [](const TwinTrainingRun& r) { return r.replayed; }))
    out_.increment_window_s = options_.increment_window_s;
  hac_ = estimator::UsesHac(options_.std_method, real_);
  out_.std_method = hac_ ? "hac" : "white";
  State state;
  sim::Scenario nominal = Base({});
  nominal.duration_s = spans_.front().whole_s;  // the runners' time since the first stamp
  auto simulator = sim::Simulator::Create(nominal, {});
  if (!simulator.ok()) return Status::Error("the nominal scenario: " + simulator.status().message());
  const double step_s = simulator.value()->PhysicsStepS();

  Progress("nominal twin");
  auto twins = RunWhole({});
  if (!twins.ok()) return Status::Error("the nominal twin: " + twins.status().message());
  state.twins = std::move(twins).value();
  const RunSpan& span = spans_.front();
  out_.whole_run = CompareTwin(real_, state.twins.front(), span.first.seconds(), span.last.seconds(), options_.drift,
                               Absolute(residuals_.front()));
  state.heldout = HeldOut(state.twins);
  out_.heldout_before = state.heldout.front();
  for (std::size_t i = 1; i < runs_in_.size(); ++i)
    out_.training_runs.push_back(
        {runs_in_[i].recording, runs_in_[i].replayed, spans_[i].train_end.seconds(), state.heldout[i], {}});
  const Layout whole = internal::MakeLayout(real_, span.first, span.last, Absolute(residuals_.front()));
  out_.located =
      Locate(internal::MeasurementResiduals(whole, internal::WhitenedResiduals(whole, real_, state.twins.front())),
             RealConditions(real_), {});
  state.residuals = internal::CombinedResiduals(fit_runs_, state.twins);
  state.chi2 = internal::SumOfSquares(state.residuals, &measurements_);

  library_ = internal::TwinCandidates(nominal_, options_.max_shift_s);
  std::vector<TwinCandidate> pool;
  for (const TwinCandidate& c : library_)
    if (Applies(c, runs_in_) &&
        (options_.candidates.empty()
             ? DefaultCandidate(c, runs_in_.size())
             : std::find(options_.candidates.begin(), options_.candidates.end(), c.label) != options_.candidates.end()))
      pool.push_back(c);
  // A round after a kept time shift re-screens: it tries every candidate not yet kept (a clock error hides what the
  // others explain); the rounds after a non-clock effect try the significant candidates of the last screening round.
  const std::vector<TwinCandidate> screened = pool;
  std::set<std::string> passed;
  bool screening = true;
  for (int round = 0; round < options_.max_effects && !pool.empty(); ++round) {
    std::vector<TwinEffect> scored;
    auto kept = Round(round, pool, step_s, &state, &scored);
    if (!kept.ok()) return kept.status();
    if (round == 0) out_.candidates = scored;
    out_.rounds.push_back(scored);
    if (screening) {
      passed.clear();
      for (const TwinEffect& e : scored)
        if (e.estimate.lr_pvalue < options_.alpha) passed.insert(e.estimate.name);
    }
    if (!kept.value()) break;
    const std::string& label = out_.effects.back().estimate.name;
    screening = std::any_of(screened.begin(), screened.end(),
                            [&](const TwinCandidate& c) { return c.label == label && c.time_shift; });
    // The next round: those candidates, other than the ones that set a simulator effect kept already (a composite's
    // parts, or the composite of a kept part).
    std::set<std::string> kept_effects;
    for (const sim::EffectOptions& e : state.effects) kept_effects.insert(e.name);
    std::vector<TwinCandidate> next;
    for (const TwinCandidate& c : screened) {
      const std::vector<std::string> sets = internal::SimulatorEffects(c);
      if ((screening || passed.count(c.label)) &&
          std::none_of(sets.begin(), sets.end(), [&](const std::string& x) { return kept_effects.count(x) > 0; }))
        next.push_back(c);
    }
    pool = next;
  }
  if (InterruptRequested()) return InterruptedError();
  FitJointly(state, step_s);
  Finish(state);
  out_.runs = runs_;
  out_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out_;
}

}  // namespace

std::vector<std::string> TwinCandidateNames(const sim::Scenario& nominal) {
  std::vector<std::string> out;
  for (const TwinCandidate& c : internal::TwinCandidates(nominal, 0.5)) out.push_back(c.label);
  return out;
}

Result<TwinHeldOutRun> ShowOnHeldOut(const sim::Scenario& nominal, const std::vector<sim::EffectOptions>& patch,
                                     const recording::Recording& held, const TwinRunner& runner,
                                     const DriftOptions& drift, int threads, const TwinResidualOptions& residuals) {
  Time first = Time::FromNanoseconds(std::numeric_limits<std::int64_t>::max());
  Time last = Time::FromNanoseconds(std::numeric_limits<std::int64_t>::min());
  for (const recording::Stream& s : held.streams) {
    if (s.t.empty()) continue;
    first = std::min(first, s.t.front());
    last = std::max(last, s.t.back());
  }
  if (last <= first) return Status::Error("the held-out recording has no span of samples to compare");
  std::vector<sim::Scenario> scenarios(2, nominal);
  scenarios[0].effects.clear();
  scenarios[1].effects = patch;
  for (sim::Scenario& s : scenarios) s.duration_s = std::max(last.seconds(), 1.0);
  std::vector<Result<recording::Recording>> twins(2, Result<recording::Recording>(Status::Error("not run")));
  internal::ParallelFor(2, threads, [&](int i) {
    try {
      twins[static_cast<std::size_t>(i)] = runner(scenarios[static_cast<std::size_t>(i)]);
    } catch (const std::exception& e) {
      twins[static_cast<std::size_t>(i)] = Status::Error(std::string("the twin runner failed: ") + e.what());
    }
  });
  for (std::size_t i = 0; i < twins.size(); ++i)
    if (!twins[i].ok())
      return Status::Error(std::string(i == 0 ? "the nominal" : "the patched") +
                           " twin: " + twins[i].status().message());
  TwinHeldOutRun out;
  out.before = CompareTwin(held, twins[0].value(), first.seconds(), last.seconds(), drift, residuals);
  out.after = CompareTwin(held, twins[1].value(), first.seconds(), last.seconds(), drift, residuals);
  return out;
}

Result<TwinDiagnosis> DiagnoseTwin(const sim::Scenario& nominal, const recording::Recording& real,
                                   const TwinRunner& runner, const TwinDiagnoseOptions& options) {
  return DiagnoseTwin(nominal, {TwinTrainingRun{"", &real, runner, options.replayed}}, options);
}

Result<TwinDiagnosis> DiagnoseTwin(const sim::Scenario& nominal, const std::vector<TwinTrainingRun>& runs,
                                   const TwinDiagnoseOptions& options) {
  if (runs.empty()) return Status::Error("no recording to diagnose");
  for (const TwinTrainingRun& run : runs)
    if (!run.real || !run.runner) return Status::Error(run.recording + ": no recording or no twin runner");
  return Diagnoser(nominal, runs, options).Run();
}

}  // namespace roamlab::gap
