// `roamlab gap-benchmark --cases N --seed S --out DIR [--calibration-cases C] [--jobs J] [--other-drive F]
//  [--duration T] [--atv SCENARIO.yaml] [--diffdrive SCENARIO.yaml] [--mecanum SCENARIO.yaml] [--resume]
//  [--backend local|slurm ...] [--quiet]`: the blind benchmark of the reality-gap diagnosis
// (gap/benchmark/benchmark.h), on this host's threads or as Slurm job arrays (batch/slurm.h: the calibration cases,
// then the scored ones). Writes DIR/score.json, DIR/timings.json and each case's files under DIR/calibration/NNN and
// DIR/cases/NNN. Exit codes: 0 done, 2 bad options or scenarios, 1 a failure at run time.
#pragma once

#include <iosfwd>

#include "apps/batch.h"
#include "gap/benchmark/benchmark.h"

namespace roamlab::apps {

struct GapBenchmarkArgs : gap::benchmark::BenchmarkOptions {
  BackendArgs backend;
  bool quiet = false;
  std::ostream* err = nullptr;  // receives the one-line error; nullptr: stderr
};
int RunGapBenchmark(const GapBenchmarkArgs& args);

}  // namespace roamlab::apps
