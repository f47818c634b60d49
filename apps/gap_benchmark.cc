#include "apps/gap_benchmark.h"

#include <filesystem>
#include <iomanip>
#include <iostream>

#include "apps/cli.h"
#include "common/atomic_file.h"

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
  std::error_code ec;
  std::filesystem::create_directories(args.out, ec);
  if (ec) return bad(args.out + ": cannot create the output directory");

  auto score = benchmark::RunBenchmark(args, std::move(platforms).value(), args.quiet ? nullptr : &std::cout);
  if (!score.ok()) return Failure(args.err, "gap-benchmark", score.status().message());
  if (Status s = WriteFileAtomic(args.out + "/score.json", score.value().dump(2) + "\n"); !s.ok())
    return Failure(args.err, "gap-benchmark", s.message());
  if (!args.quiet) {
    std::cout << "figures: " << score.value()["figures"].dump() << "\n"
              << "total " << std::fixed << std::setprecision(0) << score.value()["seconds"]["total"].get<double>()
              << " s (" << args.out << "/score.json)\n";
  }
  return 0;
}

}  // namespace roamlab::apps
