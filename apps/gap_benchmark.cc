#include "apps/gap_benchmark.h"

#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>

namespace roamlab::apps {

int RunGapBenchmark(const GapBenchmarkArgs& args) {
  namespace benchmark = gap::benchmark;
  std::ostream& err = args.err ? *args.err : std::cerr;
  const auto bad = [&](const std::string& message) {
    err << "roamlab gap-benchmark: " << message << "\n";
    return 2;
  };
  if (args.cases < 1 || args.cases > benchmark::kMaxCases || args.calibration_cases < 1 ||
      args.calibration_cases > benchmark::kMaxCases)
    return bad("--cases and --calibration-cases must be in [1, " + std::to_string(benchmark::kMaxCases) + "]");
  if (args.jobs < 1) return bad("--jobs must be >= 1");
  if (args.duration_s < 0.0) return bad("--duration must be positive");
  auto platforms = benchmark::LoadPlatforms(args);
  if (!platforms.ok()) return bad(platforms.status().message());
  std::error_code ec;
  std::filesystem::create_directories(args.out, ec);
  if (ec) return bad(args.out + ": cannot create the output directory");

  auto score = benchmark::RunBenchmark(args, std::move(platforms).value(), args.quiet ? nullptr : &std::cout);
  if (!score.ok()) {
    err << "roamlab gap-benchmark: " << score.status().message() << "\n";
    return 1;
  }
  std::ofstream out(args.out + "/score.json");
  out << score.value().dump(2) << "\n";
  if (!out) {
    err << "roamlab gap-benchmark: " << args.out << "/score.json: cannot write\n";
    return 1;
  }
  if (!args.quiet) {
    std::cout << "figures: " << score.value()["figures"].dump() << "\n"
              << "total " << std::fixed << std::setprecision(0) << score.value()["seconds"]["total"].get<double>()
              << " s (" << args.out << "/score.json)\n";
  }
  return 0;
}

}  // namespace roamlab::apps
