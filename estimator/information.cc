#include "estimator/information.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <set>
#include <unordered_map>
#include <utility>

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCore>

#include "estimator/geometry.h"
#include "estimator/internal/linearization.h"
#include "estimator/internal/sparse_solve.h"
#include "estimator/problem.h"
#include "estimator/solver.h"

namespace roamlab::estimator {

std::string InformationOptions::Validate() const {
  if (!(window_s > 0.0) || !std::isfinite(window_s)) return "window_s must be > 0";
  return "";
}

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The pose of O at t: linear in position, slerp in orientation between the samples around t (clamped at the ends).
StampedPose InterpolatePose(const Trajectory& trajectory, Time t) {
  auto after = std::lower_bound(trajectory.begin(), trajectory.end(), t,
                                [](const StampedPose& p, Time when) { return p.t < when; });
  if (after == trajectory.begin()) return trajectory.front();
  if (after == trajectory.end()) return trajectory.back();
  const StampedPose& a = *std::prev(after);
  const StampedPose& b = *after;
  const double span = SecondsBetween(a.t, b.t);
  const double f = span > 0.0 ? SecondsBetween(a.t, t) / span : 0.0;
  return {t, a.p_world_body + f * (b.p_world_body - a.p_world_body), a.q_world_body.slerp(f, b.q_world_body)};
}

// Component labels of a parameter's tangent coordinates.
std::vector<std::string> ComponentLabels(const std::string& name, const Manifold& manifold) {
  const int dim = manifold.tangent_dim();
  std::vector<std::string> out;
  if (manifold.kind() == ManifoldKind::kQuaternion) {
    for (const char* axis : {"rx", "ry", "rz"}) out.push_back(name + "[" + axis + "]");
  } else if (dim == 1) {
    out.push_back(name);
  } else if (dim == 3) {
    for (const char* axis : {"x", "y", "z"}) out.push_back(name + "[" + axis + "]");
  } else if (dim == 9) {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) out.push_back(name + "[" + std::to_string(r) + "," + std::to_string(c) + "]");
  } else {
    for (int k = 0; k < dim; ++k) out.push_back(name + "[" + std::to_string(k) + "]");
  }
  return out;
}

// The graph at the truth: every pose from the trajectory, every parameter (and time-varying instance) from `truth`
// where given; the free constant parameters in `result->parameters`.
Status SetTruth(const std::map<std::string, std::vector<double>>& truth, const Trajectory& trajectory,
                ProblemBuilder* builder, InformationResult* result) {
  Graph& graph = builder->graph();
  const auto true_value = [&](const std::string& name, Variable* v) -> Result<bool> {
    const auto it = truth.find(name);
    if (it == truth.end()) return false;
    if (static_cast<int>(it->second.size()) != v->manifold.ambient_dim())
      return Status::Error("truth of '" + name + "' has " + std::to_string(it->second.size()) + " values, the " +
                           v->manifold.Name() + " parameter " + std::to_string(v->manifold.ambient_dim()));
    v->value = Eigen::Map<const Eigen::VectorXd>(it->second.data(), static_cast<Eigen::Index>(it->second.size()));
    if (v->manifold.kind() == ManifoldKind::kQuaternion) v->value.normalize();
    return true;
  };
  for (const PoseNode& node : builder->poses()) {
    const StampedPose pose = InterpolatePose(trajectory, node.t);
    PoseToArray(Pose<double>{pose.p_world_body, pose.q_world_body.normalized()},
                graph.mutable_variable(node.id).value.data());
    for (const auto& [name, id] : node.instances) {
      auto set = true_value(name, &graph.mutable_variable(id));
      if (!set.ok()) return set.status();
    }
  }
  const std::vector<std::string> free = builder->FreeParameterNames();
  const std::set<std::string> free_set(free.begin(), free.end());
  for (const auto& [name, id] : builder->parameters()) {
    Variable& v = graph.mutable_variable(id);
    auto set = true_value(name, &v);
    if (!set.ok()) return set.status();
    v.fixed = free_set.count(name) == 0;
    if (v.fixed) continue;
    result->parameters.push_back({name, v.manifold, v.value, set.value(), 0});
  }
  return Status::Ok();
}

// Where each free variable's tangent block sits: the nuisance variables x (poses, time-varying instances) in the
// solver's order, the analysed parameters p in result order.
struct Layout {
  std::unordered_map<VariableId, int> x_offset, p_offset;
  int nx = 0, np = 0;
};

