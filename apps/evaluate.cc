#include "apps/evaluate.h"

#include <cstdio>
#include <iostream>

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

// The human-readable summary of metrics.json.
void PrintSummary(const json& m) {
  const json& a = m["association"];
  std::printf("matched %s of %s estimate poses (max |dt| %s s); alignment %s\n", Format(a["matched"], "%.0f").c_str(),
              Format(a["estimate_poses"], "%.0f").c_str(), Format(a["max_time_difference_s"], "%.3g").c_str(),
              m["alignment"]["kind"].get<std::string>().c_str());
  std::printf("ATE  rmse %s m  mean %s m  median %s m  max %s m\n", Format(m["ate"]["rmse_m"]).c_str(),
              Format(m["ate"]["mean_m"]).c_str(), Format(m["ate"]["median_m"]).c_str(),
              Format(m["ate"]["max_m"]).c_str());
  std::printf("RPE  over %s poses (%s s): rmse %s m, %s deg; over %s m: rmse %s m, %s deg\n",
              Format(m["rpe"]["delta_poses"], "%.0f").c_str(), Format(m["rpe"]["delta_s"]).c_str(),
              Format(m["rpe_trans_m"]).c_str(), Format(m["rpe_rot_deg"]).c_str(),
              Format(m["rpe_distance"]["distance_m"]).c_str(), Format(m["rpe_distance"]["trans_m"]["rmse"]).c_str(),
              Format(m["rpe_distance"]["rot_deg"]["rmse"]).c_str());
  if (m.contains("nees")) {
    std::printf("NEES mean %s over %s poses (3 dof: 3 when consistent); %s of the poses in the 95%% band %s\n",
                Format(m["nees_mean"]).c_str(), Format(m["nees"]["poses"], "%.0f").c_str(),
                Format(m["nees"]["fraction_in_band"], "%.3f").c_str(),
                FormatArray(m["nees"]["band_single_run"], "%.3f").c_str());
  }
  if (m.contains("parameters")) {
    std::printf("%-22s %-34s %-34s %-28s %s\n", "parameter", "truth", "estimate", "error", "error/std");
    for (const auto& [name, p] : m["parameters"].items()) {
      std::string error = FormatArray(p["error"], "%.3g");
      if (p.contains("angle_error_deg")) error += " (" + Format(p["angle_error_deg"], "%.3g") + " deg)";
      std::printf("%-22s %-34s %-34s %-28s %s\n", name.c_str(), FormatArray(p["truth"]).c_str(),
                  FormatArray(p["estimate"]).c_str(), error.c_str(), FormatArray(p["error_over_std"], "%.2f").c_str());
    }
  }
}

}  // namespace

int RunEvaluate(const EvaluateArgs& args) {
  eval::EvaluateOptions options;
  options.estimate_dir = args.estimate;
  options.recording_dir = args.recording;
  options.max_time_difference_s = args.max_time_difference_s;
  options.rpe_delta_s = args.rpe_delta_s;
  options.rpe_distance_m = args.rpe_distance_m;
  options.nees_t0_s = args.nees_t0_s;
  if (!args.align.empty()) {
    options.alignment = eval::ParseAlignmentKind(args.align);
    if (!options.alignment)
      return BadInput(args.err, "evaluate",
                      "--align: unknown alignment '" + args.align + "' (none, se3 or yaw_translation)");
  }
  if (const std::string problem = options.Validate(); !problem.empty()) return BadInput(args.err, "evaluate", problem);

  Result<eval::Evaluation> evaluation = eval::Evaluate(options);
  if (!evaluation.ok()) return BadInput(args.err, "evaluate", evaluation.status().message());
  Result<eval::WrittenEvaluation> written = eval::WriteEvaluation(evaluation.value(), args.out, !args.no_plots);
  if (!written.ok()) return Failure(args.err, "evaluate", written.status().message());

  if (!written.value().note.empty()) Report(args.err, "evaluate", written.value().note, 0);
  if (!args.quiet) {
    PrintSummary(evaluation.value().metrics);
    std::printf("wrote %s", written.value().metrics_path.c_str());
    for (const std::string& image : written.value().images) std::printf(", %s", image.c_str());
    std::printf("\n");
  }
  return 0;
}

}  // namespace roamlab::apps
