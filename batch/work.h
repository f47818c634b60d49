// Batch work: runs 0..runs-1, each writing its own result file into the output directory (written under a temporary
// name, then renamed), and a summary aggregated from those files alone. Runs are independent of each other, but for
// runs that need earlier runs' results (Ready). Whoever
// runs a run (a thread here, a Slurm task on another host) writes the same file, because every run's seed derives
// from its index; so the summary's bytes do not depend on the backend. A Work is what a Slurm task rebuilds from
// OUT/batch/batch.json (ToJson, WorkFromJson) to run its block of runs.
#pragma once

#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "common/status.h"
#include "experiment/montecarlo.h"
#include "experiment/steps.h"
#include "experiment/sweep.h"
#include "gap/benchmark/benchmark.h"

namespace roamlab::batch {

class Work {
 public:
  virtual ~Work() = default;
  virtual std::string kind() const = 0;  // the command: "montecarlo", "sweep", "gap-benchmark"
  virtual int runs() const = 0;
  // Runs [0, Ready()) can run now; the later ones need their results first (gap-benchmark's scored cases need the
  // thresholds chosen on its calibration cases). Read from the result files: it grows once those runs are done, and
  // is runs() once every earlier run is.
  virtual int Ready() const { return runs(); }
  virtual const std::string& out() const = 0;
  // Everything WorkFromJson needs to make the same work again: {"kind": kind(), ...}.
  virtual nlohmann::json ToJson() const = 0;
  // Reads what every run shares and computes what is computed once (montecarlo's shared calibration); with `resume`,
  // reuses what an earlier call computed.
  virtual experiment::Outcome Prepare(bool resume) = 0;
  // What a Slurm task running runs [first, last) needs of Prepare(true) (by default all of it).
  virtual experiment::Outcome PrepareRuns(int first, int last) {
    (void)first;
    (void)last;
    return Prepare(true);
  }
  // Whether run i's result file exists.
  virtual bool Done(int i) const = 0;
  // Runs run i and writes its result file (after Prepare).
  virtual experiment::Outcome Run(int i) = 0;
  // Writes the summary files from the result files; `headline` receives the one-line result.
  virtual experiment::Outcome Aggregate(std::string* headline) = 0;
  // Names run i for messages: "run 3 (seed 1003)".
  virtual std::string RunName(int i) const = 0;
  // Removes every run's result file (a new call that does not resume starts from none).
  virtual Status Clear() = 0;
};

// The line `roamlab montecarlo` prints: the in-band fraction and the file written.
std::string MonteCarloHeadline(const experiment::MonteCarloOptions& options,
                               const experiment::MonteCarloSummary& summary);

// The Monte-Carlo of experiment/montecarlo.h as batch work (log, progress and jobs are not used).
std::unique_ptr<Work> MonteCarloWork(experiment::MonteCarloOptions options);

// A sweep (experiment/sweep.h) as batch work: run r is run r % seeds of point r / seeds. The points' files must have
// been written (experiment::WriteSweepPoints) before Prepare.
std::unique_ptr<Work> SweepWork(experiment::SweepPlan plan);

// The gap benchmark (gap/benchmark/benchmark.h) as batch work: run k is case k of the benchmark (the calibration
// cases, then the scored ones, which are ready once every calibration case is done). A task learns the baselines of
// the platforms its cases are drawn on. Aggregate writes score.json (the local backend's bytes) and timings.json.
std::unique_ptr<Work> GapBenchmarkWork(gap::benchmark::BenchmarkOptions options);

// The work ToJson described; an error names what is missing.
Result<std::unique_ptr<Work>> WorkFromJson(const nlohmann::json& json);

}  // namespace roamlab::batch
