#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/CholmodSupport>

#include "bench/bench.h"
#include "bench/ceres_peer.h"
#include "common/atomic_file.h"
#include "estimator/calibration.h"
#include "estimator/calibration_io.h"
#include "estimator/covariance.h"
#include "estimator/internal/normal_equations.h"
#include "estimator/problem.h"
#include "estimator/solver.h"
#include "sim/simulator.h"

namespace roamlab::bench {
namespace {

// Values of the constant parameters by name.
std::map<std::string, Eigen::VectorXd> ParameterValues(const est::ProblemBuilder& builder) {
  std::map<std::string, Eigen::VectorXd> out;
  for (const auto& [name, id] : builder.parameters()) out[name] = builder.graph().variable(id).value;
  return out;
}

struct PeerComparison {
  double roamlab_seconds = 0.0, roamlab_cpu_seconds = 0.0, ceres_seconds = 0.0;
  int roamlab_iterations = 0, ceres_iterations = 0;
  double roamlab_final_cost = 0.0, ceres_final_cost = 0.0;  // each evaluated by roamlab's objective at its point
  double roamlab_reported_cost = 0.0, ceres_reported_cost = 0.0;
  double final_cost_rel_diff = 0.0;
  double max_parameter_diff_over_std = 0.0;
  std::string worst_parameter;
  double factorization_seconds = 0.0;  // one numeric CHOLMOD factorization of the final Hessian (best of 5)
  int dimension = 0;
  std::string ceres_termination, roamlab_termination;
  std::map<std::string, Eigen::VectorXd> calibration;  // roamlab's final parameter values
  est::CalibrationPrior prior;                         // their joint marginal information at roamlab's estimate
};

// Cost of the graph at its current values under roamlab's objective (whitening at those values).
double CostAt(const est::Graph& graph) {
  est::internal::NormalEquations system(graph, est::FreeVariableOrder(graph));
  return system.Linearize(graph) ? system.cost() : std::nan("");
}

// The floor: CHOLMOD's numeric factorization of the final Hessian (the pattern analysed beforehand, as a sparse
// solver's iterations would), the general sparse Cholesky the target is set against; roamlab's own iterations factor
// this band in its envelope instead. Fills `out`'s dimension and factorization_seconds (best of 5).
Status FactorizationFloor(const est::Graph& graph, PeerComparison* out) {
  est::internal::NormalEquations system(graph, est::FreeVariableOrder(graph));
  if (!system.Linearize(graph)) return Status::Error("final Hessian cannot be evaluated");
  out->dimension = system.dimension();
  Eigen::VectorXd dx;
  if (!system.Solve(0.0, &dx)) return Status::Error("final Hessian is not positive definite");
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Upper> llt;
  llt.cholmod().print = 0;
  llt.analyzePattern(system.hessian_upper());
  out->factorization_seconds = 1e9;
  for (int k = 0; k < 5; ++k) {
    const auto t0 = Clock::now();
    llt.factorize(system.hessian_upper());
    out->factorization_seconds = std::min(out->factorization_seconds, Since(t0));
  }
  return Status::Ok();
}

Result<PeerComparison> CompareWithCeres(est::EstimatorConfig config, const recording::Recording& rec) {
  config.stages.clear();  // one stage: every configured parameter free
  config.gate_probability.reset();
  auto built = est::ProblemBuilder::Create(config, rec);
  if (!built.ok()) return built.status();
  est::ProblemBuilder& builder = *built.value();
  for (const est::MeasurementRef& m : builder.Measurements()) builder.Add(m);
  builder.Finish();
  builder.AlignToAbsoluteFixes();
  est::Graph& graph = builder.graph();
  PeerComparison out;

  // Ceres from the graph's (initial) values; the graph is left as it is.
  CeresPeerOptions peer_options;
  peer_options.max_iterations = config.solver.max_iterations;
  peer_options.function_tolerance = config.solver.function_tolerance;
  peer_options.parameter_tolerance = config.solver.step_tolerance;
  peer_options.initial_lambda = config.solver.initial_lambda;
  // Each solver runs kSolveRuns times from the same values and its least time is kept, as the floor's factorization
  // (best of 5): other work on the machine only ever slows a run down.
  constexpr int kSolveRuns = 3;
  CeresPeerResult ceres = SolveWithCeres(graph, peer_options);
  for (int run = 1; run < kSolveRuns && ceres.usable; ++run) {
    const double fastest = ceres.seconds;
    ceres = SolveWithCeres(graph, peer_options);
    ceres.seconds = std::min(ceres.seconds, fastest);
  }
  if (!ceres.usable) return Status::Error("Ceres: " + ceres.termination);
  out.ceres_seconds = ceres.seconds;
  out.ceres_iterations = ceres.iterations;
  out.ceres_reported_cost = ceres.final_cost;
  out.ceres_termination = ceres.termination;

  // roamlab from the same values (restored before each run).
  std::map<est::VariableId, Eigen::VectorXd> initial_values;
  for (const auto& [id, v] : graph.variables()) initial_values[id] = v.value;
  est::SolverSummary summary;
  out.roamlab_seconds = out.roamlab_cpu_seconds = 1e9;
  for (int run = 0; run < kSolveRuns; ++run) {
    for (const auto& [id, value] : initial_values) graph.mutable_variable(id).value = value;
    const double c0 = ProcessCpu();
    summary = est::Solve(config.solver, &graph);
    out.roamlab_cpu_seconds = std::min(out.roamlab_cpu_seconds, ProcessCpu() - c0);
    if (!summary.usable()) return Status::Error("roamlab: " + summary.message);
    out.roamlab_seconds = std::min(out.roamlab_seconds, summary.seconds);
  }
  out.roamlab_iterations = summary.iterations;
  out.roamlab_reported_cost = summary.final_cost;
  out.roamlab_termination = est::TerminationName(summary.termination);
  out.calibration = ParameterValues(builder);

  if (Status floor = FactorizationFloor(graph, &out); !floor.ok()) return floor;

  // Standard deviations of the parameters at roamlab's estimate.
  std::vector<est::VariableId> ids;
  std::vector<std::string> names;
  for (const auto& [name, id] : builder.parameters()) {
    if (graph.variable(id).fixed) continue;
    ids.push_back(id);
    names.push_back(name);
  }
  auto info = est::ComputeMarginalInformation(graph, ids);
  if (!info.ok()) return info.status();
  const Eigen::MatrixXd covariance = info.value().information.inverse();
  out.prior = est::CalibrationPrior{names, info.value().information};

  // Both final points under roamlab's objective, and the parameters' differences in tangent space over their std.
  out.roamlab_final_cost = CostAt(graph);
  std::map<est::VariableId, Eigen::VectorXd> roamlab_values;
  for (const auto& [id, value] : ceres.values) {
    roamlab_values[id] = graph.variable(id).value;
    graph.mutable_variable(id).value = value;
  }
  out.ceres_final_cost = CostAt(graph);
  for (std::size_t i = 0; i < ids.size(); ++i) {
    const est::Variable& v = graph.variable(ids[i]);
    Eigen::VectorXd d(v.manifold.tangent_dim());
    v.manifold.Minus(v.value.data(), roamlab_values.at(ids[i]).data(), d.data());
    for (int k = 0; k < d.size(); ++k) {
      const int row = info.value().offsets[i] + k;
      const double ratio = std::abs(d[k]) / std::sqrt(covariance(row, row));
      if (ratio > out.max_parameter_diff_over_std) {
        out.max_parameter_diff_over_std = ratio;
        out.worst_parameter = names[i] + "[" + std::to_string(k) + "]";
      }
    }
  }
  for (const auto& [id, value] : roamlab_values) graph.mutable_variable(id).value = value;
  out.final_cost_rel_diff = std::abs(out.ceres_final_cost - out.roamlab_final_cost) / out.roamlab_final_cost;
  return out;
}

}  // namespace

// Reads REC, runs the product's offline calibration, writes seconds and peak memory.
int ChildCalibrate(const std::string& rec_dir, const std::string& config_path, const std::string& out_path) {
  auto rec = recording::ReadRecording(rec_dir);
  if (!rec.ok()) return Fail(rec.status().message());
  auto config = est::LoadEstimatorConfig(config_path);
  if (!config.ok()) return Fail(config.status().message());
  const auto t0 = Clock::now();
  const double c0 = ProcessCpu();
  auto result = est::Calibrate(config.value(), rec.value());
  const double wall = Since(t0), cpu = ProcessCpu() - c0;
  if (!result.ok()) return Fail(result.status().message());
  const Json j = {{"seconds", wall},
                  {"cpu_seconds", cpu},
                  {"iterations", result.value().iterations},
                  {"final_cost", result.value().final_cost},
                  {"peak_rss_kb", StatusKb("VmHWM")},
                  {"poses", result.value().trajectory.size()}};
  if (const Status s = WriteFileAtomic(out_path, j.dump(2) + "\n"); !s.ok()) {
    std::fprintf(stderr, "%s\n", s.message().c_str());
    return 1;
  }
  return 0;
}

// 2-3. The Ceres peer and the floor; `peer` receives the peer problem's calibration (roamlab's solution of it).
int BenchCeresPeer(const Context& ctx, const recording::Recording& rec, Json* j,
                   TrackingCalibration* peer_calibration) {
  std::optional<sim::Simulation> peer_simulation;
  if (ctx.sizes.peer_drive_s != ctx.scenario.duration_s) {
    auto shorter = sim::Simulate(LongerDrive(ctx.scenario, ctx.sizes.peer_drive_s));
    if (!shorter.ok()) return Fail(shorter.status().message());
    peer_simulation = std::move(shorter).value();
  }
  auto peer = CompareWithCeres(ctx.calibration_config, peer_simulation ? peer_simulation->recording : rec);
  if (!peer.ok()) return Fail(peer.status().message());
  const PeerComparison& p = peer.value();
  const double ceres_ratio = p.roamlab_seconds / p.ceres_seconds;
  const double per_iteration = p.roamlab_seconds / std::max(1, p.roamlab_iterations);
  const double over_floor = per_iteration / p.factorization_seconds;
  (*j)["ceres_time_ratio"] = ceres_ratio;
  (*j)["final_cost_rel_diff"] = p.final_cost_rel_diff;
  (*j)["iteration_over_floor"] = over_floor;
  (*j)["ceres"] = {{"roamlab_seconds", p.roamlab_seconds},
                   {"roamlab_cpu_seconds", p.roamlab_cpu_seconds},
                   {"ceres_seconds", p.ceres_seconds},
                   {"roamlab_iterations", p.roamlab_iterations},
                   {"ceres_iterations", p.ceres_iterations},
                   {"roamlab_final_cost", p.roamlab_final_cost},
                   {"ceres_final_cost", p.ceres_final_cost},
                   {"roamlab_reported_cost", p.roamlab_reported_cost},
                   {"ceres_reported_cost", p.ceres_reported_cost},
                   {"roamlab_termination", p.roamlab_termination},
                   {"ceres_termination", p.ceres_termination},
                   {"max_parameter_diff_over_std", p.max_parameter_diff_over_std},
                   {"worst_parameter", p.worst_parameter},
                   {"hessian_dimension", p.dimension},
                   {"factorization_seconds", p.factorization_seconds},
                   {"roamlab_seconds_per_iteration", per_iteration}};
  Say("  calibration vs Ceres 2.1           roamlab %.2f s (%d it), Ceres %.2f s (%d it): roamlab/Ceres %.2f"
      "   target <= 0.5   ratio %.2f\n",
      p.roamlab_seconds, p.roamlab_iterations, p.ceres_seconds, p.ceres_iterations, ceres_ratio, 0.5 / ceres_ratio);
  Say("    final cost roamlab %.6f, Ceres %.6f (relative difference %.2e, target < 1e-6); parameters differ by at "
      "most %.3f std (%s)\n",
      p.roamlab_final_cost, p.ceres_final_cost, p.final_cost_rel_diff, p.max_parameter_diff_over_std,
      p.worst_parameter.c_str());
  Say("  iteration over factorization floor %8.2f (%.1f ms / %.2f ms, n = %d)   target <= 3   ratio %.2f\n", over_floor,
      1e3 * per_iteration, 1e3 * p.factorization_seconds, p.dimension, 3.0 / over_floor);
  peer_calibration->values = p.calibration;
  peer_calibration->prior = p.prior;
  return 0;
}

// The calibration that tracking (steps 4, 6 and 7) runs under: the product's (`roamlab calibrate`: stages, gating,
// observability) of step 1's recording, what `roamlab track --calibration` is given after it, whatever drive step 2
// used. Step 2's calibration (a shorter drive in --quick, one stage without gating) sits further from the
// simulation's values, and the calibration prior holds the window against it; tracking under it is measured beside
// (the 40-pose window). `calibration_json` receives the file written for the child processes.
int CalibrateForTracking(const Context& ctx, const recording::Recording& rec, TrackingCalibration* calibrated,
                         std::string* calibration_json) {
  const auto t_product = Clock::now();
  auto product = est::Calibrate(ctx.calibration_config, rec);
  if (!product.ok()) return Fail(product.status().message());
  for (const est::ParameterEstimate& e : product.value().parameters) {
    calibrated->values[e.name] = e.estimate;
    calibrated->prior.names.push_back(e.name);
  }
  calibrated->prior.information = product.value().information;
  Say("  calibration for tracking           the product's of step 1's %.0f s drive, %.2f s, %d iterations\n",
      ctx.scenario.duration_s, Since(t_product), product.value().iterations);
  *calibration_json = (ctx.tmp / "calibration.json").string();
  const Status written = est::WriteCalibrationFile(product.value(), "", "", *calibration_json);
  if (!written.ok()) return Fail(written.message());
  return 0;
}

// 5. Calibration scaling, each size in its own process.
int BenchCalibrationScaling(const Context& ctx, const recording::Recording& rec, Json* j) {
  std::map<double, double> calibration_seconds, calibration_cpu_seconds;
  for (double size : ctx.sizes.calibration_s) {
    const std::string dir = (ctx.tmp / ("rec_" + std::to_string(static_cast<int>(size)))).string();
    // A drive as long as the scenario's (up to 30 s, which LongerDrive leaves unchanged) is the recording of step 1,
    // the simulation being deterministic: written out instead of simulated again.
    const Status simulated = size == ctx.scenario.duration_s && size <= 30.0 ? recording::WriteRecording(rec, dir)
                                                                             : SimulateTo(ctx.scenario, size, dir);
    if (!simulated.ok()) return Fail(simulated.message());
    // The shorter drives' calibrations (under a second for 30 s) move by 10 % from one process to the next on a
    // shared host: the median of several runs, each in its own process; the 30 min one averages over its 45-60 s.
    const int runs = size <= 60.0 ? 5 : size <= 600.0 ? 3 : 1;
    const std::string out = (ctx.tmp / "calibrate.json").string();
    std::vector<Json> repeats;
    for (int run = 0; run < runs; ++run) {
      auto child = RunChild(ctx.self, {"--child-calibrate", dir, ctx.calibration_path, out}, out);
      if (!child.ok()) return Fail(child.status().message());
      repeats.push_back(child.value());
    }
    std::filesystem::remove_all(dir);
    std::sort(repeats.begin(), repeats.end(),
              [](const Json& a, const Json& b) { return a["seconds"].get<double>() < b["seconds"].get<double>(); });
    Json c = repeats[repeats.size() / 2];
    c["runs"] = runs;
    c["seconds_min"] = repeats.front()["seconds"];
    c["seconds_max"] = repeats.back()["seconds"];
    calibration_seconds[size] = c["seconds"].get<double>();
    calibration_cpu_seconds[size] = c["cpu_seconds"].get<double>();
    // CPU time per pose and iteration (set-up, gate passes and the observability analysis spread over them): flat
    // when the calibration's cost grows with the data alone.
    const double us_per_pose_iteration =
        1e6 * c["cpu_seconds"].get<double>() / (c["poses"].get<double>() * std::max(1, c["iterations"].get<int>()));
    c["cpu_us_per_pose_iteration"] = us_per_pose_iteration;
    (*j)["calibration_scaling"][std::to_string(static_cast<int>(size)) + "s"] = c;
    char spread[96] = "";
    if (runs > 1)
      std::snprintf(spread, sizeof spread, "; median of %d, %.2f-%.2f s", runs, c["seconds_min"].get<double>(),
                    c["seconds_max"].get<double>());
    Say("  calibration of a %5.0f s drive    %8.2f s wall, %.2f s CPU, %d iterations (%.1f us CPU per pose and "
        "iteration), peak memory %.0f MB%s\n",
        size, c["seconds"].get<double>(), c["cpu_seconds"].get<double>(), c["iterations"].get<int>(),
        us_per_pose_iteration, c["peak_rss_kb"].get<double>() / 1024.0, spread);
  }
  const double smallest = ctx.sizes.calibration_s.front(), largest = ctx.sizes.calibration_s.back();
  const double growth = calibration_seconds[largest] / calibration_seconds[smallest];
  const double cpu_growth = calibration_cpu_seconds[largest] / calibration_cpu_seconds[smallest];
  const double growth_target = largest / smallest * 70.0 / 60.0;  // 70x for 60x the data
  (*j)["calibration_30min_over_30s"] = growth;  // --quick: largest over smallest of ctx.sizes.calibration_drives_s
  (*j)["calibration_30min_over_30s_cpu"] = cpu_growth;
  Say("  calibration %.0f s / %.0f s          %8.1f (CPU time %.1f)   target <= %.1f   ratio %.2f\n", largest, smallest,
      growth, cpu_growth, growth_target, growth_target / growth);
  return 0;
}

}  // namespace roamlab::bench
