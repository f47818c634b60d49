#include "apps/montecarlo.h"

#include <cstdio>
#include <iostream>

#include "apps/cli.h"
#include "experiment/montecarlo.h"

namespace roamlab::apps {

int RunMonteCarlo(const MonteCarloArgs& args) {
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
  experiment::MonteCarloSummary summary;
  const experiment::Outcome outcome = experiment::RunMonteCarlo(options, &summary);
  if (bar) std::cerr << "\n";
  if (!outcome.ok()) return Exit(args.err, "montecarlo", outcome);
  if (args.quiet) return 0;
  const eval::MonteCarloNees& nees = summary.nees;
  std::printf(
      "%d runs: mean NEES in the 95%% band [%.3f, %.3f] for %.1f%% of the time steps after %.1f s; wrote %s%s\n",
      args.runs, nees.band.lo, nees.band.hi, 100.0 * nees.fraction_in_band, args.t0_s,
      (args.out + "/nees.json").c_str(), summary.plot_note.c_str());
  return 0;
}

}  // namespace roamlab::apps
