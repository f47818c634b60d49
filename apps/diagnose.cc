#include "apps/diagnose.h"

#include <iostream>
#include <sstream>

#include "apps/cli.h"
#include "common/progress.h"

namespace roamlab::apps {

int RunDiagnose(const DiagnoseArgs& args) {
  experiment::DiagnoseRequest request = args;
  ProgressMeter meter("diagnose", &std::cout);
  if (!args.quiet) request.progress = [&meter](const std::string& line) { meter.Note(line); };
  gap::Diagnosis d;
  gap::TwinDiagnosis twin;
  const experiment::Outcome outcome = experiment::DiagnoseToDirectory(request, &d, &twin);
  if (!outcome.ok()) return Exit(args.err, "diagnose", outcome);
  if (args.quiet) return 0;
  std::ostringstream summary;
  summary.precision(4);
  const auto effects = [&summary](const std::vector<gap::EffectEstimate>& estimates) {
    for (const gap::EffectEstimate& e : estimates) {
      summary << "; " << e.name;
      for (const auto& [k, v] : e.parameters) summary << " " << k << " = " << v;
    }
  };
  // With --twin the twin's verdict leads: its values are the accepted ones (scenario_patch.yaml).
  if (!twin.verdict.empty()) {
    std::vector<gap::EffectEstimate> kept;
    for (const gap::TwinEffect& e : twin.effects) kept.push_back(e.estimate);
    summary << "twin verdict: " << twin.verdict;
    effects(kept);
    summary << "; estimator-side ";
  }
  summary << "verdict: " << d.verdict;
  effects(d.effects);
  std::cout << summary.str() << " (" << args.out << "/report.html)" << std::endl;
  return 0;
}

}  // namespace roamlab::apps
