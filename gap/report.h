// What `roamlab diagnose` writes about a diagnosis (gap/diagnose.h): DIR/gap.json (docs/commands.md, `roamlab
// diagnose`), DIR/report.md, DIR/report.html (the same, self-contained: verdict first, then the held-out fit before and
// after, the candidates, where, the re-simulation, and the figures embedded), DIR/scenario_patch.yaml (the accepted
// effects in a scenario's `effects:` form), DIR/estimator_patch.yaml (the same as estimator parameters and stream time
// shifts) and PNG figures with their gnuplot scripts.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "common/status.h"
#include "gap/diagnose.h"
#include "gap/resimulate.h"

namespace roamlab::gap {

// The diagnosis as gap.json; `baseline` null: diagnosed without one; `simulation` null: no re-simulation (a robot
// without a MuJoCo twin).
nlohmann::json DiagnosisJson(const Diagnosis& d, const Baseline* baseline, std::uint64_t baseline_seed,
                             const SimulationComparison* simulation);

// report.md: the verdict, where the recording departs from the model, the candidates, the held-out fit before and
// after, the re-simulation (when given) and the figures in `images`. `recording` and `model` name the inputs.
std::string ReportMarkdown(const Diagnosis& d, const std::string& recording, const std::string& model, bool baseline,
                           const SimulationComparison* simulation, const std::vector<std::string>& images);

// The accepted effects as the simulator takes them: as simulated when the scenario was simulated again (time shifts
// in whole physics steps), otherwise converted without the step.
std::string ScenarioPatch(const Diagnosis& d, const SimulationComparison* simulation);

// The accepted effects as estimator settings: parameter values and stream time shifts.
std::string EstimatorPatch(const Diagnosis& d);

struct ReportInputs {
  std::string recording;               // the recording's path, as given
  std::string model;                   // the nominal scenario's (or configuration's) path
  const Baseline* baseline = nullptr;  // null: diagnosed without one
  std::uint64_t baseline_seed = 0;
  const SimulationComparison* simulation = nullptr;  // null: no re-simulation
  const nlohmann::json* twin = nullptr;  // the diagnosis against the twin (twin.json), gap.json's "twin"; null: none
  bool plots = true;                     // write the figures (when gnuplot is installed)
  std::function<void(const std::string&)> progress;  // receives a note when no figure can be drawn
};

// Writes gap.json, scenario_patch.yaml, estimator_patch.yaml, the figures, report.md and report.html into `dir` (which
// exists).
// Errors: a file cannot be written.
Status WriteReport(const Diagnosis& d, const ReportInputs& in, const std::string& dir);

}  // namespace roamlab::gap
