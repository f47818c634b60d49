#include "apps/montecarlo.h"

#include <filesystem>
#include <iostream>

#include "apps/cli.h"
#include "apps/consistency.h"
#include "batch/slurm.h"
#include "batch/work.h"
#include "common/progress.h"
#include "experiment/montecarlo.h"

namespace roamlab::apps {
namespace {

// The local backend: the runs on this host's threads, with elapsed time and the time left.
int RunLocally(const MonteCarloArgs& args, batch::Work& work) {
  experiment::MonteCarloOptions options = args;
  ProgressMeter meter("montecarlo", &std::cerr);
  if (!args.quiet) {
    options.log = [&meter](const std::string& line) { meter.Note(line); };
    options.progress = [&meter](int finished, int runs) { meter.Update(finished, runs); };
  }
  (void)batch::WriteLocalBatchFile(work, "running", "");
  experiment::MonteCarloSummary summary;
  const experiment::Outcome outcome = experiment::RunMonteCarlo(options, &summary);
  meter.Finish();
  const std::string headline = outcome.ok() ? batch::MonteCarloHeadline(args, summary) : outcome.status.message();
  if (!outcome.bad_input) (void)batch::WriteLocalBatchFile(work, outcome.ok() ? "done" : "failed", headline);
  if (!outcome.ok()) return Exit(args.err, "montecarlo", outcome);
  if (!args.quiet) std::cout << headline << "\n";
  return 0;
}

}  // namespace

int RunMonteCarlo(const MonteCarloArgs& given) {
  if (given.terrain_base && !given.redraw_terrain)
    return BadInput(given.err, "montecarlo", "--terrain-base is for --redraw-terrain");
  if (given.redraw_terrain && !given.calibration_consistency)
    return BadInput(given.err, "montecarlo",
                    "--redraw-terrain is for --calibration-consistency (tracking runs keep the scenario's terrain)");
  if (given.calibration_consistency) return RunCalibrationConsistency(given);
  // An external command runs where roamlab was started, wherever the runs execute (a Slurm task's directory).
  MonteCarloArgs args = given;
  std::error_code ec;
  if (args.external() && args.command.working_dir.empty())
    args.command.working_dir = std::filesystem::current_path(ec).string();
  if (const std::string problem = args.Validate(); !problem.empty()) return BadInput(args.err, "montecarlo", problem);
  const std::unique_ptr<batch::Work> work = batch::MonteCarloWork(args);
  if (args.backend.backend == "slurm")
    return SubmitBatch(*work, args.backend, args.resume, args.quiet, args.err, "montecarlo");
  return RunLocally(args, *work);
}

}  // namespace roamlab::apps
