#include "regress/mode_specs.h"

namespace roamlab::regress {
namespace {

using nlohmann::json;

// What `roamlab evaluate` writes (eval/evaluate.cc, eval/parameters.cc).
json MetricsSchema() {
  const json stats = {{"rmse", "number"}, {"mean", "number"}, {"median", "number"}, {"max", "number"}};
  return {
      {"ate_m", "number"},
      {"rpe_trans_m", "number"},
      {"rpe_rot_deg", "number"},
      {"nees_mean", "number"},
      {"association",
       {{"estimate_poses", "number"},
        {"reference_poses", "number"},
        {"matched", "number"},
        {"tolerance_s", "number"},
        {"max_time_difference_s", "number"}}},
      {"alignment", {{"q_ref_est_wxyz", "numbers"}, {"p_ref_est_m", "numbers"}}},
      {"ate",
       {{"poses", "number"}, {"rmse_m", "number"}, {"mean_m", "number"}, {"median_m", "number"}, {"max_m", "number"}}},
      {"rpe",
       {{"delta_poses", "number"}, {"delta_s", "number"}, {"pairs", "number"}, {"trans_m", stats}, {"rot_deg", stats}}},
      {"rpe_distance", {{"distance_m", "number"}, {"pairs", "number"}, {"trans_m", stats}, {"rot_deg", stats}}},
      {"nees",
       {{"poses", "number"},
        {"without_covariance", "number"},
        {"not_positive_definite", "number"},
        {"dof", "number"},
        {"band_single_run", "numbers"},
        {"t0_s", "number"},
        {"fraction_in_band", "number"}}},
      {"velocity",
       {{"fused",
         {{"linear_rmse", "number"}, {"angular_rmse", "number"}, {"rpe_rot_deg", "number"}, {"intervals", "number"}}},
        {"encoders_only",
         {{"linear_rmse", "number"}, {"angular_rmse", "number"}, {"rpe_rot_deg", "number"}, {"intervals", "number"}}},
        {"rpe_delta_poses", "number"}}},
      {"parameters",
       {{"<parameter>",
         {{"truth", "numbers"},
          {"estimate", "numbers"},
          {"std", "numbers"},
          {"error", "numbers"},
          {"error_over_std", "numbers"},
          {"angle_error_deg", "number"},
          {"component_error", "numbers"},
          {"relative_error", "relative"}}}}}};
}

json CountsSchema() {
  return {{"<stream>",
           {{"attached", "number"},
            {"rejected", "number"},
            {"too_late", "number"},
            {"outside", "number"},
            {"duplicates", "number"},
            {"gaps", "number"},
            {"frozen", "number"}}}};
}

// What `roamlab calibrate` writes (estimator/calibration_io.h).
json CalibrationSchema() {
  return {{"parameters", {{"<parameter>", {{"estimate", "numbers"}, {"std", "numbers"}}}}},
          {"solver",
           {{"iterations", "number"},
            {"initial_cost", "number"},
            {"final_cost", "number"},
            {"seconds", "timing"},
            {"stages", json::array({{{"iterations", "number"},
                                     {"initial_cost", "number"},
                                     {"final_cost", "number"},
                                     {"rejected", "number"},
                                     {"readmitted", "number"},
                                     {"seconds", "timing"}}})}}},
          {"measurements", CountsSchema()}};
}

// What `roamlab track` writes to summary.json (estimator/tracking_io.h).
json SummarySchema() {
  return {{"poses", "number"},
          {"updates", "number"},
          {"mean_iterations", "number"},
          {"window", "number"},
          {"rejected_measurements", "number"},
          {"mean_update_s", "timing"},
          {"max_update_s", "timing"},
          {"p99_update_s", "timing"},
          {"seconds", "timing"},
          {"realtime_factor", "timing"},
          {"measurements", CountsSchema()}};
}

// What `roamlab montecarlo` writes (experiment/montecarlo.h, eval/nees.h).
json NeesSchema() {
  return {{"runs", "number"}, {"dof", "number"}, {"band", "numbers"},      {"alpha", "number"},
          {"t0_s", "number"}, {"t", "numbers"},  {"mean_nees", "numbers"}, {"fraction_in_band", "number"}};
}
json RunsSchema() {
  return {{"runs", json::array({{{"seed", "number"},
                                 {"ate_m", "number"},
                                 {"mean_nees", "number"},
                                 {"rpe_m", "number"},
                                 {"track_seconds", "timing"}}})}};
}

// What `roamlab odometry evaluate` writes (experiment/odometry.h).
json TableSchema() {
  return {{"rows", json::array({{{"model", "string"},
                                 {"mean", "string"},
                                 {"kernel", "string"},
                                 {"ate_m", "number"},
                                 {"rpe_mm", "number"},
                                 {"model_file", "string"}}})},
          {"recordings", json::array({{{"recording", "string"}, {"key_poses", "number"}}})},
          {"interval_s", "number"}};
}

// What `roamlab diagnose` writes to gap.json (apps/diagnose.h); effect parameters and stream names vary ("<any>").
json GapSchema() {
  const json effect = {{"name", "string"},
                       {"parameters", {{"<any>", "number"}}},
                       {"std", {{"<any>", "number"}}},
                       {"baseline_parameters", {{"<any>", "number"}}},
                       {"dof", "number"},
                       {"lr_statistic", "number"},
                       {"chi2_drop", "number"},
                       {"baseline_lr_statistic", "number"},
                       {"lr_pvalue", "number"},
                       {"delta_bic", "number"},
                       {"heldout_improvement", "number"},
                       {"decision", "string"}};
  const json fits = {
      {"<any>", {{"rms", "number"}, {"chi2_per_dof", "number"}, {"dof", "number"}, {"measurements", "number"}}}};
  const json component = {
      {"stream", "string"}, {"component", "number"}, {"chi2_per_dof", "number"}, {"expected_chi2_per_dof", "number"}};
  return {{"verdict", "string"},
          {"located", json::array({component})},
          {"effects", json::array({effect})},
          {"candidates", json::array({effect})},
          {"components", json::array({component})},
          {"fit", {{"before", fits}, {"after", fits}, {"heldout_start_s", "number"}, {"whole_run_nominal", fits}}},
          {"run", {{"fits", "number"}, {"seconds", "timing"}}}};
}
const std::vector<ModeSpec>& Modes() {
  static const std::vector<ModeSpec> modes = {
      {"calibrate",
       {"scenario", "recording", "seed", "config", "faults"},
       {"scenario|recording", "config"},
       {{"calibration", "calibration/calibration.json", CalibrationSchema()},
        {"metrics", "evaluation/metrics.json", MetricsSchema()}}},
      {"track",
       {"scenario", "recording", "seed", "config", "command", "timeout_s", "calibration", "calibrate", "t0_s",
        "faults"},
       {"scenario|recording", "config|command"},
       {{"summary", "tracking/summary.json", SummarySchema()},
        {"metrics", "evaluation/metrics.json", MetricsSchema()}}},
      {"montecarlo",
       {"scenario", "seed", "config", "command", "timeout_s", "calibration", "calibrate", "runs", "seed_base", "t0_s"},
       {"scenario", "config|command", "runs"},
       {{"nees", "montecarlo/nees.json", NeesSchema()}, {"runs", "montecarlo/runs.json", RunsSchema()}}},
      {"odometry",
       {"train", "test", "models", "interval_s", "seed"},
       {"train", "test", "models"},
       {{"table", "odometry/table.json", TableSchema()}}},
      {"diagnose",
       {"scenario", "recording", "seed", "effects", "config", "baseline_seed"},
       {"scenario"},
       {{"gap", "diagnosis/gap.json", GapSchema()}}},
  };
  return modes;
}

}  // namespace

const ModeSpec* FindMode(const std::string& name) {
  for (const ModeSpec& mode : Modes())
    if (mode.name == name) return &mode;
  return nullptr;
}

std::string ModeNames() {
  std::string names;
  for (const ModeSpec& mode : Modes()) names += (names.empty() ? "" : ", ") + mode.name;
  return names;
}

}  // namespace roamlab::regress
