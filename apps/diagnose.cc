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
  const experiment::Outcome outcome = experiment::DiagnoseToDirectory(request, &d);
  if (!outcome.ok()) return Exit(args.err, "diagnose", outcome);
  if (args.quiet) return 0;
  std::ostringstream summary;
  summary.precision(4);
  summary << "verdict: " << d.verdict;
  for (const gap::EffectEstimate& e : d.effects) {
    summary << "; " << e.name;
    for (const auto& [k, v] : e.parameters) summary << " " << k << " = " << v;
  }
  std::cout << summary.str() << " (" << args.out << "/report.html)" << std::endl;
  return 0;
}

}  // namespace roamlab::apps
