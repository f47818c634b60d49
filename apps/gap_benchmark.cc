#include "apps/gap_benchmark.h"

#include <iomanip>
#include <iostream>
#include <memory>

#include "apps/cli.h"
#include "batch/slurm.h"
#include "batch/work.h"
#include "experiment/steps.h"

namespace roamlab::apps {

int RunGapBenchmark(const GapBenchmarkArgs& args) {
  namespace benchmark = gap::benchmark;
  const auto bad = [&](const std::string& message) { return BadInput(args.err, "gap-benchmark", message); };
  if (args.cases < 1 || args.cases > benchmark::kMaxCases || args.calibration_cases < 1 ||
      args.calibration_cases > benchmark::kMaxCases)
    return bad("--cases and --calibration-cases must be in [1, " + std::to_string(benchmark::kMaxCases) + "]");
  if (args.jobs < 1) return bad("--jobs must be >= 1");
  if (args.duration_s < 0.0) return bad("--duration must be positive");
  if (!(args.other_drive >= 0.0 && args.other_drive <= 1.0)) return bad("--other-drive must be in [0, 1]");
  auto platforms = benchmark::LoadPlatforms(args);
  if (!platforms.ok()) return bad(platforms.status().message());
  const std::unique_ptr<batch::Work> work = batch::GapBenchmarkWork(args);
  if (args.backend.backend == "slurm")
    return SubmitBatch(*work, args.backend, args.resume, args.quiet, args.err, "gap-benchmark");
  if (Status made = experiment::MakeOutputDirectory(args.out); !made.ok()) return bad(made.message());

  (void)batch::WriteLocalBatchFile(*work, "running", "");
  auto result = benchmark::RunBenchmark(args, std::move(platforms).value(), args.quiet ? nullptr : &std::cout);
  Status written = result.ok() ? benchmark::WriteBenchmarkResult(args.out, result.value()) : result.status();
  (void)batch::WriteLocalBatchFile(*work, written.ok() ? "done" : "failed",
                                   written.ok() ? args.out + "/score.json" : written.message());
  if (!written.ok()) return Failure(args.err, "gap-benchmark", written.message());
  if (!args.quiet) {
    const nlohmann::json& score = result.value().score;
    std::cout << "figures: " << score["figures"].dump() << "\n"
              << "total " << std::fixed << std::setprecision(0)
              << result.value().timings["seconds"]["total"].get<double>() << " s (" << args.out
              << "/score.json, timings.json)\n";
  }
  return 0;
}

}  // namespace roamlab::apps
