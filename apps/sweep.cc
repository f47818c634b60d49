#include "apps/sweep.h"

#include <iostream>

#include "apps/cli.h"
#include "batch/slurm.h"
#include "batch/work.h"
#include "common/progress.h"
#include "experiment/sweep.h"

namespace roamlab::apps {

int RunSweep(const SweepArgs& args) {
  if (args.jobs < 0) return BadInput(args.err, "sweep", "--jobs must be >= 0");
  auto plan = experiment::ReadSweep(args.sweep, args.out);
  if (!plan.ok()) return BadInput(args.err, "sweep", plan.status().message());
  const std::unique_ptr<batch::Work> work = batch::SweepWork(plan.value());
  if (args.backend.backend == "slurm") {
    if (Status written = experiment::WriteSweepPoints(plan.value()); !written.ok())
      return BadInput(args.err, "sweep", written.message());
    return SubmitBatch(*work, args.backend, args.resume, args.quiet, args.err, "sweep");
  }
  if (Status made = experiment::MakeOutputDirectory(args.out); !made.ok())
    return BadInput(args.err, "sweep", made.message());
  (void)batch::WriteLocalBatchFile(*work, "running", "");
  ProgressMeter meter("sweep", &std::cerr);
  std::function<void(const std::string&)> log;
  std::function<void(int, int)> progress;
  if (!args.quiet) {
    log = [&meter](const std::string& line) { meter.Note(line); };
    progress = [&meter](int finished, int runs) { meter.Update(finished, runs); };
  }
  std::string headline;
  const experiment::Outcome outcome =
      experiment::RunSweep(plan.value(), args.resume, args.jobs, log, progress, &headline);
  meter.Finish();
  if (!outcome.bad_input)
    (void)batch::WriteLocalBatchFile(*work, outcome.ok() ? "done" : "failed",
                                     outcome.ok() ? headline : outcome.status.message());
  if (!outcome.ok()) return Exit(args.err, "sweep", outcome);
  if (!args.quiet) std::cout << headline << "\n";
  return 0;
}

}  // namespace roamlab::apps