Layout MakeLayout(const Graph& graph, const std::map<std::string, VariableId>& parameters,
                  const std::vector<InformationParameter>& analysed) {
  Layout layout;
  std::set<VariableId> p_ids;
  for (const InformationParameter& p : analysed) {
    const VariableId id = parameters.at(p.name);
    p_ids.insert(id);
    layout.p_offset[id] = layout.np;
    layout.np += p.manifold.tangent_dim();
  }
  for (VariableId id : FreeVariableOrder(graph)) {
    if (p_ids.count(id) != 0) continue;
    layout.x_offset[id] = layout.nx;
    layout.nx += graph.variable(id).manifold.tangent_dim();
  }
  return layout;
}

// One factor's whitened Jacobians at the graph's values, stacked by role: Jx (residual x nx blocks, with their
// offsets) and Jp (residual x np).
struct FactorRows {
  std::vector<std::pair<int, Eigen::MatrixXd>> x_blocks;  // (offset in x, block)
  Eigen::MatrixXd Jp;
};

bool LinearizeRows(const Graph& graph, const FactorEntry& entry, const Layout& layout, internal::WhitenedFactor* wf,
                   FactorRows* rows) {
  std::vector<bool> want(entry.variables.size());
  for (std::size_t i = 0; i < entry.variables.size(); ++i) want[i] = !graph.variable(entry.variables[i]).fixed;
  if (!internal::LinearizeFactor(graph, entry, want, wf)) return false;
  rows->x_blocks.clear();
  rows->Jp = Eigen::MatrixXd::Zero(entry.factor->residual_dim(), layout.np);
  for (std::size_t i = 0; i < entry.variables.size(); ++i) {
    if (!want[i]) continue;
    const VariableId id = entry.variables[i];
    if (const auto p = layout.p_offset.find(id); p != layout.p_offset.end()) {
      rows->Jp.middleCols(p->second, wf->jacobians[i].cols()) += wf->jacobians[i];
    } else {
      rows->x_blocks.emplace_back(layout.x_offset.at(id), wf->jacobians[i]);
    }
  }
  return true;
}

// Calls visit(entry, rows) for every active factor, linearized at the graph's values.
template <typename Visit>
Status ForEachActiveFactor(const Graph& graph, const Layout& layout, Visit visit) {
  internal::WhitenedFactor wf;
  FactorRows rows;
  for (const auto& [id, entry] : graph.factors()) {
    if (!entry.active) continue;
    if (!LinearizeRows(graph, entry, layout, &wf, &rows))
      return Status::Error("a factor of '" + entry.stream + "' cannot be evaluated at the truth");
    visit(entry, rows);
  }
  return Status::Ok();
}

struct FisherBlocks {
  Eigen::SparseMatrix<double> Hxx;
  Eigen::MatrixXd Hxp, Hpp;
};

// H = J^T J by blocks over every active factor.
Result<FisherBlocks> AccumulateFisher(const Graph& graph, const Layout& layout) {
  FisherBlocks out;
  out.Hxp = Eigen::MatrixXd::Zero(layout.nx, layout.np);
  out.Hpp = Eigen::MatrixXd::Zero(layout.np, layout.np);
  std::vector<Eigen::Triplet<double>> triplets;
  const Status status = ForEachActiveFactor(graph, layout, [&](const FactorEntry&, const FactorRows& rows) {
    out.Hpp += rows.Jp.transpose() * rows.Jp;
    for (const auto& [a, Ja] : rows.x_blocks) {
      out.Hxp.middleRows(a, Ja.cols()) += Ja.transpose() * rows.Jp;
      for (const auto& [b, Jb] : rows.x_blocks) {
        const Eigen::MatrixXd block = Ja.transpose() * Jb;
        for (int r = 0; r < block.rows(); ++r)
          for (int c = 0; c < block.cols(); ++c)
            if (block(r, c) != 0.0) triplets.emplace_back(a + r, b + c, block(r, c));
      }
    }
  });
  if (!status.ok()) return status;
  out.Hxx.resize(layout.nx, layout.nx);
  out.Hxx.setFromTriplets(triplets.begin(), triplets.end());
  return out;
}

