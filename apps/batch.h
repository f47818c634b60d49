// The backends of `roamlab montecarlo` and `roamlab sweep` (--backend local|slurm and the Slurm options), and
// `roamlab batch status|task|aggregate OUT` (batch/slurm.h): what a batch has done, and the two commands its Slurm
// jobs run.
#pragma once

#include <iosfwd>
#include <string>

#include "batch/slurm.h"
#include "batch/work.h"

namespace roamlab::apps {

struct BackendArgs {
  std::string backend = "local";  // local | slurm
  batch::SlurmOptions slurm;
};

// Runs `work` on the Slurm backend: submits it and prints the job ids on stderr; with --wait, prints its headline
// unless `quiet`. The exit code.
int SubmitBatch(batch::Work& work, const BackendArgs& backend, bool resume, bool quiet, std::ostream* err,
                const std::string& command);

struct BatchArgs {
  std::string out;
  int index = -1;               // batch task: the array task index
  std::ostream* err = nullptr;  // nullptr: stderr
};
// `roamlab batch status OUT`: runs done, queued and failed (with their logs), and the batch's state. Exit 0; 2 when
// OUT holds no batch; 1 when runs failed.
int RunBatchStatus(const BatchArgs& args);
// `roamlab batch task OUT --index K` (what a Slurm array task runs).
int RunBatchTask(const BatchArgs& args);
// `roamlab batch aggregate OUT` (what the Slurm aggregation job runs).
int RunBatchAggregate(const BatchArgs& args);

}  // namespace roamlab::apps
