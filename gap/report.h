// What `roamlab diagnose` writes about a diagnosis (gap/diagnose.h): DIR/gap.json (docs/commands.md, `roamlab
// diagnose`), DIR/report.md, DIR/report.html (the same, self-contained, the figures embedded), DIR/scenario_patch.yaml
// (the accepted effects in a scenario's `effects:` form; with a twin diagnosis, its patch), DIR/estimator_patch.yaml
// (the estimator-side diagnosis's effects as estimator parameters and stream time shifts) and PNG figures with their
// gnuplot scripts.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/status.h"
#include "gap/diagnose.h"
#include "gap/resimulate.h"
#include "gap/twin.h"
#include "recording/recording.h"

namespace roamlab::gap {

// The diagnosis as gap.json; `baseline` null: diagnosed without one; `simulation` null: no re-simulation (a robot
// without a MuJoCo twin); `real` (may be null) the recording, for the twins' held-out drift in "simulation".
nlohmann::json DiagnosisJson(const Diagnosis& d, const Baseline* baseline, std::uint64_t baseline_seed,
                             const SimulationComparison* simulation, const recording::Recording* real = nullptr);

// The accepted effects as the simulator takes them. With `twin` (not null) the twin diagnosis's patch (twin.json
// "patch": its values are the accepted ones, the estimator-side diagnosis only its first guess), std as its rounds
// report them; otherwise the diagnosis's effects, as simulated when the scenario was simulated again (time shifts in
// whole physics steps), else converted without the step.
std::string ScenarioPatch(const Diagnosis& d, const SimulationComparison* simulation,
                          const TwinDiagnosis* twin = nullptr);

// The estimator-side diagnosis's accepted effects as estimator settings: parameter values and stream time shifts.
std::string EstimatorPatch(const Diagnosis& d);

struct ReportInputs {
  std::string recording;               // the recording's path, as given
  std::string model;                   // the nominal scenario's (or configuration's) path
  const Baseline* baseline = nullptr;  // null: diagnosed without one
  std::uint64_t baseline_seed = 0;
  const SimulationComparison* simulation = nullptr;  // null: no re-simulation
  const recording::Recording* real = nullptr;        // the recording (the twins' drift and figures); null: none
  // The diagnosis against the twin, written to twin.json by the caller (gap.json's "simulation" names the file, the
  // report leads with its verdict and shows its held-out runs, scenario_patch.yaml is its patch); null: none.
  const TwinDiagnosis* twin = nullptr;
  bool plots = true;                                 // write the figures (when gnuplot is installed)
  std::function<void(const std::string&)> progress;  // receives a note when no figure can be drawn
};

// The figures drawn beside the report: the diagnosis's, the twin's, and why some were not drawn.
struct ReportFigures {
  std::vector<std::string> images, twin_images;
  std::vector<std::string> notes;
};

// report.md: the verdict, the held-out fit before and after, the candidates, where the recording departs from the
// model, the twin against the recording (when re-simulated: which twin and why, the held-out RMS and drift before and
// after) and the figures. With a twin diagnosis its verdict comes first, then the estimator side's, and its section
// (where the nominal twin departs, its candidates, its held-out part and runs) and the twin's come before the estimator
// side's.
std::string ReportMarkdown(const Diagnosis& d, const ReportInputs& in, const ReportFigures& figures);

// Writes gap.json, scenario_patch.yaml, estimator_patch.yaml, the figures, report.md and report.html into `dir` (which
// exists).
// Errors: a file cannot be written.
Status WriteReport(const Diagnosis& d, const ReportInputs& in, const std::string& dir);

}  // namespace roamlab::gap
