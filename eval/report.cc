#include "eval/report.h"

#include <cmath>
#include <cstdio>
#include <filesystem>

namespace roamlab::eval {
namespace {

using nlohmann::json;

// j[key], or null when j is not an object or has no such key.
const json& At(const json& j, const std::string& key) {
  static const json kNull;
  if (!j.is_object()) return kNull;
  const auto it = j.find(key);
  return it == j.end() ? kNull : *it;
}

// A number, "-" when absent or null.
std::string Number(const json& node, const char* format = "%.4g") {
  if (!node.is_number()) return "-";
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, node.get<double>());
  return buffer;
}

std::string Numbers(const json& array, const char* format = "%.4g") {
  if (!array.is_array()) return "-";
  std::string out;
  for (const json& v : array) out += (out.empty() ? "" : ", ") + Number(v, format);
  return "[" + out + "]";
}

std::string Text(const json& node) { return node.is_string() ? node.get<std::string>() : "-"; }

// The cells rmse, mean, median, std, min, max of a statistics object whose keys end in `suffix`.
std::vector<std::string> StatisticsCells(const json& s, const std::string& suffix) {
  std::vector<std::string> cells;
  for (const char* key : {"rmse", "mean", "median", "std", "min", "max"}) cells.push_back(Number(At(s, key + suffix)));
  return cells;
}

// Parameters whose every finite |error/std| is at most 3, and those with an error/std at all.
std::pair<int, int> ParametersWithin3Sigma(const json& parameters) {
  int within = 0, judged = 0;
  if (!parameters.is_object()) return {0, 0};
  for (const auto& [name, p] : parameters.items()) {
    bool any = false, ok = true;
    for (const json& r : At(p, "error_over_std")) {
      if (!r.is_number()) continue;
      any = true;
      ok = ok && std::abs(r.get<double>()) <= 3.0;
    }
    judged += any;
    within += any && ok;
  }
  return {within, judged};
}

void AddComparedTable(const json& m, int level, html::Page* page) {
  page->Heading(level, "What was compared");
  const json& a = At(m, "association");
  page->AddTable(
      {{"item", "value"},
       {{"reference", Text(At(At(m, "reference"), "path")) + " (" + Text(At(At(m, "reference"), "kind")) + ")"},
        {"association", "by " + Text(At(a, "by")) + ": " + Number(At(a, "matched"), "%.0f") + " of " +
                            Number(At(a, "estimate_poses"), "%.0f") + " estimate poses matched (tolerance " +
                            Number(At(a, "tolerance_s")) + " s, offset " + Number(At(a, "time_offset_s")) + " s)"},
        {"alignment", Text(At(At(m, "alignment"), "kind"))}}});
}

void AddAccuracyTables(const json& m, int level, html::Page* page) {
  page->Heading(level, "Absolute trajectory error (ATE)");
  html::Table ate{{"error", "rmse", "mean", "median", "std", "min", "max"}, {}};
  ate.rows.push_back(StatisticsCells(At(m, "ate"), "_m"));
  ate.rows.back().insert(ate.rows.back().begin(), "position [m]");
  if (At(m, "ate_rotation").is_object()) {
    ate.rows.push_back(StatisticsCells(At(m, "ate_rotation"), "_deg"));
    ate.rows.back().insert(ate.rows.back().begin(), "rotation [deg]");
  }
  page->AddTable(ate);
  html::Table axes{{"position error [m]", "rmse", "mean", "median", "std", "min", "max"}, {}};
  for (const char* axis : {"x", "y", "z", "horizontal", "vertical"}) {
    axes.rows.push_back(StatisticsCells(At(At(m, "ate_axes"), axis), "_m"));
    axes.rows.back().insert(axes.rows.back().begin(), axis);
  }
  page->AddTable(axes);

  page->Heading(level, "Relative pose error (RPE)");
  const json& step = At(m, "rpe");
  if (At(step, "skipped").is_string()) {
    page->Paragraph("RPE skipped: " + Text(At(step, "skipped")), "note");
    return;
  }
  html::Table rpe{
      {"pairs", "count", "translation rmse [m]", "translation max [m]", "rotation rmse [deg]", "rotation max [deg]"},
      {}};
  const json& distance = At(m, "rpe_distance");
  const auto row = [](const std::string& what, const json& r) {
    return std::vector<std::string>{what,
                                    Number(At(r, "pairs"), "%.0f"),
                                    Number(At(At(r, "trans_m"), "rmse")),
                                    Number(At(At(r, "trans_m"), "max")),
                                    Number(At(At(r, "rot_deg"), "rmse")),
                                    Number(At(At(r, "rot_deg"), "max"))};
  };
  rpe.rows.push_back(
      row(Number(At(step, "delta_poses"), "%.0f") + " poses apart (" + Number(At(step, "delta_s")) + " s)", step));
  rpe.rows.push_back(row(Number(At(distance, "distance_m")) + " m along the reference", distance));
  page->AddTable(rpe);
}

void AddNeesTable(const json& m, int level, html::Page* page) {
  const json& nees = At(m, "nees");
  if (!nees.is_object()) return;
  page->Heading(level, "Consistency: position NEES (3 dof, 3 when consistent)");
  if (nees.contains("warning")) page->Paragraph("Warning: " + Text(At(nees, "warning")), "note");
  page->AddTable(
      {{"mean", "poses", "in the 95 % band", "band (single run)", "without covariance", "left out before t0 [s]"},
       {{Number(At(m, "nees_mean")), Number(At(nees, "poses"), "%.0f"), Number(At(nees, "fraction_in_band"), "%.3f"),
         Numbers(At(nees, "band_single_run"), "%.3f"), Number(At(nees, "without_covariance"), "%.0f"),
         Number(At(nees, "t0_s"))}}});
}

void AddParameterTable(const json& m, int level, html::Page* page) {
  const json& parameters = At(m, "parameters");
  if (!parameters.is_object() || parameters.empty()) return;
  page->Heading(level, "Calibration parameters against the truth");
  html::Table table{{"parameter", "manifold", "truth", "estimate", "std", "error", "error / std", "observability"}, {}};
  for (const auto& [name, p] : parameters.items()) {
    std::string error = Numbers(At(p, "error"), "%.3g");
    if (At(p, "angle_error_deg").is_number()) error += " (" + Number(At(p, "angle_error_deg"), "%.3g") + " deg)";
    table.rows.push_back({name, Text(At(p, "manifold")), Numbers(At(p, "truth")), Numbers(At(p, "estimate")),
                          Numbers(At(p, "std"), "%.3g"), error, Numbers(At(p, "error_over_std"), "%.2f"),
                          Text(At(p, "observability"))});
  }
  page->AddTable(table);
  page->Paragraph(
      "Errors of rotations are the tangent vector Log(q_true^-1 q_est) [rad], comparable with their std; "
      "|error / std| well above 3 says the reported uncertainty is too small for the actual error.");
  const json& without = At(m, "parameters_without_truth");
  if (without.is_array() && !without.empty()) page->Paragraph("Estimated without a true value: " + without.dump());
}

// The caption of a figure, from its file name.
std::string Caption(const std::string& image) {
  const std::string stem = std::filesystem::path(image).stem().string();
  if (stem == "trajectory") return "Trajectory, top view: reference, estimate(s) and absolute fixes";
  if (stem == "position_error") return "Position error per axis (E, N, U) with the +-3 sigma envelope";
  if (stem == "nees") return "Position NEES per pose with the 95 % chi-square band";
  if (stem == "velocity") return "Velocities: truth, encoders' forward kinematics, fused estimate";
  if (stem == "ate_over_time") return "Absolute error of every estimate against time";
  return stem;
}

}  // namespace

