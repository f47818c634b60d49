// The twin's part of what `roamlab diagnose` writes (gap/report.h): the re-simulation's twins (gap/resimulate.h)
// against the recording on its held-out part, as tables, gap.json entries and figures.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/html.h"
#include "gap/locate.h"
#include "gap/resimulate.h"
#include "gap/twin.h"
#include "recording/recording.h"

namespace roamlab::gap::internal {

// The drift over 10 s windows (gap/twin.h CompareTwin, DriftOptions' defaults) of the twin as believed and of the twin
// with the effects against `real`, from c.from_s to real's last stamp; `after` empty when the patched twin failed.
struct HeldOutDrift {
  std::map<std::string, TwinDrift> before, after;
};
HeldOutDrift TwinHeldOutDrift(const SimulationComparison& c, const recording::Recording& real);

// {"stream": {"before": TwinDriftJson's entry, "after": ... or null}}.
nlohmann::json HeldOutDriftJson(const HeldOutDrift& drift);

// The twin's drive in a sentence: replayed or the scenario's own drive, and why.
std::string TwinChoiceText(const TwinChoice& twin);

// Per absolute stream: the mean and largest position drift, and the mean heading drift when measured, before and after.
html::Table DriftTable(const HeldOutDrift& drift);

// The twin diagnosis (gap/twin.h): its verdict and kept effects with their stds, in lines.
std::vector<std::string> TwinVerdictLines(const TwinDiagnosis& d);
// Its candidates, round by round: each one's values with their std, LR, p, Delta BIC, held-out chi-square drop and
// decision.
html::Table TwinCandidatesTable(const TwinDiagnosis& d);
// Its held-out part: per stream, the whitened RMS (a replayed twin's over its windows, as fitted) with the nominal
// twin and with the patch.
html::Table TwinHeldOutTable(const TwinDiagnosis& d);
// Its held-out runs: per run and absolute stream, the drift and the chi-square before and after the patch.
html::Table HeldOutRunsTable(const TwinDiagnosis& d);

// Figures in `dir` (gnuplot; the caller checks that it is installed), the images drawn:
//   twin_top_view.png: the top view of the recording's first absolute stream (a pose stream, else gps, else a
//     position stream) and of the twin's as believed and with the effects, at its stamps on the held-out part;
//   twin_residual_vs_condition.png: the held-out component the twin as believed misses most (whitened RMS) against
//     the motion condition it correlates with most (gap/locate.h, `conditions`), before and after the effects.
// A figure without data (no absolute stream, no condition) is not drawn; `notes` gets why.
std::vector<std::string> WriteTwinFigures(const SimulationComparison& c, const recording::Recording& real,
                                          const Conditions& conditions, const std::string& dir,
                                          std::vector<std::string>* notes);

}  // namespace roamlab::gap::internal
