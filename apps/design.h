// `roamlab design SCENARIO.yaml --config EST.yaml --out DESIGNED.yaml [--target NAME=STD ...]`: the drive of the
// scenario's robot, within its driver's family (experiment/drive_family.h: the Ackermann weave, the indoor robots'
// body-velocity sines), that minimizes the worst ratio of a parameter's Cramer-Rao std to its target, feasible in
// MuJoCo (experiment/design.h). Limits not given are the robot's (sim/drive_envelope.h). Writes the designed scenario
// and design.json beside it; prints the predicted std of every component. The targets are the configuration's
// target_std entries, each overridden by a --target of the same parameter. Exit codes as the other commands'
// (apps/cli.h).
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "experiment/design.h"

namespace roamlab::apps {

struct DesignArgs : experiment::DesignRequest {
  std::vector<std::string> target_texts;  // "NAME=STD", parsed into `targets`
  std::vector<double> speed_range_mps;    // {min, max} when given
  std::vector<double> period_range_s;     // {min, max} when given
  bool quiet = false;                     // no progress and no table
  std::ostream* err = nullptr;            // receives the one-line error; nullptr: stderr
};
int RunDesign(const DesignArgs& args);

}  // namespace roamlab::apps
