// The Slurm backend of batch work (batch/work.h). One submission is one `sbatch` job array, task k running the runs
// [k * runs_per_task, (k + 1) * runs_per_task) that have no result file yet (`roamlab batch task OUT --index k`),
// and one aggregation job that depends on the array with afterany (`roamlab batch aggregate OUT`). The aggregation
// job submits the blocks whose runs are still missing again while retries remain (a task that failed, timed out or
// was cancelled); when runs that waited for earlier runs' results have become ready (Work::Ready: gap-benchmark's
// scored cases after its calibration cases), it submits them as the next array, with retries of their own; then it
// writes the summary files from the result files, the same bytes as the local backend; when runs are still missing
// after the retries it writes OUT/batch/failed.json instead ({"failed": [{"run", "name", "log"}]}) and no summary.
// OUT must be on a file system every node sees, and the roamlab executable at the same path. OUT/batch/ holds
// batch.json (the work, the options, each submission's job ids, blocks and the Ready() it was made under, "state":
// submitted | done | failed and its message), task.sh, aggregate.sh and logs/ (task-ARRAYJOB-TASK.log,
// aggregate-JOB.log).
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "batch/work.h"
#include "common/status.h"
#include "experiment/steps.h"

namespace roamlab::batch {

struct SlurmOptions {
  std::string partition;                 // sbatch --partition; "" the cluster's default
  std::string time;                      // sbatch --time of each task (Slurm's forms: MM, HH:MM:SS, D-HH); ""
  int array_parallelism = 0;             // at most this many tasks at once (--array=...%N); 0: no limit
  int runs_per_task = 1;                 // runs per array task
  int retries = 1;                       // submissions of the missing runs after the first
  std::vector<std::string> sbatch_args;  // further sbatch arguments, one word each ("--qos=long")
  bool wait = false;                     // return once the summary is written (or the batch failed)

  // What is wrong with the options, "" when nothing.
  std::string Validate() const;
};

// Prepares the work (montecarlo's shared calibration is computed here, once), removes earlier result files unless
// `resume`, writes OUT/batch/ and submits the runs without a result file. `log` receives the job ids. When every run
// already has its result file (resume), aggregates at once without submitting. With options.wait, returns the
// batch's end (its headline in `headline`); otherwise after the submission.
experiment::Outcome SubmitToSlurm(Work& work, const SlurmOptions& options, bool resume, std::ostream& log,
                                  std::string* headline);

// `roamlab batch task OUT --index K`: runs task K's runs that have no result file. Exit 0; 1 when a run failed.
int RunSlurmTask(const std::string& out, int index, std::ostream& err);

// `roamlab batch aggregate OUT`: submits the missing runs again while retries remain, else writes the summary (or
// failed.json). Exit 0 when done or resubmitted, 1 when failed.
int AggregateSlurm(const std::string& out, std::ostream& out_stream, std::ostream& err);

// What `roamlab batch status OUT` prints.
struct BatchStatus {
  std::string kind;
  std::string backend;  // local | slurm
  std::string state;    // submitted | done | failed (slurm); local: done when the summary is written
  std::string message;  // the headline or why the batch failed
  int runs = 0;
  int done = 0;                     // with a result file
  int queued = 0;                   // without one, in a task Slurm still lists (pending or running)
  std::vector<std::string> failed;  // without one and not queued: "run 3 (seed 1003): log PATH"
};
Result<BatchStatus> ReadBatchStatus(const std::string& out);

// OUT/batch/batch.json for a call of the local backend, so that `batch status` reads it: `state` running, done or
// failed, with its message.
Status WriteLocalBatchFile(const Work& work, const std::string& state, const std::string& message);

}  // namespace roamlab::batch
