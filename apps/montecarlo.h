// `roamlab montecarlo`: consistency of online tracking over noise realizations (experiment/montecarlo.h).
#pragma once

#include <iosfwd>
#include <optional>

#include "apps/batch.h"
#include "experiment/montecarlo.h"

namespace roamlab::apps {

// The runner's options (without log and progress, which the command sets).
struct MonteCarloArgs : experiment::MonteCarloOptions {
  BackendArgs backend;
  // --redraw-terrain [--terrain-base N]: with --calibration-consistency, terrain_seed_base is set to N (default
  // experiment::kDefaultTerrainSeedBase); --terrain-base alone is bad input.
  bool redraw_terrain = false;
  std::optional<unsigned long long> terrain_base;
  bool quiet = false;           // no progress bar and no summary
  std::ostream* err = nullptr;  // receives the one-line error; nullptr: stderr
};

// Runs experiment::RunMonteCarlo and prints a progress bar and a one-line summary (local backend), or submits it to
// Slurm (batch/slurm.h). Exit code 0; 2 on bad input; 1 when a run fails.
int RunMonteCarlo(const MonteCarloArgs& args);

}  // namespace roamlab::apps
