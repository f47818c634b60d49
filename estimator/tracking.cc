#include "estimator/tracking.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <deque>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "common/check.h"
#include "common/interrupt.h"
#include "estimator/calibration.h"
#include "estimator/covariance.h"
#include "estimator/geometry.h"
#include "estimator/internal/after_gap.h"
#include "estimator/internal/linearization.h"
#include "estimator/internal/normal_equations.h"
#include "estimator/marginalization.h"
#include "estimator/solver.h"

namespace roamlab::estimator {
namespace {

using Clock = std::chrono::steady_clock;

// A pose's tangent starts with its position (manifold.h); the output is the position's covariance.
constexpr int kPositionDims = 3;

FactorId NextFactorId(const Graph& graph) { return graph.factors().empty() ? 0 : graph.factors().rbegin()->first + 1; }

// Gating passes over the factors with ids in [first, end) after a solve, each followed by a re-solve (`solve`,
// returning its iterations) when it switched any factor: a pass rejects only the factors that fail worst at their
// poses (GateOptions::worst_per_pose) and re-admits those that fit again once the outliers are out. Returns the
// re-solves' iterations.
constexpr int kMaxGatePasses = 5;
int GateAndResolve(double probability, FactorId first, FactorId end, const SolverWorkspace* last_solve,
                   ProblemBuilder* builder, const std::function<int()>& solve) {
  GateOptions options;
  options.worst_per_pose = true;
  options.end = end;
  int iterations = 0;
  for (int pass = 0;
       pass < kMaxGatePasses && GateOutliers(probability, builder, first, last_solve, options).switched() > 0; ++pass)
    iterations += solve();
  return iterations;
}

// Before a solve with a cumulative wheel master: switches off, counted as rejected, the newest pose's spans (those that
// end at it), when the measurements that tie the newest pose to earlier ones (the IMU's rows) have at least as many
// residual rows as it has dimensions (not in an IMU gap). The solve then places the newest pose by its motion, and the
// gate tests the spans there and re-admits those that fit. Otherwise the newest pose is predicted from the newest span
// itself, which then fits whatever its reading: an outlying reading bends the poses before it through the IMU's rows,
// failing their good spans, and a bridge over an earlier reading that ends at the newest pose passes at the position
// the outlier gave it.
void HoldOutNewestSpans(ProblemBuilder* builder) {
  Graph& graph = builder->graph();
  const std::deque<PoseNode>& poses = builder->poses();
  const auto& spans = builder->cumulative_spans();
  if (spans.empty()) return;
  const VariableId newest = poses.back().id;
  const auto poses_joined = [&](const FactorEntry& entry) {
    return std::count_if(entry.variables.begin(), entry.variables.end(), [&](VariableId v) {
      return std::any_of(poses.begin(), poses.end(), [&](const PoseNode& p) { return p.id == v; });
    });
  };
  int motion_rows = 0;
  for (const FactorId id : graph.FactorsOf(newest)) {
    const FactorEntry& entry = graph.factor(id);
    if (entry.active && builder->StreamOfFactor(id) >= 0 && spans.count(id) == 0 && poses_joined(entry) > 1)
      motion_rows += entry.factor->residual_dim();
  }
  if (motion_rows < graph.variable(newest).manifold.tangent_dim()) return;
  for (const FactorId id : graph.FactorsOf(newest)) {
    FactorEntry& entry = graph.mutable_factor(id);
    if (spans.count(id) == 0 || !entry.active || !builder->StreamGated(builder->StreamOfFactor(id))) continue;
    entry.active = false;
    ++builder->mutable_counts(entry.stream).rejected;
  }
}

// The measurement factors of `streams` attached since `first` that hold one pose alone (every other variable they join
// fixed): absolute measurements (a motion-capture pose, a GPS fix). The master stream's are not among them.
std::vector<FactorId> NewAbsoluteFactors(const ProblemBuilder& builder, FactorId first, const std::string& master,
                                         const std::set<std::string>& streams) {
  const Graph& graph = builder.graph();
  std::vector<FactorId> out;
  for (auto it = graph.factors().lower_bound(first); it != graph.factors().end(); ++it) {
    const FactorEntry& entry = it->second;
    const int stream = builder.StreamOfFactor(it->first);
    if (stream < 0 || builder.stream_names()[stream] == master || !builder.StreamGated(stream) || !entry.active ||
        streams.count(entry.stream) == 0)
      continue;
    int free_poses = 0, free_other = 0;
    for (VariableId v : entry.variables) {
      if (graph.variable(v).fixed) continue;
      const bool pose = std::any_of(builder.poses().begin(), builder.poses().end(),
                                    [&](const PoseNode& p) { return p.id == v; });
      (pose ? free_poses : free_other) += 1;
    }
    if (free_poses == 1 && free_other == 0) out.push_back(it->first);
  }
  return out;
}

// Adds to `unconfirmed` the streams whose rows resume after a gap within a millisecond of the newest pose or before it
// (a row is attached at the master sample at or after its stamp); `resumes` loses each gap so passed.
void MarkStreamsAfterGaps(Time newest, std::map<std::string, std::vector<Time>>* resumes,
                          std::set<std::string>* unconfirmed) {
  constexpr std::int64_t kSlackNs = 1000000;
  const Time reach = Time::FromNanoseconds(newest.nanoseconds() + kSlackNs);
  for (auto& [name, stamps] : *resumes) {
    const auto passed = std::upper_bound(stamps.begin(), stamps.end(), reach);
    if (passed == stamps.begin()) continue;
    stamps.erase(stamps.begin(), passed);
    unconfirmed->insert(name);
  }
}

// Switches `factors` off, counted as rejected, for the update's first solve.
void HoldOut(const std::vector<FactorId>& factors, ProblemBuilder* builder) {
  for (const FactorId id : factors) {
    builder->graph().mutable_factor(id).active = false;
    ++builder->mutable_counts(builder->graph().factor(id).stream).rejected;
  }
}

// Whether the absolute factor `entry` (its one free variable the pose `pose`) fails the innovation test
// (internal::InnovationWithin) against the pose's marginal covariance in the window. A pose whose marginal covariance
// cannot be had (nothing else holds it) has nothing to test the factor against: it does not fail.
bool InnovationFails(double probability, const FactorEntry& entry, VariableId pose,
                     const std::vector<const double*>& values, const Graph& graph, internal::WhitenedFactor* wf) {
  const int column =
      static_cast<int>(std::find(entry.variables.begin(), entry.variables.end(), pose) - entry.variables.begin());
  if (!internal::LinearizeFactorAt(entry, values.data(), std::uint64_t{1} << column, wf)) return false;
  const auto info = ComputeMarginalInformation(graph, {pose});
  if (!info.ok()) return false;
  const Eigen::LDLT<Eigen::MatrixXd> information(info.value().information);
  if (information.info() != Eigen::Success || !information.isPositive() ||
      information.vectorD().minCoeff() <= 0.0)
    return false;
  const Eigen::MatrixXd covariance =
      information.solve(Eigen::MatrixXd::Identity(information.rows(), information.cols()));
  return !internal::InnovationWithin(probability, *wf, {column}, covariance);
}

// Re-admits each held-out absolute factor whose innovation at the estimate solved without it passes the chi-square
// quantile `probability` of its dimension (InnovationFails). Adds the streams of those it re-admitted to *consistent;
// returns how many it re-admitted.
int ReadmitConsistentAbsolute(double probability, const std::vector<FactorId>& held, ProblemBuilder* builder,
                              std::set<std::string>* consistent) {
  Graph& graph = builder->graph();
  int readmitted = 0;
  std::vector<const double*> values;
  internal::WhitenedFactor wf;
  for (const FactorId id : held) {
    FactorEntry& entry = graph.mutable_factor(id);
    VariableId pose = 0;
    values.clear();
    for (const VariableId v : entry.variables) {
      values.push_back(graph.variable(v).value.data());
      if (!graph.variable(v).fixed) pose = v;
    }
    if (InnovationFails(probability, entry, pose, values, graph, &wf)) continue;
    entry.active = true;
    --builder->mutable_counts(entry.stream).rejected;
    consistent->insert(entry.stream);
    ++readmitted;
  }
  return readmitted;
}

// The oldest pose's estimate and position covariance (marginal of the whole window): from `known` when it holds that
// pose (a request of poses' positions only, kPositionDims each, computed by a solve or by OldestPoseCovariances),
// otherwise from the window's Hessian now.
Status EmitOldest(ProblemBuilder* builder, const CovarianceRequest* known, const TrackingOptions& options,
                  TrackingResult* out) {
  const PoseNode& node = builder->poses().front();
  const Graph& graph = builder->graph();
  const Pose<double> p = PoseFromArray(graph.variable(node.id).value.data());
  Eigen::Matrix3d cov;
  const auto found = known != nullptr && known->computed
                         ? std::find(known->variables.begin(), known->variables.end(), node.id)
                         : std::vector<VariableId>::const_iterator();
  if (known != nullptr && known->computed && found != known->variables.end()) {
    ROAMLAB_CHECK(known->leading_dims == kPositionDims, "a pose covariance request of positions only");
    const int offset = kPositionDims * static_cast<int>(found - known->variables.begin());
    cov = known->covariance.block<3, 3>(offset, offset);
  } else {
    auto info = ComputeMarginalInformation(graph, {node.id});
    if (!info.ok()) return info.status();
    cov = info.value().information.inverse().topLeftCorner<3, 3>();
  }
  // The marginal covariance is symmetric; the solves and the inverse above are so only to rounding, which on a badly
  // conditioned window exceeds what a consumer's symmetry check (eval::PositionNees: 1e-9) allows.
  cov = (0.5 * (cov + cov.transpose())).eval();
  // A covariance that is not finite means the window lost the pose's information (a direction no factor constrains):
  // a run-time failure, never a value in the output.
  if (!cov.allFinite() || !p.p_world_body.allFinite())
    return Status::Error("the position covariance of the pose at t = " + FormatSeconds(node.t) + " is not finite");
  const StampedPose pose{node.t, p.p_world_body, p.q_world_body};
  if (options.on_pose) {
    options.on_pose(pose, cov);
  } else {
    out->trajectory.push_back(pose);
    out->position_covariance.push_back(cov);
  }
  return Status::Ok();
}

// Marginal position covariances of the oldest `count` poses of the window, one request per pose, all from one
// factorization of its Hessian at the current estimate (each a forward substitution from the pose's block on: only
// the diagonal blocks are emitted). They equal what EmitOldest would compute for each pose in turn after marginalizing
// the ones before it: the Schur complement at the same linearization point keeps the marginal covariance of the
// remaining variables. `computed` is false when the Hessian is not positive definite (EmitOldest then falls back to
// one pose at a time).
std::vector<CovarianceRequest> OldestPoseCovariances(const ProblemBuilder& builder, std::size_t count) {
  std::vector<CovarianceRequest> out(count);
  const Graph& graph = builder.graph();
  internal::NormalEquations system(graph, FreeVariableOrder(graph));
  if (!system.Linearize(graph)) return out;
  for (std::size_t k = 0; k < count; ++k) {
    CovarianceRequest& request = out[k];
    request.variables.assign(1, builder.poses()[k].id);
    request.leading_dims = kPositionDims;
    request.computed = system.Covariance(request.variables, &request.covariance, kPositionDims);
  }
  return out;
}

Status EmitAndMarginalizeOldest(ProblemBuilder* builder, const CovarianceRequest* known,
                                const SolverWorkspace* last_solve, const TrackingOptions& options,
                                TrackingResult* out) {
  const Status emitted = EmitOldest(builder, known, options, out);
  if (!emitted.ok()) return emitted;
  const PoseNode& node = builder->poses().front();
  std::vector<VariableId> leaving = {node.id};
  // A time-varying parameter's instance leaves with the last pose that uses it (process.interval_s: poses share one).
  const PoseNode* next = builder->poses().size() > 1 ? &builder->poses()[1] : nullptr;
  for (const auto& [name, id] : node.instances)
    if (next == nullptr || next->instances.at(name) != id) leaving.push_back(id);
  if (!Marginalize(leaving, &builder->graph(), last_solve))
    return Status::Error("marginalization failed at t = " + FormatSeconds(node.t));
  builder->PopOldestPose();
  return Status::Ok();
}

// The calibration's Gaussian prior on the parameters as a linear prior factor at the calibrated values: with the
// information H = V diag(lambda) V^T, e = diag(sqrt(lambda)) V^T [x [-] x_calibrated] (directions the calibration did
// not observe, lambda ~ 0, carry no information and are left out).
Status AddCalibrationPrior(const CalibrationPrior& prior, ProblemBuilder* builder) {
  std::vector<VariableId> ids;
  std::vector<Manifold> manifolds;
  std::vector<Eigen::VectorXd> values;
  int dim = 0;
  for (const std::string& name : prior.names) {
    const auto it = builder->parameters().find(name);
    if (it == builder->parameters().end() || builder->IsTimeVarying(name))
      return Status::Error("calibration prior: '" + name + "' is not a constant parameter of the configuration");
    const Variable& v = builder->graph().variable(it->second);
    ids.push_back(it->second);
    manifolds.push_back(v.manifold);
    values.push_back(v.value);
    dim += v.manifold.tangent_dim();
  }
  if (prior.information.rows() != dim || prior.information.cols() != dim)
    return Status::Error("calibration prior: information is " + std::to_string(prior.information.rows()) + "x" +
                         std::to_string(prior.information.cols()) + ", the parameters have " + std::to_string(dim) +
                         " tangent dimensions");
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(0.5 * (prior.information + prior.information.transpose()));
  const double floor = 1e-12 * std::max(1.0, eig.eigenvalues().cwiseAbs().maxCoeff());
  std::vector<int> kept;
  for (int i = 0; i < dim; ++i)
    if (eig.eigenvalues()[i] > floor) kept.push_back(i);
  Eigen::MatrixXd J(static_cast<int>(kept.size()), dim);
  for (std::size_t r = 0; r < kept.size(); ++r)
    J.row(static_cast<int>(r)) = std::sqrt(eig.eigenvalues()[kept[r]]) * eig.eigenvectors().col(kept[r]).transpose();
  const int rows = static_cast<int>(J.rows());
  builder->graph().AddFactor(std::make_unique<LinearPriorFactor>(manifolds, values, J, Eigen::VectorXd::Zero(rows)),
                             ids, Eigen::MatrixXd::Identity(rows, rows), Loss::Trivial(), "calibration_prior", Time());
  return Status::Ok();
}

// The tracking configuration: constant parameters fixed at their calibrated (or configured) values, those under the
// calibration prior (when given) free; no stages.
Result<EstimatorConfig> ConfigForTracking(const EstimatorConfig& config_in,
                                          const std::map<std::string, Eigen::VectorXd>& calibration,
                                          const CalibrationPrior* prior) {
  EstimatorConfig config = config_in;
  for (auto& [name, p] : config.parameters)
    if (p.process.type == ProcessConfig::Type::kConstant) p.free = false;
  for (const auto& [name, value] : calibration) {
    ParameterConfig& p = config.parameters[name];
    p.value = value;
    if (p.process.type == ProcessConfig::Type::kConstant) p.free = false;
  }
  if (prior != nullptr) {
    for (const std::string& name : prior->names) {
      if (!calibration.count(name) || !config.parameters.count(name))
        return Status::Error("calibration prior: parameter '" + name + "' has no calibrated value");
      config.parameters[name].free = true;
    }
  }
  config.stages.clear();
  return config;
}

// An update's solver: Gauss-Newton under the tracking options' iteration cap, improvement threshold, time budget and
// relinearization threshold.
SolverOptions UpdateOptions(const EstimatorConfig& config) {
  SolverOptions update_options = config.solver;
  update_options.method = SolverOptions::Method::kGaussNewton;
  update_options.max_iterations = config.tracking.max_iterations;
  update_options.function_tolerance = config.tracking.improvement_threshold;
  update_options.model_tolerance = config.tracking.improvement_threshold;
  update_options.time_budget_s = config.tracking.time_budget_s;
  update_options.relinearize_threshold = config.tracking.relinearize_threshold;
  return update_options;
}

// Whatever is left in the window at the end (short recordings never leave initialization): solved, the factors from
// `first_ungated` on gated, and every pose reported, their covariances from one factorization.
Status EmitFinalWindow(const EstimatorConfig& config, FactorId first_ungated, const TrackingOptions& options,
                       ProblemBuilder* builder, TrackingResult* out) {
  const SolverSummary s = Solve(config.solver, &builder->graph());
  if (!s.usable()) return Status::Error("final window: " + s.message);
  if (config.gate_probability)
    GateAndResolve(*config.gate_probability, first_ungated, std::numeric_limits<FactorId>::max(), nullptr, builder,
                   [&] { return Solve(config.solver, &builder->graph()).iterations; });
  const std::vector<CovarianceRequest> last = OldestPoseCovariances(*builder, builder->poses().size());
  for (std::size_t k = 0; !builder->poses().empty(); ++k) {
    const CovarianceRequest* known = &last[k];
    if (builder->poses().size() == 1) return EmitOldest(builder, known, options, out);
    const Status st = EmitAndMarginalizeOldest(builder, known, nullptr, options, out);
    if (!st.ok()) return st;
  }
  return Status::Ok();
}

// The first stretch, buffered until the tracking's initialization time: aligned to the absolute fixes, solved in one
// batch and gated.
Status InitializeWindow(const EstimatorConfig& config, ProblemBuilder* builder) {
  builder->AlignToAbsoluteFixes();
  if (config.gate_probability) HoldOutNewestSpans(builder);
  const SolverSummary s = Solve(config.solver, &builder->graph());
  if (!s.usable()) return Status::Error("initialization failed: " + s.message);
  if (config.gate_probability)
    GateAndResolve(*config.gate_probability, 0, std::numeric_limits<FactorId>::max(), nullptr, builder,
                   [&] { return Solve(config.solver, &builder->graph()).iterations; });
  return Status::Ok();
}

// What the window's updates carry from one to the next.
struct WindowState {
  // The factors attached since the last update start at first_new_factor; those attached before it and not gated yet
  // at first_ungated. An update gates the latter (UpdateWindow).
  FactorId first_new_factor = 0;
  FactorId first_ungated = 0;
  CovarianceRequest leaving;  // the covariance of the pose about to leave the window
  SolverWorkspace workspace;  // the window's pattern repeats from one update to the next
  std::map<std::string, std::vector<Time>> gap_resumes;
  std::set<std::string> after_gap;  // absolute streams past a gap, none of their rows since found consistent
};

// One update: Gauss-Newton on the window, gating of the measurements attached at the last update, and a re-solve after
// each gating pass that switched any. The solve also gives the covariance of the pose about to leave the window. A
// measurement is gated one update after it is attached, once the next master sample's measurements join its newest
// pose: until then the master row that predicted the new pose and the IMU rows that tie it to the poses before are the
// only measurements of its motion since the last pose, the solve splits a conflict between them, and which of them
// fails worst is chance. Rejecting the IMU's row there leaves the pose to an outlying master row, and the velocity it
// gives the pose is carried on to the next poses, failing their good rows. The next sample's rows side with the good
// ones. A cumulative wheel master (its readings bridged, GateOutliers) is gated at attachment, with the newest pose's
// spans held out of the first solve (HoldOutNewestSpans): its bridges test a reading on both spans it joins. Returns
// the solver's iterations.
Result<int> UpdateWindow(const EstimatorConfig& config, const SolverOptions& update_options, Time t,
                         ProblemBuilder* builder, WindowState* state) {
  const bool delayed = builder->cumulative_spans().empty();
  if (config.gate_probability) HoldOutNewestSpans(builder);
  // After a gap in an absolute stream (an outage, or its clock jumped: every later row stamped late), its rows attached
  // now are held out of the first solve and tested on their innovation there (ReadmitConsistentAbsolute) until one
  // passes; those that pass go back in for a re-solve, and the gate below tests them again.
  MarkStreamsAfterGaps(builder->poses().back().t, &state->gap_resumes, &state->after_gap);
  const std::vector<FactorId> held =
      config.gate_probability && !state->after_gap.empty()
          ? NewAbsoluteFactors(*builder, state->first_new_factor, config.master, state->after_gap)
          : std::vector<FactorId>();
  HoldOut(held, builder);
  CovarianceRequest& leaving = state->leaving;
  leaving.variables.assign(1, builder->poses().front().id);
  leaving.computed = false;
  CovarianceRequest* request =
      static_cast<int>(builder->poses().size()) > config.tracking.window ? &leaving : nullptr;
  const SolverSummary s = Solve(update_options, &builder->graph(), request, &state->workspace);
  if (!s.usable()) return Status::Error("update at t = " + FormatSeconds(t) + " failed: " + s.message);
  int iterations = s.iterations;
  std::set<std::string> consistent;
  if (!held.empty() && ReadmitConsistentAbsolute(*config.gate_probability, held, builder, &consistent) > 0) {
    for (const std::string& name : consistent) state->after_gap.erase(name);
    const CovarianceRequest before = leaving;
    iterations += Solve(update_options, &builder->graph(), request, &state->workspace).iterations;
    if (request != nullptr && !leaving.computed && before.computed) leaving = before;
  }
  if (config.gate_probability) {
    // Without a gated measurement the window may not factor (a gated odometer factor leaves the newest pose's position
    // free until the next samples attach), and the Schur complement EmitOldest would fall back to runs through that
    // singular block: keep the leaving pose's covariance from before the gate then.
    iterations += GateAndResolve(*config.gate_probability, delayed ? state->first_ungated : state->first_new_factor,
                                 delayed ? state->first_new_factor : std::numeric_limits<FactorId>::max(),
                                 &state->workspace, builder, [&] {
      const CovarianceRequest before_gate = leaving;
      const int resolve_iterations =
          Solve(update_options, &builder->graph(), request, &state->workspace).iterations;
      if (request != nullptr && !leaving.computed && before_gate.computed) leaving = before_gate;
      return resolve_iterations;
    });
  }
  return iterations;
}

// Poses beyond the window leave it: after an update the one whose covariance the solve computed, after the initial
// batch every pose beyond the window, their covariances from one factorization.
Status EmitPosesBeyondWindow(const EstimatorConfig& config, const TrackingOptions& options, ProblemBuilder* builder,
                             WindowState* state, TrackingResult* out) {
  const int excess = static_cast<int>(builder->poses().size()) - config.tracking.window;
  const std::vector<CovarianceRequest> batch =
      excess > 1 ? OldestPoseCovariances(*builder, excess) : std::vector<CovarianceRequest>();
  for (int k = 0; k < excess; ++k) {
    // After an update, the leaving pose's factors were linearized at the solve's final point (Gauss-Newton).
    const Status st = EmitAndMarginalizeOldest(builder, excess > 1 ? &batch[k] : &state->leaving,
                                               excess > 1 ? nullptr : &state->workspace, options, out);
    if (!st.ok()) return st;
  }
  state->leaving.computed = false;
  return Status::Ok();
}

// The update times' mean and 99th percentile, the mean iterations per update.
void SetUpdateStatistics(std::vector<double> update_times, int iterations, TrackingResult* out) {
  double total_s = 0.0;
  for (const double dt : update_times) total_s += dt;
  out->mean_update_s = out->updates > 0 ? total_s / out->updates : 0.0;
  if (!update_times.empty()) {
    const std::size_t k = std::min(update_times.size() - 1, (update_times.size() * 99) / 100);
    std::nth_element(update_times.begin(), update_times.begin() + k, update_times.end());
    out->p99_update_s = update_times[k];
  }
  out->mean_iterations = out->updates > 0 ? static_cast<double>(iterations) / out->updates : 0.0;
}

}  // namespace

Result<TrackingResult> Track(const EstimatorConfig& config_in, const recording::Recording& recording,
                             const std::map<std::string, Eigen::VectorXd>& calibration,
                             const TrackingOptions& options) {
  const auto start = Clock::now();
  const CalibrationPrior* prior =
      config_in.tracking.calibration_prior && options.calibration_prior ? &*options.calibration_prior : nullptr;
  const Result<EstimatorConfig> tracking_config = ConfigForTracking(config_in, calibration, prior);
  if (!tracking_config.ok()) return tracking_config.status();
  const EstimatorConfig& config = tracking_config.value();
  auto built = ProblemBuilder::Create(config, recording);
  if (!built.ok()) return built.status();
  ProblemBuilder& builder = *built.value();
  if (prior != nullptr) {
    const Status added = AddCalibrationPrior(*prior, &builder);
    if (!added.ok()) return added;
  }

  const SolverOptions update_options = UpdateOptions(config);
  TrackingResult out;
  const std::vector<MeasurementRef> measurements = builder.Measurements();
  bool initialized = false;
  std::size_t poses_before = 0;
  int iterations = 0;
  std::vector<double> update_times;
  WindowState state;
  state.leaving.leading_dims = kPositionDims;
  state.gap_resumes = internal::GapResumes(config, recording, false);
  for (std::size_t i = 0; i < measurements.size(); ++i) {
    const MeasurementRef& m = measurements[i];
    builder.Add(m);
    if (builder.stream_names()[m.stream] != config.master || builder.poses().size() == poses_before) continue;
    poses_before = builder.poses().size();
    if (InterruptRequested()) return InterruptedError();
    if (options.progress && i % 1000 == 0) options.progress(static_cast<double>(i) / measurements.size());
    if (!initialized) {
      // Buffer the first stretch, then solve it in one batch.
      if (builder.poses().size() < 3 ||
          SecondsBetween(builder.poses().front().t, m.t) < config.tracking.initialization_s)
        continue;
      const Status st = InitializeWindow(config, &builder);
      if (!st.ok()) return st;
      state.first_new_factor = NextFactorId(builder.graph());
      initialized = true;
    } else {
      const auto t0 = Clock::now();
      const Result<int> update = UpdateWindow(config, update_options, m.t, &builder, &state);
      if (!update.ok()) return update.status();
      iterations += update.value();
      const double dt = std::chrono::duration<double>(Clock::now() - t0).count();
      ++out.updates;
      update_times.push_back(dt);
      out.max_update_s = std::max(out.max_update_s, dt);
    }
    state.first_ungated = state.first_new_factor;
    state.first_new_factor = NextFactorId(builder.graph());
    const Status emitted = EmitPosesBeyondWindow(config, options, &builder, &state, &out);
    if (!emitted.ok()) return emitted;
    poses_before = builder.poses().size();
  }
  builder.Finish();

  const FactorId first_final = builder.cumulative_spans().empty() ? state.first_ungated : state.first_new_factor;
  const Status final_window = EmitFinalWindow(config, first_final, options, &builder, &out);
  if (!final_window.ok()) return final_window;
  SetUpdateStatistics(std::move(update_times), iterations, &out);
  out.factor_evaluations = state.workspace.evaluations();
  out.factor_carries = state.workspace.carries();
  out.counts = builder.counts();
  out.total_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return out;
}

}  // namespace roamlab::estimator
