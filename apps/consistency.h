// `roamlab montecarlo --calibration-consistency`: the calibration's reported std against its errors over noise
// realizations (experiment/consistency.h).
#pragma once

#include "apps/montecarlo.h"

namespace roamlab::apps {

// Runs experiment::RunCalibrationConsistency on the local backend with a progress bar, then prints the table and a
// one-line summary; with --redraw-terrain also the failed runs, one line each. Exit code 0; 2 on bad input (also
// --backend slurm, --calibration or --calibrate-each-run with it, a flat terrain to redraw); 1 when a run fails (with
// the terrain redrawn: when every run fails).
int RunCalibrationConsistency(const MonteCarloArgs& args);

}  // namespace roamlab::apps
