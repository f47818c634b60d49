// report.html: one self-contained page (common/html.h) per `roamlab evaluate` output, readable in two minutes. In
// order:
//   headline     ATE (position, rotation), RPE, NEES mean and in-band fraction, and how many calibration parameters
//                lie within 3 std of their true value
//   tables       what was compared (reference, association, alignment); ATE statistics (position, rotation), per axis
//                and horizontal/vertical; RPE by step and by distance; NEES with its band; the calibration parameters
//                (truth, estimate, std, error, error/std, observability) when the estimate is a calibration
//   figures      the PNGs of eval/plots.h embedded as data: URIs (trajectory, position error per axis with 3 sigma,
//                NEES with its band, velocities), or a note when gnuplot was missing
// A comparison of several estimates puts the comparison table and overlaid figures first, then each estimate's
// sections.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/html.h"
#include "common/status.h"

namespace roamlab::eval {

// One estimate's metrics (the content of its metrics.json) and its drawn figures (PNG paths).
struct ReportedEvaluation {
  std::string name;  // the estimate's name, e.g. "tracking"
  nlohmann::json metrics;
  std::vector<std::string> images;
};

// One line of headline numbers from metrics.json.
std::string HeadlineOf(const nlohmann::json& metrics);

// The tables of one evaluation under headings of `level` (html::Page::Heading).
void AddEvaluationTables(const nlohmann::json& metrics, int level, html::Page* page);

// Embeds each PNG with a caption named after its file; `note` (gnuplot missing) as a note when there is no image.
// Errors: an image cannot be read.
Status AddFigures(const std::vector<std::string>& images, const std::string& note, int level, html::Page* page);

// Writes PATH (report.html) for one evaluation.
Status WriteEvaluationReport(const ReportedEvaluation& evaluation, const std::string& note, const std::string& path);

// Writes PATH for several estimates against one reference: `comparison_images` are the overlaid figures.
Status WriteComparisonReport(const std::vector<ReportedEvaluation>& evaluations,
                             const std::vector<std::string>& comparison_images, const std::string& note,
                             const std::string& path);

}  // namespace roamlab::eval
