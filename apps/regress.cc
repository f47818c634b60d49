#include "apps/regress.h"

#include <cstdio>

#include "apps/cli.h"
#include "common/interrupt.h"
#include "regress/regress.h"

namespace roamlab::apps {

int RunRegress(const RegressArgs& args) {
  regress::RunOptions options = args;
  if (!args.quiet) options.progress = [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); };
  regress::SuiteResult result;
  regress::RunReports reports;
  const experiment::Outcome outcome = regress::RunSuite(options, &result, &reports);
  // Bad input stops before any case; an interrupted run has not applied its bounds: no table for either.
  if (!outcome.ok() && (outcome.bad_input || InterruptRequested())) return Exit(nullptr, "regress", outcome);
  std::fputs(regress::ResultsTable(result).c_str(), stdout);
  if (!outcome.ok()) return Exit(nullptr, "regress", outcome);
  if (args.update_baseline) std::printf("baseline written to %s\n", reports.baseline_dir.c_str());
  std::printf("wrote %s, %s, %s\n", reports.results_json.c_str(), reports.junit_xml.c_str(),
              reports.report_html.c_str());
  return result.Passed() ? 0 : 1;
}

}  // namespace roamlab::apps
