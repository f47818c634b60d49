// `roamlab simulate SCENARIO.yaml --out REC [--seed N]`: runs a scenario in MuJoCo (sim/simulator.h) and writes the
// recording with its ground_truth.tum and truth.yaml. Returns the process exit code: 0 on success, 2 with one line
// "roamlab simulate: <file>:<line>: <key>: <problem>" on a bad scenario or model, 1 when the simulation fails (the
// vehicle leaves the terrain, MuJoCo diverges) or the recording cannot be written.
// `roamlab replay REC --scenario NOMINAL.yaml --out TWIN [--from S] [--to S]`: the recording's drive replayed in the
// scenario's model (sim/replay.h), written as the noise-free twin recording. Exit codes as simulate's; a recording
// without drive inputs or an empty window is bad input (2).
#pragma once

#include <iosfwd>

#include "experiment/steps.h"

namespace roamlab::apps {

// The step's request (without progress, which the command sets).
struct SimulateArgs : experiment::SimulateRequest {
  bool quiet = false;           // no progress and no summary
  std::ostream* err = nullptr;  // receives the one-line error; nullptr: stderr
};
int RunSimulate(const SimulateArgs& args);

struct ReplayArgs : experiment::ReplayRequest {
  bool quiet = false;           // no progress and no summary
  std::ostream* err = nullptr;  // receives the one-line error; nullptr: stderr
};
int RunReplay(const ReplayArgs& args);

}  // namespace roamlab::apps
