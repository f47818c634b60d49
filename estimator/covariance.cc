#include "estimator/covariance.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>
#include <map>
#include <unordered_set>

#include <Eigen/CholmodSupport>
#include <Eigen/Eigenvalues>

#include "common/interrupt.h"
#include "estimator/internal/linearization.h"
#include "estimator/internal/normal_equations.h"
#include "estimator/internal/sparse_solve.h"
#include "estimator/solver.h"

namespace roamlab::estimator {

const char* ObservabilityName(Observability observability) {
  switch (observability) {
    case Observability::kObservable:
      return "observable";
    case Observability::kWeak:
      return "weak";
    case Observability::kUnobservable:
      return "unobservable";
  }
  return "unknown";
}

namespace {

// Linearizes `system` at the graph's values with every other free variable first and `variables` last; `offsets`
// receives each variable's offset within the last block, `np` its dimension.
Status LinearizeWithVariablesLast(const Graph& graph, const std::vector<VariableId>& variables,
                                  internal::NormalEquations* system, std::vector<int>* offsets, int* np) {
  const std::unordered_set<VariableId> requested(variables.begin(), variables.end());
  std::vector<VariableId> order;
  for (VariableId id : FreeVariableOrder(graph))
    if (requested.count(id) == 0) order.push_back(id);
  *np = 0;
  for (VariableId id : variables) {
    const Variable& v = graph.variable(id);
    if (v.fixed) return Status::Error("variable '" + v.name + "' is fixed: it has no marginal covariance");
    offsets->push_back(*np);
    *np += v.manifold.tangent_dim();
    order.push_back(id);
  }
  system->set_relinearize_threshold(0.0);
  system->set_keep_linearizations(false);  // (one linearization, H alone read)
  system->Reset(graph, std::move(order));
  system->ForgetLinearizations();  // (a workspace's may have been carried to first order)
  std::string failed;
  if (!system->Linearize(graph, &failed)) {
    if (InterruptRequested()) return InterruptedError();  // (the linearization stops on one)
    return Status::Error("a factor from '" + failed + "' cannot be evaluated");
  }
  return Status::Ok();
}

// AnalyzeAutocorrelation: the truncation lag in units of the last correlated lag, and the lags sampled per window.
constexpr int kLagsPerCorrelatedWindow = 3;
constexpr int kSampledLags = 16;

// One active factor's contribution to the HAC sums: its stamp, whitened residual and a_t = E^T H~ g_t (the influence
// before the multiplication by the white covariance, see ComputeHacCovariance).
struct Score {
  std::int64_t t_ns;
  Eigen::VectorXd residual;
  Eigen::VectorXd a;
};

// The residual rows of one stream's scores.
std::vector<Eigen::VectorXd> Residuals(const std::vector<Score>& rows) {
  std::vector<Eigen::VectorXd> out;
  out.reserve(rows.size());
  for (const Score& row : rows) out.push_back(row.residual);
  return out;
}

// The influences of one stream's rows in time order, one column each.
Eigen::MatrixXd Influences(const std::vector<Score>& rows) {
  Eigen::MatrixXd a(rows.front().a.size(), static_cast<Eigen::Index>(rows.size()));
  for (std::size_t t = 0; t < rows.size(); ++t) a.col(static_cast<Eigen::Index>(t)) = rows[t].a;
  return a;
}

}  // namespace

namespace internal {
Result<Eigen::MatrixXd> SolveSparseSpd(Eigen::SparseMatrix<double> H, const Eigen::MatrixXd& rhs) {
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> llt;
  llt.cholmod().print = 0;
  llt.compute(H);
  if (llt.info() != Eigen::Success) {
    for (int i = 0; i < H.rows(); ++i) H.coeffRef(i, i) += 1e-10 * std::max(1.0, H.coeff(i, i));
    llt.compute(H);
    if (llt.info() != Eigen::Success)
      return Status::Error("the Hessian of the variables being marginalized is singular");
  }
  return Eigen::MatrixXd(llt.solve(rhs));
}
}  // namespace internal

Result<MarginalInformation> ComputeMarginalInformation(const Graph& graph, const std::vector<VariableId>& variables,
                                                       SolverWorkspace* workspace) {
  MarginalInformation result;
  result.variables = variables;
  int np = 0;
  internal::NormalEquations local;
  internal::NormalEquations& system = workspace != nullptr ? *workspace->system_ : local;
  if (Status s = LinearizeWithVariablesLast(graph, variables, &system, &result.offsets, &np); !s.ok()) return s;
  const int n = system.dimension();
  const int nx = n - np;
  {
    const Eigen::SparseMatrix<double>& upper = system.hessian_upper();
    result.conditional.resize(np);
    for (int i = 0; i < np; ++i) result.conditional[i] = upper.coeff(nx + i, nx + i);
  }
  // Schur complement S = Hpp - Hxp^T Hxx^-1 Hxp: from the envelope factorization when the other variables are a band
  // of poses with the requested ones as its border (a calibration), else with CHOLMOD on the (large, sparse) Hxx.
  if (nx > 0 && system.BorderInformation(np, &result.information)) return result;
  const Eigen::SparseMatrix<double> H = system.hessian_upper().selfadjointView<Eigen::Upper>();
  const Eigen::MatrixXd Hpp = Eigen::MatrixXd(H.bottomRightCorner(np, np));
  if (nx == 0) {
    result.information = Hpp;
    return result;
  }

  const Eigen::MatrixXd Hxp = Eigen::MatrixXd(H.topRightCorner(nx, np));
  auto Y = internal::SolveSparseSpd(H.topLeftCorner(nx, nx), Hxp);
  if (!Y.ok()) return Y.status();
  result.information = Hpp - Hxp.transpose() * Y.value();
  result.information = 0.5 * (result.information + result.information.transpose()).eval();
  return result;
}

// b_t = the Bartlett-weighted sum of the a around t (a triangle is two boxes of length L + 1 convolved), then
// sum_t a_t b_t^T.
Eigen::MatrixXd BartlettSum(const Eigen::MatrixXd& a, int lag) {
  const Eigen::Index n = a.cols(), k = a.rows();
  lag = std::max(0, lag);
  // box_t = sum_{j=0..L} a_{t-j} (rows outside 0..n-1 are zero) for t < n + L: the boxes past the last row still hold
  // rows, whose products with the last L rows the sum needs.
  const Eigen::Index boxes = n + lag;
  Eigen::MatrixXd box(k, boxes);
  Eigen::VectorXd running = Eigen::VectorXd::Zero(k);
  for (Eigen::Index t = 0; t < boxes; ++t) {
    if (t < n) running += a.col(t);
    if (t - lag - 1 >= 0 && t - lag - 1 < n) running -= a.col(t - lag - 1);
    box.col(t) = running;
  }
  Eigen::MatrixXd b(k, n);  // b_t = sum_{j=0..L} box_{t+j} / (L + 1)
  running.setZero();
  for (Eigen::Index t = boxes - 1; t >= 0; --t) {
    running += box.col(t);
    if (t + lag + 1 < boxes) running -= box.col(t + lag + 1);
    if (t < n) b.col(t) = running / static_cast<double>(lag + 1);
  }
  const Eigen::MatrixXd m = a * b.transpose();
  return 0.5 * (m + m.transpose());
}

// The bound on a prewhitening coefficient (PrewhitenedBartlettSum).
constexpr double kMaxPrewhitening = 0.97;

Eigen::MatrixXd PrewhitenedBartlettSum(const Eigen::MatrixXd& a, int lag) {
  const Eigen::Index n = a.cols(), k = a.rows();
  if (n < 3) return BartlettSum(a, lag);
  const Eigen::MatrixXd before = a.leftCols(n - 1), after = a.rightCols(n - 1);
  Eigen::VectorXd rho = Eigen::VectorXd::Zero(k);
  for (Eigen::Index i = 0; i < k; ++i) {
    const double denominator = before.row(i).squaredNorm();
    if (denominator > 0.0)
      rho[i] = std::clamp(before.row(i).dot(after.row(i)) / denominator, -kMaxPrewhitening, kMaxPrewhitening);
  }
  const Eigen::MatrixXd whitened = after - rho.asDiagonal() * before;
  const Eigen::VectorXd recolour = (Eigen::VectorXd::Ones(k) - rho).cwiseInverse();
  return static_cast<double>(n) / static_cast<double>(n - 1) * recolour.asDiagonal() * BartlettSum(whitened, lag) *
         recolour.asDiagonal();
}

ResidualAutocorrelation AnalyzeAutocorrelation(const std::vector<Eigen::VectorXd>& residuals) {
  ResidualAutocorrelation out;
  const int n = static_cast<int>(residuals.size());
  if (n < 4) return out;
  const Eigen::Index dim = residuals.front().size();
  Eigen::MatrixXd r(dim, n);
  for (int t = 0; t < n; ++t) {
    if (residuals[t].size() != dim) return out;  // (mixed dimensions: no lags)
    r.col(t) = residuals[t];
  }
  r.colwise() -= r.rowwise().mean();
  const double c0 = r.squaredNorm();
  if (!(c0 > 0.0)) return out;
  const auto rho = [&](int lag) {
    double c = 0.0;
    for (int t = 0; t + lag < n; ++t) c += r.col(t).dot(r.col(t + lag));
    return c / c0;
  };
  // Windows of lags [2^j, 2^(j+1)): the last whose mean autocorrelation reaches 2 / sqrt(n) sets the lag. A window's
  // mean is taken over at most kSampledLags lags spread over it (the autocorrelation is smooth at long lags), so
  // that a long recording costs O(n log n); the integrated time interpolates linearly between the sampled lags.
  const double threshold = 2.0 / std::sqrt(static_cast<double>(n));
  const int max_lag = n / 4;
  std::map<int, double> sampled = {{0, 1.0}};
  int last_end = 0;
  for (int begin = 1; begin <= max_lag; begin *= 2) {
    const int end = std::min(2 * begin, max_lag + 1);  // exclusive
    const int step = std::max(1, (end - begin) / kSampledLags);
    double mean = 0.0;
    int count = 0;
    for (int lag = begin; lag < end; lag += step, ++count) mean += sampled[lag] = rho(lag);
    if (mean / count >= threshold) last_end = end - 1;
  }
  out.lag = std::min(kLagsPerCorrelatedWindow * last_end, max_lag);
  if (out.lag > 0 && !sampled.count(out.lag)) sampled[out.lag] = rho(out.lag);
  double sum = 1.0;
  auto upper = sampled.begin();
  for (int lag = 1; lag <= out.lag; ++lag) {
    while (upper->first < lag) ++upper;
    const auto lower = std::prev(upper);
    const double f =
        upper->first == lag ? 1.0 : static_cast<double>(lag - lower->first) / (upper->first - lower->first);
    const double correlation = (1.0 - f) * lower->second + f * upper->second;
    sum += 2.0 * (1.0 - static_cast<double>(lag) / (out.lag + 1)) * correlation;
  }
  out.integrated_time = std::max(1.0, sum);
  return out;
}

Result<HacCovariance> ComputeHacCovariance(const Graph& graph, const std::vector<VariableId>& variables,
                                           const Eigen::MatrixXd& white_covariance) {
  internal::NormalEquations system;
  std::vector<int> offsets;
  int np = 0;
  if (Status s = LinearizeWithVariablesLast(graph, variables, &system, &offsets, &np); !s.ok()) return s;
  const int nx = system.dimension() - np;
  // H^-1 E = [-Y; I] S^-1 with Y = Hxx^-1 Hxp, S the Schur complement: u_t = S^-1 (g_p - Y^T g_x) = P a_t.
  Eigen::MatrixXd Y;
  if (nx > 0) {
    const Eigen::SparseMatrix<double> H = system.hessian_upper().selfadjointView<Eigen::Upper>();
    auto solved = internal::SolveSparseSpd(H.topLeftCorner(nx, nx), Eigen::MatrixXd(H.topRightCorner(nx, np)));
    if (!solved.ok()) return solved.status();
    Y = std::move(solved).value();
  }
  std::map<std::string, std::vector<Score>> streams;
  internal::WhitenedFactor wf;
  for (const auto& [id, entry] : graph.factors()) {
    if (!entry.active) continue;
    std::vector<bool> want(entry.variables.size());
    bool any = false;
    for (std::size_t i = 0; i < want.size(); ++i) any |= want[i] = system.OffsetOf(entry.variables[i]) >= 0;
    if (!any) continue;
    if (!internal::LinearizeFactor(graph, entry, want, &wf))
      return Status::Error("a factor from '" + entry.stream + "' cannot be evaluated");
    Score row{entry.stamp.nanoseconds(), wf.residual, Eigen::VectorXd::Zero(np)};
    for (std::size_t i = 0; i < want.size(); ++i) {
      if (!want[i]) continue;
      const int offset = system.OffsetOf(entry.variables[i]);
      const Eigen::VectorXd g = wf.jacobians[i].transpose() * wf.residual;
      if (offset >= nx)
        row.a.segment(offset - nx, g.size()) += g;
      else
        row.a.noalias() -= Y.middleRows(offset, g.size()).transpose() * g;
    }
    streams[entry.stream].push_back(std::move(row));
  }
  HacCovariance out;
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(np, np);
  for (auto& [name, rows] : streams) {
    std::stable_sort(rows.begin(), rows.end(), [](const Score& x, const Score& y) { return x.t_ns < y.t_ns; });
    const int lag = AnalyzeAutocorrelation(Residuals(rows)).lag;
    out.lags[name] = lag;
    M += BartlettSum(Influences(rows), lag);
  }
  out.covariance = white_covariance * M * white_covariance;
  out.covariance = 0.5 * (out.covariance + out.covariance.transpose()).eval();
  return out;
}

ObservabilityAnalysis AnalyzeObservability(const Eigen::MatrixXd& information, const Eigen::VectorXd& conditional,
                                           const ObservabilityOptions& options) {
  const int n = static_cast<int>(information.rows());
  ObservabilityAnalysis out;
  out.std = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::quiet_NaN());
  out.inflation = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::infinity());
  out.observability.assign(n, Observability::kUnobservable);
  out.covariance = Eigen::MatrixXd::Zero(n, n);
  out.correlation = Eigen::MatrixXd::Identity(n, n);
  if (n == 0) return out;

  // Normalize to unit diagonal; a zero diagonal means no information at all.
  Eigen::VectorXd scale(n);
  for (int i = 0; i < n; ++i) scale[i] = information(i, i) > 0.0 ? 1.0 / std::sqrt(information(i, i)) : 0.0;
  const Eigen::MatrixXd normalized = scale.asDiagonal() * information * scale.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(normalized);
  const Eigen::VectorXd& lambda = eig.eigenvalues();
  const Eigen::MatrixXd& V = eig.eigenvectors();

  // Null loading, pseudo-inverse and regularized inverse in normalized coordinates.
  Eigen::VectorXd null_loading = Eigen::VectorXd::Zero(n);
  Eigen::MatrixXd pseudo = Eigen::MatrixXd::Zero(n, n);
  Eigen::MatrixXd regularized = Eigen::MatrixXd::Zero(n, n);
  for (int k = 0; k < n; ++k) {
    const Eigen::VectorXd v = V.col(k);
    if (lambda[k] < options.null_eigenvalue) {
      null_loading += v.cwiseAbs2();
    } else {
      pseudo += v * v.transpose() / lambda[k];
    }
    regularized += v * v.transpose() / (std::max(lambda[k], 0.0) + 1e-6);
  }
  out.covariance = scale.asDiagonal() * pseudo * scale.asDiagonal();
  for (int i = 0; i < n; ++i) {
    if (scale[i] == 0.0 || null_loading[i] > options.null_loading) continue;
    out.inflation[i] = out.covariance(i, i) * conditional[i];
    if (out.inflation[i] > options.unobservable_inflation) continue;
    out.std[i] = std::sqrt(out.covariance(i, i));
    out.observability[i] =
        out.inflation[i] > options.weak_inflation ? Observability::kWeak : Observability::kObservable;
  }
  const Eigen::VectorXd d = regularized.diagonal().cwiseSqrt().cwiseInverse();
  out.correlation = d.asDiagonal() * regularized * d.asDiagonal();
  return out;
}

}  // namespace roamlab::estimator
