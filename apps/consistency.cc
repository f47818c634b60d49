#include "apps/consistency.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "apps/cli.h"
#include "common/progress.h"
#include "experiment/consistency.h"
#include "experiment/terrain_redraw.h"

namespace roamlab::apps {
namespace {

// What the options combine with --calibration-consistency that it does not support, "" when nothing.
std::string Unsupported(const MonteCarloArgs& args) {
  if (args.backend.backend != "local") return "--calibration-consistency runs on the local backend only";
  if (!args.calibration.empty()) return "--calibration-consistency calibrates every run: no --calibration";
  if (args.calibrate_each_run) return "--calibration-consistency calibrates every run: no --calibrate-each-run";
  return "";
}

// The failed runs, one line each (run, terrain seed, reason); "" when none.
std::string FailedRunsTable(const std::vector<experiment::FailedRun>& failed) {
  if (failed.empty()) return "";
  std::string s = "failed runs (not in the statistics): " + std::to_string(failed.size()) + "\n";
  for (const experiment::FailedRun& f : failed)
    s += "  run " + std::to_string(f.run) + " (noise seed " + std::to_string(f.seed) + ", terrain seed " +
         std::to_string(f.terrain_seed) + "): " + f.reason + "\n";
  return s;
}

// The summary line: how many components and blocks pass each test, and the file written.
std::string Headline(const MonteCarloArgs& args, const experiment::ConsistencySummary& summary) {
  int components = 0, covered = 0, efficient = 0, in_band = 0;
  for (const eval::BlockConsistency& b : summary.blocks) {
    in_band += b.nees_in_band() ? 1 : 0;
    for (const eval::ComponentConsistency& c : b.components) {
      ++components;
      covered += c.coverage[1].consistent() ? 1 : 0;
      efficient += std::abs(c.efficiency - 1.0) <= 0.2 ? 1 : 0;
    }
  }
  const int failed = static_cast<int>(summary.failed_runs.size());
  char line[320];
  std::snprintf(line, sizeof line,
                "%d runs (%d calibrated, %d failed): 2-sigma coverage consistent with 95.4 %% for %d of %d "
                "components, mean std within 20 %% of the Cramer-Rao std for %d, block NEES in band for %d of %zu "
                "parameters; wrote ",
                args.runs, args.runs - failed, failed, covered, components, efficient, in_band, summary.blocks.size());
  return line + args.out + "/consistency.json" + summary.plot_note;
}

}  // namespace

int RunCalibrationConsistency(const MonteCarloArgs& args) {
  if (const std::string problem = Unsupported(args); !problem.empty())
    return BadInput(args.err, "montecarlo", problem);
  experiment::MonteCarloOptions options = args;
  if (args.redraw_terrain) options.terrain_seed_base = args.terrain_base.value_or(experiment::kDefaultTerrainSeedBase);
  ProgressMeter meter("montecarlo", &std::cerr);
  if (!args.quiet) {
    options.log = [&meter](const std::string& line) { meter.Note(line); };
    options.progress = [&meter](int finished, int runs) { meter.Update(finished, runs); };
  }
  experiment::ConsistencySummary summary;
  const experiment::Outcome outcome = experiment::RunCalibrationConsistency(options, &summary);
  meter.Finish();
  if (!outcome.ok()) return Exit(args.err, "montecarlo", outcome);
  if (!args.quiet)
    std::cout << eval::ConsistencyTable(summary.blocks) << FailedRunsTable(summary.failed_runs)
              << Headline(args, summary) << "\n";
  return 0;
}

}  // namespace roamlab::apps
