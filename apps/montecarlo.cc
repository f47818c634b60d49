#include "apps/montecarlo.h"

#include <iostream>

#include "apps/cli.h"
#include "batch/slurm.h"
#include "batch/work.h"
#include "experiment/montecarlo.h"

namespace roamlab::apps {
namespace {

// The local backend: the runs on this host's threads, with a progress bar.
int RunLocally(const MonteCarloArgs& args, batch::Work& work) {
  experiment::MonteCarloOptions options = args;
  bool bar = false;
  if (!args.quiet) {
    options.log = [](const std::string& line) { std::cerr << "montecarlo: " << line << "\n"; };
    options.progress = [&bar](int finished, int runs) {
      const int width = 40, filled = width * finished / runs;
      std::cerr << "\rmontecarlo [" << std::string(filled, '#') << std::string(width - filled, ' ') << "] " << finished
                << "/" << runs << std::flush;
      bar = true;
    };
  }
  (void)batch::WriteLocalBatchFile(work, "running", "");
  experiment::MonteCarloSummary summary;
  const experiment::Outcome outcome = experiment::RunMonteCarlo(options, &summary);
  if (bar) std::cerr << "\n";
  const std::string headline = outcome.ok() ? batch::MonteCarloHeadline(args, summary) : outcome.status.message();
  if (!outcome.bad_input) (void)batch::WriteLocalBatchFile(work, outcome.ok() ? "done" : "failed", headline);
  if (!outcome.ok()) return Exit(args.err, "montecarlo", outcome);
  if (!args.quiet) std::cout << headline << "\n";
  return 0;
}

}  // namespace

int RunMonteCarlo(const MonteCarloArgs& args) {
  if (const std::string problem = args.Validate(); !problem.empty()) return BadInput(args.err, "montecarlo", problem);
  const std::unique_ptr<batch::Work> work = batch::MonteCarloWork(args);
  if (args.backend.backend == "slurm")
    return SubmitBatch(*work, args.backend, args.resume, args.quiet, args.err, "montecarlo");
  return RunLocally(args, *work);
}

}  // namespace roamlab::apps
