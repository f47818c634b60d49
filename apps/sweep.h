// `roamlab sweep SWEEP.yaml --out DIR [--jobs N] [--resume] [--backend local|slurm ...] [--quiet]`: Monte-Carlo points
// over scenario and estimator keys (experiment/sweep.h). Exit codes: 0 done (or submitted), 2 bad input, 1 a failure.
#pragma once

#include <iosfwd>
#include <string>

#include "apps/batch.h"

namespace roamlab::apps {

struct SweepArgs {
  std::string sweep;  // SWEEP.yaml
  std::string out;
  int jobs = 0;  // local backend: parallel runs of a point; 0 one per core
  bool resume = false;
  BackendArgs backend;
  bool quiet = false;
  std::ostream* err = nullptr;  // nullptr: stderr
};
int RunSweep(const SweepArgs& args);

}  // namespace roamlab::apps