std::string HeadlineOf(const json& m) {
  std::string out = "ATE " + Number(At(m, "ate_m")) + " m";
  if (At(m, "ate_rot_deg").is_number()) out += ", " + Number(At(m, "ate_rot_deg")) + " deg";
  if (At(m, "rpe_trans_m").is_number())
    out += "; RPE " + Number(At(m, "rpe_trans_m")) + " m, " + Number(At(m, "rpe_rot_deg")) + " deg";
  if (At(m, "nees").is_object())
    out += "; NEES mean " + Number(At(m, "nees_mean")) + " (3 when consistent), " +
           Number(At(At(m, "nees"), "fraction_in_band"), "%.3f") + " of the poses in the 95 % band";
  const auto [within, judged] = ParametersWithin3Sigma(At(m, "parameters"));
  if (judged > 0)
    out += "; " + std::to_string(within) + " of " + std::to_string(judged) + " parameters within 3 std of the truth";
  return out;
}

void AddEvaluationTables(const json& metrics, int level, html::Page* page) {
  AddComparedTable(metrics, level, page);
  AddParameterTable(metrics, level, page);
  AddAccuracyTables(metrics, level, page);
  AddNeesTable(metrics, level, page);
}

Status AddFigures(const std::vector<std::string>& images, const std::string& note, int level, html::Page* page) {
  page->Heading(level, "Figures");
  if (images.empty()) page->Paragraph(note.empty() ? "No figures were drawn." : note, "note");
  for (const std::string& image : images)
    if (Status s = page->AddImage(image, Caption(image)); !s.ok()) return s;
  return Status::Ok();
}

Status WriteEvaluationReport(const ReportedEvaluation& evaluation, const std::string& note, const std::string& path) {
  html::Page page("Evaluation of " + evaluation.name);
  page.Paragraph(HeadlineOf(evaluation.metrics), "headline");
  AddEvaluationTables(evaluation.metrics, 2, &page);
  if (Status s = AddFigures(evaluation.images, note, 2, &page); !s.ok()) return s;
  return page.Write(path);
}

Status WriteComparisonReport(const std::vector<ReportedEvaluation>& evaluations,
                             const std::vector<std::string>& comparison_images, const std::string& note,
                             const std::string& path) {
  html::Page page("Evaluation of " + std::to_string(evaluations.size()) + " estimates");
  for (const ReportedEvaluation& e : evaluations) page.Paragraph(e.name + ": " + HeadlineOf(e.metrics), "headline");
  html::Table table{{"estimate", "matched", "ATE [m]", "ATE [deg]", "RPE [m]", "RPE [deg]", "NEES mean", "alignment"},
                    {}};
  for (const ReportedEvaluation& e : evaluations) {
    const json& m = e.metrics;
    table.rows.push_back({e.name, Number(At(At(m, "association"), "matched"), "%.0f"), Number(At(m, "ate_m")),
                          Number(At(m, "ate_rot_deg")), Number(At(m, "rpe_trans_m")), Number(At(m, "rpe_rot_deg")),
                          Number(At(m, "nees_mean")), Text(At(At(m, "alignment"), "kind"))});
  }
  page.Heading(2, "Comparison");
  page.AddTable(table);
  if (Status s = AddFigures(comparison_images, note, 3, &page); !s.ok()) return s;
  for (const ReportedEvaluation& e : evaluations) {
    page.Heading(2, "Estimate " + e.name);
    page.Paragraph(HeadlineOf(e.metrics), "headline");
    AddEvaluationTables(e.metrics, 3, &page);
    if (Status s = AddFigures(e.images, note, 3, &page); !s.ok()) return s;
  }
  return page.Write(path);
}

}  // namespace roamlab::eval
