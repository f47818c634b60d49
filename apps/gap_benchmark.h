// `roamlab gap-benchmark --cases N --seed S --out DIR [--calibration-cases C] [--jobs J] [--other-drive F]
//  [--duration T] [--atv SCENARIO.yaml] [--diffdrive SCENARIO.yaml] [--mecanum SCENARIO.yaml] [--quiet]`: the blind
// benchmark of the reality-gap diagnosis (gap/benchmark/benchmark.h). Writes DIR/score.json and each case's files
// under DIR/calibration/NNN and DIR/cases/NNN. Exit codes: 0 done, 2 bad options or scenarios, 1 a failure at run time.
#pragma once

#include <iosfwd>

#include "gap/benchmark/benchmark.h"

namespace roamlab::apps {

struct GapBenchmarkArgs : gap::benchmark::BenchmarkOptions {
  bool quiet = false;
  std::ostream* err = nullptr;  // receives the one-line error; nullptr: stderr
};
int RunGapBenchmark(const GapBenchmarkArgs& args);

}  // namespace roamlab::apps
