#include "gap/benchmark/benchmark.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <map>
#include <mutex>
#include <ostream>
#include <random>
#include <sstream>
#include <thread>
#include <tuple>

#include "common/atomic_file.h"
#include "common/interrupt.h"
#include "gap/learn_baseline.h"

namespace roamlab::gap::benchmark {
namespace {

using nlohmann::json;

// Runs fn(0..n-1) on `jobs` threads with a progress bar on `progress` (null: none) and each call's line; the first
// error stops the rest.
Status RunParallel(int n, int jobs, const std::string& label, std::ostream* progress,
                   const std::function<Result<std::string>(int)>& fn) {
  std::atomic<int> next{0};
  std::mutex mutex;
  int done = 0;
  Status first_error = Status::Ok();
  const auto start = std::chrono::steady_clock::now();
  const auto bar = [&] {
    constexpr int kWidth = 30;
    const int filled = n > 0 ? kWidth * done / n : kWidth;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::ostringstream s;
    s << "\r" << label << " [" << std::string(filled, '#') << std::string(kWidth - filled, '.') << "] " << done << "/"
      << n << "  " << std::fixed << std::setprecision(0) << elapsed << " s";
    if (done > 0 && done < n) s << ", about " << elapsed / done * (n - done) << " s left";
    *progress << s.str() << std::flush;
  };
  if (progress) bar();
  const auto worker = [&] {
    for (int i = next++; i < n; i = next++) {
      {
        std::lock_guard<std::mutex> lock(mutex);
        if (!first_error.ok() || InterruptRequested()) return;
      }
      Result<std::string> line = fn(i);
      std::lock_guard<std::mutex> lock(mutex);
      ++done;
      if (!line.ok() && first_error.ok()) first_error = line.status();
      if (progress) {
        *progress << "\r" << std::string(100, ' ') << "\r" << (line.ok() ? line.value() : line.status().message())
                  << "\n";
        bar();
      }
    }
  };
  std::vector<std::thread> threads;
  for (int k = 0; k < std::max(1, std::min(jobs, n)); ++k) threads.emplace_back(worker);
  for (std::thread& t : threads) t.join();
  if (progress) *progress << "\n";
  if (first_error.ok() && InterruptRequested()) return InterruptedError();
  return first_error;
}

// Draws and runs one phase's cases (stratified: kinds by CalibrationKind; else blind); results in draw order.
// The case a finished earlier call wrote to dir/case.json; an error names the file when it does not read back.
Result<CaseResult> ReadCase(const std::string& dir) {
  const Result<std::string> text = ReadWholeFile(dir + "/case.json");
  if (!text.ok()) return text.status();
  auto c = CaseFromRow(json::parse(text.value(), nullptr, false));
  if (!c.ok()) return Status::Error(dir + "/case.json: " + c.status().message() + " (delete it to run the case again)");
  return c;
}

// The salt of the drives' random numbers (DrawDrives), seeded apart from the draws' own.
constexpr std::uint64_t kDriveSeedSalt = 0x6f74686572ULL;

Result<std::vector<CaseResult>> RunPhase(const std::vector<Platform>& platforms, int n, std::uint64_t draw_seed,
                                         std::uint64_t noise_seed0, bool stratified, const std::string& dir,
                                         const CaseSetup& setup, const std::string& label,
                                         const BenchmarkOptions& options, std::ostream* progress) {
  std::mt19937_64 rng(draw_seed);
  std::vector<Draw> draws;
  for (int i = 0; i < n; ++i)  // all drawn first: independent of scheduling
    draws.push_back(DrawCase(rng, stratified ? CalibrationKind(i) : std::string()));
  std::mt19937_64 drive_rng(draw_seed ^ kDriveSeedSalt);
  DrawDrives(drive_rng, options.other_drive, &draws);
  const int jobs = options.jobs;
  const bool resume = options.resume;
  std::vector<CaseResult> results(static_cast<std::size_t>(n));
  const Status st = RunParallel(n, jobs, label, progress, [&](int i) -> Result<std::string> {
    std::ostringstream id;
    id << std::setw(3) << std::setfill('0') << i;
    const Draw& draw = draws[static_cast<std::size_t>(i)];
    const std::string case_dir = dir + "/" + id.str();
    auto c = resume && std::filesystem::exists(case_dir + "/case.json")
                 ? ReadCase(case_dir)
                 : RunCase(platforms[static_cast<std::size_t>(draw.platform)], draw,
                           noise_seed0 + static_cast<std::uint64_t>(i), id.str(), case_dir, setup);
    if (!c.ok()) return Status::Error(label + " case " + id.str() + ": " + c.status().message());
    results[static_cast<std::size_t>(i)] = c.value();
    return CaseLine(c.value());
  });
  if (!st.ok()) return st;
  return results;
}

// Learns each platform's baseline (in parallel) and the ATV's nominal cornering compliance on its truth.
Status LearnBaselines(std::vector<Platform>* platforms, int jobs, std::ostream* progress) {
  return RunParallel(static_cast<int>(platforms->size()), jobs, "baselines", progress,
                     [&](int i) -> Result<std::string> {
                       Platform& p = (*platforms)[static_cast<std::size_t>(i)];
                       auto learned = LearnBaseline(p.scenario, p.config);
                       if (!learned.ok()) return Status::Error(p.name + " " + learned.status().message());
                       p.baseline = learned.value().baseline;
                       const auto& truth = learned.value().simulation.recording.ground_truth;
                       if (p.name == "atv" && truth) p.rear_compliance_s = RearCorneringCompliance(*truth);
                       return p.name + " baseline learned (noise seed " + std::to_string(kDefaultBaselineSeed) + ")";
                     });
}

double SecondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// Phase 1: the calibration cases with the loosest thresholds, the thresholds chosen on them and the parameters'
// noise; score.json's "calibration" and "thresholds".
struct Calibration {
  Thresholds chosen;
  std::map<std::string, std::map<std::string, double>> sigmas;
  json section;
  json thresholds;
};

Result<Calibration> Calibrate(const BenchmarkOptions& options, const std::vector<Platform>& platforms,
                              std::ostream* progress) {
  const CaseSetup loose{Loosest(), true};
  const std::uint64_t calibration_seed = options.seed * 1000 + kMaxCases;
  auto cases = RunPhase(platforms, options.calibration_cases, calibration_seed, calibration_seed, true,
                        options.out + "/calibration", loose, "calibration", options, progress);
  if (!cases.ok()) return cases.status();
  Calibration out;
  json grid;
  // The benchmark's targets on the effect-free cases, imposed on the calibration with the score's rule.
  const double max_decoy_false_rate = 1.0 - kMinDecoysUnknown;
  out.chosen = ChooseThresholds(cases.value(), kMaxNoneFalseRate, max_decoy_false_rate, &grid);
  out.sigmas = CalibrationSigmas(cases.value());
  json rows = json::array();
  for (CaseResult& c : cases.value()) {
    if (c.kind == "effect")
      c.noise_ratio = NoiseRatio(out.sigmas, c.platform, c.truth_name, c.truth_parameter, c.truth_value);
    json row = CaseRow(c);
    row["replayed_first_round"] = ReplayFirstRound(c.candidates, out.chosen);
    rows.push_back(row);
  }
  json sigma_json = json::object();
  for (const auto& [platform, by_parameter] : out.sigmas)
    for (const auto& [key, sigma] : by_parameter) sigma_json[platform][key] = sigma;
  out.section = {{"cases", rows},
                 {"draw_and_noise_seed_base", calibration_seed},
                 {"max_none_false_rate", kMaxNoneFalseRate},
                 {"max_decoy_false_rate", max_decoy_false_rate},
                 {"grid", grid},
                 {"noise_sigmas", sigma_json}};
  out.thresholds = {{"alpha", out.chosen.alpha},
                    {"max_delta_bic", out.chosen.max_delta_bic},
                    {"min_heldout_improvement", out.chosen.min_heldout_improvement},
                    {"min_explained_share", out.chosen.min_explained_share}};
  return out;
}

}  // namespace

Result<std::vector<Platform>> LoadPlatforms(const BenchmarkOptions& options) {
  std::vector<Platform> platforms;
  for (const auto& [name, path, kind] : {std::make_tuple("atv", options.atv_scenario, "ackermann"),
                                         std::make_tuple("diffdrive", options.diffdrive_scenario, "differential_drive"),
                                         std::make_tuple("mecanum", options.mecanum_scenario, "mecanum")}) {
    auto p = LoadPlatform(name, path, kind, options.duration_s);
    if (!p.ok()) return p.status();
    platforms.push_back(std::move(p).value());
  }
  return platforms;
}

Result<json> RunBenchmark(const BenchmarkOptions& options, std::vector<Platform> platforms, std::ostream* progress) {
  const auto start = std::chrono::steady_clock::now();
  if (Status s = LearnBaselines(&platforms, options.jobs, progress); !s.ok()) return s;
  const double baseline_s = SecondsSince(start);

  // 1. Calibration: the loosest thresholds, every passing candidate evaluated on the held-out part.
  const auto calibration_start = std::chrono::steady_clock::now();
  auto calibration = Calibrate(options, platforms, progress);
  if (!calibration.ok()) return calibration.status();
  const double calibration_s = SecondsSince(calibration_start);
  if (progress) *progress << "thresholds from the calibration cases: " << calibration.value().thresholds.dump() << "\n";

  // 2. The scored cases, diagnosed with the chosen thresholds.
  const auto scored_start = std::chrono::steady_clock::now();
  auto scored = RunPhase(platforms, options.cases, options.seed, options.seed * 1000, false, options.out + "/cases",
                         {calibration.value().chosen, false}, "scored", options, progress);
  if (!scored.ok()) return scored.status();
  json rows = json::array();
  for (CaseResult& c : scored.value()) {
    if (c.kind == "effect")
      c.noise_ratio =
          NoiseRatio(calibration.value().sigmas, c.platform, c.truth_name, c.truth_parameter, c.truth_value);
    rows.push_back(CaseRow(c));
  }
  const double scored_s = SecondsSince(scored_start);
  const double total_s = SecondsSince(start);
  json score = {
      {"seed", options.seed},
      {"jobs", options.jobs},
      {"other_drive", options.other_drive},
      {"duration_s",
       {{"atv", platforms[0].scenario.duration_s},
        {"diffdrive", platforms[1].scenario.duration_s},
        {"mecanum", platforms[2].scenario.duration_s}}},
      {"figures", Summarize(scored.value())},
      {"thresholds", calibration.value().thresholds},
      {"calibration", calibration.value().section},
      {"cases", rows},
      {"seconds",
       {{"total", total_s},
        {"baselines", baseline_s},
        {"calibration", calibration_s},
        {"scored", scored_s},
        {"extrapolated_total_for_60_scored_cases", baseline_s + calibration_s + scored_s / options.cases * 60.0}}}};
  return score;
}

}  // namespace roamlab::gap::benchmark
