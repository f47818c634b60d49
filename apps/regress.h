// `roamlab regress SUITE.yaml --out DIR`: runs a regression suite (apps/regress_suite.h) and checks every metric
// against its bound. Each case runs in process in DIR/cases/NAME; the cases run in parallel. Writes DIR/results.json
// and DIR/junit.xml and prints a table. Returns 0 when every check passes, 1 when a check fails or a case errors, 2
// on bad input (a suite or baseline file, with one line naming the file, the case and the problem) before any case
// runs.
#pragma once

#include <string>

namespace roamlab::apps {

struct RegressArgs {
  std::string suite;
  std::string out;
  std::string baseline;          // baseline directory; "" = the suite's `baseline`
  bool update_baseline = false;  // write the values as the new baseline (one CASE.json per case that ran)
  int jobs = 0;                  // cases (and montecarlo runs) in parallel; 0 = one per core
  std::string filter;            // glob on case names (fnmatch); "" = all
  bool quick = false;            // only the cases marked `quick: true`
  bool quiet = false;            // no progress lines
};
int RunRegress(const RegressArgs& args);

}  // namespace roamlab::apps
