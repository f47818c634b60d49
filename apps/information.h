// `roamlab information SCENARIO.yaml --config EST.yaml --out DIR [--window S]`: the Cramer-Rao bound of every free
// calibration parameter for the scenario's drive and where its information comes from (experiment/information.h).
// Prints a table (per component: truth, CRB std, observability, share per stream, the windows that carry most) and
// the weak and unobservable directions. Exit codes as the other commands' (apps/cli.h).
#pragma once

#include <iosfwd>

#include "experiment/information.h"

namespace roamlab::apps {

struct InformationArgs : experiment::InformationRequest {
  bool quiet = false;           // no progress and no table
  std::ostream* err = nullptr;  // receives the one-line error; nullptr: stderr
};
int RunInformation(const InformationArgs& args);

}  // namespace roamlab::apps
