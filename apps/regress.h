// `roamlab regress SUITE.yaml --out DIR`: runs a regression suite (regress/suite.h) and checks every metric
// against its bound. Each case runs in process in DIR/cases/NAME; the cases run in parallel. Writes DIR/results.json,
// DIR/junit.xml, DIR/timings.json and DIR/report.html and prints a table. Returns 0 when every check passes, 1 when a
// check fails or a case errors, 2 on bad input (a suite or baseline file, with one line naming the file, the case and
// the problem) before any case runs; after SIGINT or SIGTERM the process exits with 130 or 143 (regress/regress.h:
// the marker, --resume).
#pragma once

#include "regress/regress.h"

namespace roamlab::apps {

// The run's options (without progress, which the command sets).
struct RegressArgs : regress::RunOptions {
  bool quiet = false;  // no progress lines
};
int RunRegress(const RegressArgs& args);

}  // namespace roamlab::apps
