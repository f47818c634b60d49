// `roamlab init REC --out EST.yaml [--platform KIND]`: writes a nominal estimator configuration from what a recording
// states about its streams and platform (experiment/init.h), every key commented with where its value came from.
// Exit codes: 0 done, 2 bad input (one line naming the file and the problem), 1 when the file cannot be written.
#pragma once

#include <iosfwd>

#include "experiment/init.h"

namespace roamlab::apps {

struct InitArgs : experiment::InitRequest {
  bool quiet = false;           // no summary
  std::ostream* err = nullptr;  // receives the one-line error; nullptr: stderr
};
int RunInit(const InitArgs& args);

}  // namespace roamlab::apps
