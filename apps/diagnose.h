// `roamlab diagnose --real REC --scenario SCENARIO.yaml --out DIR`: the reality-gap diagnosis of a recording against
// the nominal scenario (experiment/diagnose.h). Exit codes: 0 done, 2 bad input (one line naming the file), 1 a
// failure at run time.
#pragma once

#include <iosfwd>

#include "experiment/diagnose.h"

namespace roamlab::apps {

// The step's request (without progress, which the command sets).
struct DiagnoseArgs : experiment::DiagnoseRequest {
  bool quiet = false;           // no progress and no summary
  std::ostream* err = nullptr;  // receives the one-line error; nullptr: stderr
};
int RunDiagnose(const DiagnoseArgs& args);

}  // namespace roamlab::apps
