#include "apps/evaluate.h"

#include <cstdio>
#include <iostream>
#include <map>
#include <optional>
#include <vector>

#include <nlohmann/json.hpp>

#include "apps/cli.h"
#include "eval/evaluate.h"

namespace roamlab::apps {
namespace {

using nlohmann::json;

// A number from the metrics, "-" when absent or null.
std::string Format(const json& node, const char* format = "%.4g") {
  if (!node.is_number()) return "-";
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, node.get<double>());
  return buffer;
}

std::string FormatArray(const json& array, const char* format = "%.4g") {
  std::string out = "[";
  for (std::size_t i = 0; i < array.size(); ++i) out += (i ? ", " : "") + Format(array[i], format);
  return out + "]";
}

// "rmse x  mean x  median x  std x  max x" of a statistics object whose keys end in `suffix`.
std::string Statistics(const json& s, const std::string& suffix, const char* unit) {
  if (!s.is_object()) return "-";
  std::string out;
  for (const char* key : {"rmse", "mean", "median", "std", "min", "max"})
    out += std::string(out.empty() ? "" : "  ") + key + " " + Format(s.value(key + suffix, json())) + " " + unit;
  return out;
}

// The human-readable summary of metrics.json.
void PrintSummary(const json& m) {
  const json& a = m["association"];
  std::printf(
      "reference %s (%s); associated %s of %s estimate poses by %s (max |dt| %s s, offset %s s); alignment %s\n",
      m["reference"].value("path", std::string("-")).c_str(), m["reference"].value("kind", std::string("-")).c_str(),
      Format(a["matched"], "%.0f").c_str(), Format(a["estimate_poses"], "%.0f").c_str(),
      a.value("by", std::string("time")).c_str(), Format(a["max_time_difference_s"], "%.3g").c_str(),
      Format(a["time_offset_s"], "%.3g").c_str(), m["alignment"]["kind"].get<std::string>().c_str());
  std::printf("ATE  %s\n", Statistics(m["ate"], "_m", "m").c_str());
  std::printf("ATE rotation  %s\n", Statistics(m["ate_rotation"], "_deg", "deg").c_str());
  const json& axes = m["ate_axes"];
  std::printf("ATE rmse per axis  x %s  y %s  z %s  horizontal %s  vertical %s m\n",
              Format(axes["x"]["rmse_m"]).c_str(), Format(axes["y"]["rmse_m"]).c_str(),
              Format(axes["z"]["rmse_m"]).c_str(), Format(axes["horizontal"]["rmse_m"]).c_str(),
              Format(axes["vertical"]["rmse_m"]).c_str());
  if (m["rpe"].contains("skipped")) {
    std::printf("RPE  skipped: %s\n", m["rpe"]["skipped"].get<std::string>().c_str());
  } else {
    std::printf("RPE  over %s poses (%s s): rmse %s m, %s deg; over %s m: rmse %s m, %s deg\n",
                Format(m["rpe"]["delta_poses"], "%.0f").c_str(), Format(m["rpe"]["delta_s"]).c_str(),
                Format(m["rpe_trans_m"]).c_str(), Format(m["rpe_rot_deg"]).c_str(),
                Format(m["rpe_distance"]["distance_m"]).c_str(), Format(m["rpe_distance"]["trans_m"]["rmse"]).c_str(),
                Format(m["rpe_distance"]["rot_deg"]["rmse"]).c_str());
  }
  if (m.contains("nees")) {
    std::printf("NEES mean %s over %s poses (3 dof: 3 when consistent); %s of the poses in the 95%% band %s\n",
                Format(m["nees_mean"]).c_str(), Format(m["nees"]["poses"], "%.0f").c_str(),
                Format(m["nees"]["fraction_in_band"], "%.3f").c_str(),
                FormatArray(m["nees"]["band_single_run"], "%.3f").c_str());
  }
  if (m.contains("parameters") && !m["parameters"].empty()) {
    std::printf("%-22s %-34s %-34s %-28s %s\n", "parameter", "truth", "estimate", "error", "error/std");
    for (const auto& [name, p] : m["parameters"].items()) {
      std::string error = FormatArray(p["error"], "%.3g");
      if (p.contains("angle_error_deg")) error += " (" + Format(p["angle_error_deg"], "%.3g") + " deg)";
      std::printf("%-22s %-34s %-34s %-28s %s\n", name.c_str(), FormatArray(p["truth"]).c_str(),
                  FormatArray(p["estimate"]).c_str(), error.c_str(), FormatArray(p["error_over_std"], "%.2f").c_str());
    }
  }
}

// The comparison table of several estimates (evo_res).
void PrintTable(const std::vector<eval::Evaluation>& evaluations) {
  std::printf("%-24s %8s %12s %12s %12s %12s %12s\n", "estimate", "matched", "ATE [m]", "ATE [deg]", "RPE [m]",
              "RPE [deg]", "alignment");
  for (const eval::Evaluation& e : evaluations) {
    const json& m = e.metrics;
    std::printf("%-24s %8s %12s %12s %12s %12s %12s\n", e.estimate_name.c_str(),
                Format(m["association"]["matched"], "%.0f").c_str(), Format(m["ate_m"]).c_str(),
                Format(m["ate_rot_deg"]).c_str(), Format(m["rpe_trans_m"]).c_str(), Format(m["rpe_rot_deg"]).c_str(),
                m["alignment"]["kind"].get<std::string>().c_str());
  }
}

// The options shared by every estimate; an error message when one is invalid.
std::string MakeOptions(const EvaluateArgs& args, eval::EvaluateOptions* options) {
  options->recording_dir = args.recording;
  options->reference_file = args.reference;
  options->reference_stream = args.reference_stream;
  options->calibration_file = args.calibration;
  options->covariance_file = args.covariance;
  if (!args.covariance.empty() && args.estimates.size() > 1)
    return "--covariance belongs to one estimate: give it with a single --estimate";
  options->max_time_difference_s = args.max_time_difference_s;
  options->time_offset_s = args.t_offset_s;
  options->rpe_delta_s = args.rpe_delta_s;
  options->rpe_distance_m = args.rpe_distance_m;
  options->nees_t0_s = args.nees_t0_s;
  options->align_first_n = args.align_first;
  if (args.align_window_s.size() == 2) options->align_window_s = {args.align_window_s[0], args.align_window_s[1]};
  if (!args.align.empty()) {
    options->alignment = eval::ParseAlignmentKind(args.align);
    if (!options->alignment) return "--align: unknown alignment '" + args.align + "' (none, se3, sim3, yaw or origin)";
  }
  const auto format = [](const std::string& name, const char* option, std::optional<eval::TrajectoryFormat>* out) {
    if (name.empty()) return std::string();
    *out = eval::ParseTrajectoryFormat(name);
    return *out ? std::string() : std::string(option) + ": unknown format '" + name + "' (tum, kitti or euroc)";
  };
  if (std::string p = format(args.reference_format, "--reference-format", &options->reference_format); !p.empty())
    return p;
  return format(args.estimate_format, "--estimate-format", &options->estimate_format);
}

// Unique names for the comparison: a repeated name gets "_2", "_3", ...
void MakeNamesUnique(std::vector<eval::Evaluation>* evaluations) {
  std::map<std::string, int> seen;
  for (eval::Evaluation& e : *evaluations) {
    const int n = ++seen[e.estimate_name];
    if (n == 1) continue;
    e.estimate_name += "_" + std::to_string(n);
    e.estimate_label = "estimate (" + e.estimate_name + ")";
  }
}

}  // namespace