// The shares of the header comment, divided by (I^+)_ii: (J_p,f w_i)^T (R_f w_i) summed per stream (measured_by),
// |R_f w_i|^2 summed per stream and window.
Status SplitInformation(const Graph& graph, const Layout& layout, const Eigen::MatrixXd& Y,
                        InformationResult* result) {
  const int np = layout.np;
  const Eigen::MatrixXd& W = result->covariance;
  std::map<std::string, std::vector<Eigen::VectorXd>> variance;  // stream -> window -> per component
  std::map<std::string, std::vector<Eigen::VectorXd>> measured;   // stream -> window -> per component
  const Status status = ForEachActiveFactor(graph, layout, [&](const FactorEntry& entry, const FactorRows& rows) {
    Eigen::MatrixXd R = rows.Jp;
    for (const auto& [a, Ja] : rows.x_blocks) R.noalias() -= Ja * Y.middleRows(a, Ja.cols());
    const Eigen::MatrixXd RW = R * W;
    const double since = SecondsBetween(result->t0, entry.stamp);
    const int window = std::clamp(static_cast<int>(std::floor(since / result->window_s)), 0, result->windows - 1);
    std::vector<Eigen::VectorXd>& per_window = variance[entry.stream];
    if (per_window.empty()) per_window.assign(result->windows, Eigen::VectorXd::Zero(np));
    per_window[window] += RW.colwise().squaredNorm().transpose();
    std::vector<Eigen::VectorXd>& measured_per_window = measured[entry.stream];
    if (measured_per_window.empty()) measured_per_window.assign(result->windows, Eigen::VectorXd::Zero(np));
    measured_per_window[window] += ((rows.Jp * W).cwiseProduct(RW)).colwise().sum().transpose();
  });
  if (!status.ok()) return status;
  for (const auto& [stream, per_window] : variance) result->streams.push_back(stream);
  for (int i = 0; i < np; ++i) {
    InformationComponent& c = result->components[i];
    const bool observable = std::isfinite(c.crb_std);
    // (I^+)_ii; the variance shares' own total, equal to it but for the solve's rounding, makes them sum to 1 exactly.
    const double v = observable ? W(i, i) : kNaN;
    double v_variance = 0.0;
    for (const auto& [stream, per_window] : variance)
      for (const Eigen::VectorXd& w : per_window) v_variance += w[i];
    if (!observable) v_variance = kNaN;
    c.by_window.assign(result->windows, observable ? 0.0 : kNaN);
    for (const auto& [stream, per_window] : variance) {
      std::vector<double>& measured_series = c.measured_by_stream_window[stream];
      measured_series.assign(result->windows, kNaN);
      double measured_total = observable ? 0.0 : kNaN;
      for (int k = 0; k < result->windows && observable; ++k) {
        measured_series[k] = measured.at(stream)[k][i] / v;
        measured_total += measured_series[k];
      }
      c.measured_by[stream] = measured_total;
      std::vector<double>& series = c.by_stream_window[stream];
      series.assign(result->windows, kNaN);
      double total = observable ? 0.0 : kNaN;
      for (int k = 0; k < result->windows && observable; ++k) {
        series[k] = per_window[k][i] / v_variance;
        total += series[k];
        c.by_window[k] += series[k];
      }
      c.by_stream[stream] = total;
    }
  }
  return Status::Ok();
}

// The eigen-directions of N = C^-1/2 I C^-1/2 below 1 / weak_inflation, named by their large loadings.
std::vector<InformationDirection> WeakDirections(const InformationResult& r, const ObservabilityOptions& options) {
  const Eigen::Index n = r.information.rows();
  Eigen::VectorXd scale(n);
  for (Eigen::Index i = 0; i < n; ++i) scale[i] = r.conditional[i] > 0.0 ? 1.0 / std::sqrt(r.conditional[i]) : 1.0;
  const Eigen::MatrixXd N = scale.asDiagonal() * r.information * scale.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(N);
  std::vector<InformationDirection> out;
  for (Eigen::Index k = 0; k < n; ++k) {  // ascending eigenvalues: the weakest first
    const double lambda = eigen.eigenvalues()[k];
    if (lambda >= 1.0 / options.weak_inflation) break;
    InformationDirection d;
    d.eigenvalue = lambda;
    d.observability = lambda < 1.0 / options.unobservable_inflation ? Observability::kUnobservable : Observability::kWeak;
    d.direction = eigen.eigenvectors().col(k);
    const Eigen::Index largest = [&] {
      Eigen::Index best = 0;
      d.direction.cwiseAbs().maxCoeff(&best);
      return best;
    }();
    if (d.direction[largest] < 0.0) d.direction = -d.direction;
    std::vector<Eigen::Index> order(static_cast<std::size_t>(n));
    for (Eigen::Index i = 0; i < n; ++i) order[static_cast<std::size_t>(i)] = i;
    std::sort(order.begin(), order.end(),
              [&](Eigen::Index a, Eigen::Index b) { return std::abs(d.direction[a]) > std::abs(d.direction[b]); });
    for (Eigen::Index i : order) {
      const double v = d.direction[i];
      if (v * v < kDirectionLoading) break;
      char number[32];
      std::snprintf(number, sizeof(number), "%.2f", std::abs(v));
      d.name += (d.name.empty() ? (v < 0.0 ? "-" : "") : (v < 0.0 ? " - " : " + ")) + std::string(number) + " " +
                r.components[static_cast<std::size_t>(i)].label;
    }
    out.push_back(std::move(d));
  }
  return out;
}