int RunEvaluate(const EvaluateArgs& args) {
  eval::EvaluateOptions options;
  if (const std::string problem = MakeOptions(args, &options); !problem.empty())
    return BadInput(args.err, "evaluate", problem);
  if (args.estimates.empty()) return BadInput(args.err, "evaluate", "--estimate: none given");
  std::vector<eval::Evaluation> evaluations;
  for (const std::string& estimate : args.estimates) {
    options.estimate_dir = estimate;
    if (const std::string problem = options.Validate(); !problem.empty())
      return BadInput(args.err, "evaluate", problem);
    Result<eval::Evaluation> evaluation = eval::Evaluate(options);
    if (!evaluation.ok()) return BadInput(args.err, "evaluate", evaluation.status().message());
    evaluations.push_back(std::move(evaluation).value());
  }
  MakeNamesUnique(&evaluations);
  Result<eval::WrittenEvaluation> written = evaluations.size() == 1
                                                ? eval::WriteEvaluation(evaluations.front(), args.out, !args.no_plots)
                                                : eval::WriteComparison(evaluations, args.out, !args.no_plots);
  if (!written.ok()) return Failure(args.err, "evaluate", written.status().message());

  if (!written.value().note.empty()) Report(args.err, "evaluate", written.value().note, 0);
  // Even with --quiet: a NEES that tests nothing must not pass unnoticed.
  for (const eval::Evaluation& e : evaluations)
    if (e.metrics.contains("nees") && e.metrics["nees"].contains("warning"))
      Report(args.err, "evaluate", "warning: " + e.metrics["nees"]["warning"].get<std::string>(), 0);
  if (!args.quiet) {
    if (evaluations.size() == 1)
      PrintSummary(evaluations.front().metrics);
    else
      PrintTable(evaluations);
    std::printf("wrote %s, %s", written.value().report_path.c_str(), written.value().metrics_path.c_str());
    for (const std::string& image : written.value().images) std::printf(", %s", image.c_str());
    std::printf("\n");
  }
  return 0;
}

}  // namespace roamlab::apps