// Components, covariance and CRB std from I (AnalyzeObservability: the pseudo-inverse and each component's class).
void FillComponents(const ObservabilityOptions& options, InformationResult* result) {
  const ObservabilityAnalysis analysis = AnalyzeObservability(result->information, result->conditional, options);
  result->covariance = analysis.covariance;
  for (std::size_t p = 0; p < result->parameters.size(); ++p) {
    InformationParameter& param = result->parameters[p];
    param.first_component = static_cast<int>(result->components.size());
    for (const std::string& label : ComponentLabels(param.name, param.manifold)) {
      const Eigen::Index i = static_cast<Eigen::Index>(result->components.size());
      InformationComponent c;
      c.parameter = param.name;
      c.label = label;
      c.observability = analysis.observability[i];
      c.crb_std = analysis.std[i];
      result->components.push_back(std::move(c));
    }
  }
}

}  // namespace

Result<InformationResult> AnalyzeInformation(const EstimatorConfig& config, const recording::Recording& recording,
                                             const std::map<std::string, std::vector<double>>& truth,
                                             const Trajectory& true_trajectory, const InformationOptions& options) {
  if (const std::string problem = options.Validate(); !problem.empty()) return Status::Error(problem);
  if (true_trajectory.empty()) return Status::Error("the true trajectory is empty");
  auto built = ProblemBuilder::Create(config, recording);
  if (!built.ok()) return built.status();
  ProblemBuilder& builder = *built.value();
  for (const MeasurementRef& m : builder.Measurements()) builder.Add(m);
  builder.Finish();
  if (builder.poses().size() < 3) return Status::Error("the recording gives fewer than 3 poses on the master stream");

  // The graph at the truth, with the configured noise alone: no robust loss, every factor active.
  InformationResult result;
  if (Status s = SetTruth(truth, true_trajectory, &builder, &result); !s.ok()) return s;
  if (result.parameters.empty()) return Status::Error("the configuration has no free constant parameter");
  Graph& graph = builder.graph();
  std::vector<FactorId> ids;
  for (const auto& [id, entry] : graph.factors()) ids.push_back(id);
  for (FactorId id : ids) {
    graph.mutable_factor(id).loss = Loss::Trivial();
    graph.mutable_factor(id).active = true;
  }
  result.poses = static_cast<int>(builder.poses().size());
  result.factors = static_cast<int>(ids.size());
  result.window_s = options.window_s;
  result.t0 = builder.poses().front().t;
  const double span = SecondsBetween(result.t0, builder.poses().back().t);
  result.windows = std::max(1, static_cast<int>(std::ceil(span / options.window_s - 1e-9)));

  // Fisher information by blocks, the poses' response Y and the Schur complement I.
  const Layout layout = MakeLayout(graph, builder.parameters(), result.parameters);
  auto fisher = AccumulateFisher(graph, layout);
  if (!fisher.ok()) return fisher.status();
  auto Y = internal::SolveSparseSpd(fisher.value().Hxx, fisher.value().Hxp);
  if (!Y.ok()) return Y.status();
  result.information = fisher.value().Hpp - fisher.value().Hxp.transpose() * Y.value();
  result.information = 0.5 * (result.information + result.information.transpose()).eval();
  result.conditional = fisher.value().Hpp.diagonal();

  FillComponents(options.observability, &result);
  if (Status s = SplitInformation(graph, layout, Y.value(), &result); !s.ok()) return s;
  result.directions = WeakDirections(result, options.observability);
  return result;
}

}  // namespace roamlab::estimator
