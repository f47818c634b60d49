#include "gap/benchmark/benchmark.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <map>
#include <mutex>
#include <optional>
#include <ostream>
#include <random>
#include <sstream>
#include <thread>
#include <tuple>

#include "common/atomic_file.h"
#include "common/interrupt.h"
#include "common/progress.h"
#include "gap/learn_baseline.h"

namespace roamlab::gap::benchmark {
namespace {

using nlohmann::json;

// Runs fn(0..n-1) on `jobs` threads with progress (common/progress.h) on `progress` (null: none) and each call's
// line; the first error stops the rest.
Status RunParallel(int n, int jobs, const std::string& label, std::ostream* progress,
                   const std::function<Result<std::string>(int)>& fn) {
  std::atomic<int> next{0};
  std::mutex mutex;
  int done = 0;
  Status first_error = Status::Ok();
  std::optional<ProgressMeter> meter;
  if (progress) meter.emplace(label, progress);
  if (meter) meter->Update(0, n);
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
      if (meter) {
        meter->Note(line.ok() ? line.value() : line.status().message());
        meter->Update(done, n);
      }
    }
  };
  std::vector<std::thread> threads;
  for (int k = 0; k < std::max(1, std::min(jobs, n)); ++k) threads.emplace_back(worker);
  for (std::thread& t : threads) t.join();
  if (meter) meter->Finish();
  if (first_error.ok() && InterruptRequested()) return InterruptedError();
  return first_error;
}

// One phase of the benchmark: its cases' draws and noise seeds and their directory.
struct Phase {
  int n = 0;
  std::uint64_t draw_seed = 0;
  std::uint64_t noise_seed0 = 0;  // case i: noise_seed0 + i
  bool stratified = false;        // kinds by CalibrationKind; else blind
  double other_drive = 0.0;       // fraction of the cases driven by another schedule (DrawDrives)
  std::string dir;
  std::string label;
};

Phase CalibrationPhase(const BenchmarkOptions& options) {
  const std::uint64_t seed = options.seed * 1000 + kMaxCases;
  return {options.calibration_cases, seed, seed, true, options.other_drive, options.out + "/calibration",
          "calibration"};
}

Phase ScoredPhase(const BenchmarkOptions& options) {
  return {options.cases, options.seed, options.seed * 1000, false, options.other_drive, options.out + "/cases",
          "scored"};
}

// Case k of the benchmark: its phase and index in it.
std::pair<Phase, int> LocateCase(const BenchmarkOptions& options, int k) {
  if (k < options.calibration_cases) return {CalibrationPhase(options), k};
  return {ScoredPhase(options), k - options.calibration_cases};
}

// The salt of the drives' random numbers (DrawDrives), seeded apart from the draws' own.
constexpr std::uint64_t kDriveSeedSalt = 0x6f74686572ULL;

// All of a phase's draws, drawn first: independent of which cases run where and when.
std::vector<Draw> PhaseDraws(const Phase& phase) {
  std::mt19937_64 rng(phase.draw_seed);
  std::vector<Draw> draws;
  for (int i = 0; i < phase.n; ++i)
    draws.push_back(DrawCase(rng, phase.stratified ? CalibrationKind(i) : std::string()));
  std::mt19937_64 drive_rng(phase.draw_seed ^ kDriveSeedSalt);
  DrawDrives(drive_rng, phase.other_drive, &draws);
  return draws;
}

std::string CaseId(int i) {
  std::ostringstream id;
  id << std::setw(3) << std::setfill('0') << i;
  return id.str();
}

// The case a finished earlier call wrote to dir/case.json; an error names the file when it does not read back.
Result<CaseResult> ReadCase(const std::string& dir) {
  const Result<std::string> text = ReadWholeFile(dir + "/case.json");
  if (!text.ok()) return Status::Error(dir + "/case.json: cannot read (the case has not finished)");
  auto c = CaseFromRow(json::parse(text.value(), nullptr, false));
  if (!c.ok()) return Status::Error(dir + "/case.json: " + c.status().message() + " (delete it to run the case again)");
  return c;
}

// Every case of a phase read back from its case.json.
Result<std::vector<CaseResult>> ReadPhase(const Phase& phase) {
  std::vector<CaseResult> cases;
  for (int i = 0; i < phase.n; ++i) {
    auto c = ReadCase(phase.dir + "/" + CaseId(i));
    if (!c.ok()) return c.status();
    cases.push_back(std::move(c).value());
  }
  return cases;
}

// Runs case i of a phase (or, with `resume`, reads it back when its case.json exists).
Result<CaseResult> RunPhaseCase(const std::vector<Platform>& platforms, const Phase& phase,
                                const std::vector<Draw>& draws, int i, const CaseSetup& setup, bool resume) {
  const Draw& draw = draws[static_cast<std::size_t>(i)];
  const std::string case_dir = phase.dir + "/" + CaseId(i);
  auto c = resume && std::filesystem::exists(case_dir + "/case.json")
               ? ReadCase(case_dir)
               : RunCase(platforms[static_cast<std::size_t>(draw.platform)], draw,
                         phase.noise_seed0 + static_cast<std::uint64_t>(i), CaseId(i), case_dir, setup);
  if (!c.ok()) return Status::Error(phase.label + " case " + CaseId(i) + ": " + c.status().message());
  return c;
}

// Runs one phase's cases on `jobs` threads; results in draw order.
Result<std::vector<CaseResult>> RunPhase(const std::vector<Platform>& platforms, const Phase& phase,
                                         const CaseSetup& setup, int jobs, bool resume, std::ostream* progress) {
  const std::vector<Draw> draws = PhaseDraws(phase);
  std::vector<CaseResult> results(static_cast<std::size_t>(phase.n));
  const Status st = RunParallel(phase.n, jobs, phase.label, progress, [&](int i) -> Result<std::string> {
    auto c = RunPhaseCase(platforms, phase, draws, i, setup, resume);
    if (!c.ok()) return c.status();
    results[static_cast<std::size_t>(i)] = c.value();
    return CaseLine(c.value());
  });
  if (!st.ok()) return st;
  return results;
}

// Learns one platform's baseline and the ATV's nominal cornering compliance on its truth; the progress line.
Result<std::string> LearnPlatformBaseline(Platform* p) {
  auto learned = LearnBaseline(p->scenario, p->config);
  if (!learned.ok()) return Status::Error(p->name + " " + learned.status().message());
  p->baseline = learned.value().baseline;
  const auto& truth = learned.value().simulation.recording.ground_truth;
  if (p->name == "atv" && truth) p->rear_compliance_s = RearCorneringCompliance(*truth);
  return p->name + " baseline learned (noise seed " + std::to_string(kDefaultBaselineSeed) + ")";
}

double SecondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// A case's row of score.json: its case.json without the run time (timings.json holds it).
json ScoreRow(const CaseResult& c) {
  json row = CaseRow(c);
  row.erase("seconds");
  return row;
}

// The thresholds chosen on the calibration cases, with the benchmark's targets on the effect-free cases imposed on
// the calibration with the score's rule; `grid` (optional) receives every grid point's counts.
Thresholds ChooseOnCalibration(const std::vector<CaseResult>& calibration, json* grid) {
  return ChooseThresholds(calibration, kMaxNoneFalseRate, 1.0 - kMinDecoysUnknown, grid);
}

// Phase 1's outcome: the thresholds chosen on the calibration cases and the parameters' noise; score.json's
// "calibration" and "thresholds".
struct Calibration {
  Thresholds chosen;
  std::map<std::string, std::map<std::string, double>> sigmas;
  json section;
  json thresholds;
};

Calibration CalibrationFrom(const BenchmarkOptions& options, std::vector<CaseResult> cases) {
  Calibration out;
  json grid;
  out.chosen = ChooseOnCalibration(cases, &grid);
  out.sigmas = CalibrationSigmas(cases);
  json rows = json::array();
  for (CaseResult& c : cases) {
    if (c.kind == "effect")
      c.noise_ratio = NoiseRatio(out.sigmas, c.platform, c.truth_name, c.truth_parameter, c.truth_value);
    json row = ScoreRow(c);
    row["replayed_first_round"] = ReplayFirstRound(c.candidates, out.chosen);
    rows.push_back(row);
  }
  json sigma_json = json::object();
  for (const auto& [platform, by_parameter] : out.sigmas)
    for (const auto& [key, sigma] : by_parameter) sigma_json[platform][key] = sigma;
  out.section = {{"cases", rows},
                 {"draw_and_noise_seed_base", CalibrationPhase(options).draw_seed},
                 {"max_none_false_rate", kMaxNoneFalseRate},
                 {"max_decoy_false_rate", 1.0 - kMinDecoysUnknown},
                 {"grid", grid},
                 {"noise_sigmas", sigma_json}};
  out.thresholds = {{"alpha", out.chosen.alpha},
                    {"max_delta_bic", out.chosen.max_delta_bic},
                    {"min_heldout_improvement", out.chosen.min_heldout_improvement},
                    {"min_explained_share", out.chosen.min_explained_share}};
  return out;
}

// score.json: the figures on the scored cases (their noise ratios from the calibration's sigmas), the thresholds,
// the calibration and the per-case table; nothing that depends on how or where the cases ran.
json ScoreJson(const BenchmarkOptions& options, const std::vector<Platform>& platforms,
               const Calibration& calibration, std::vector<CaseResult> scored) {
  json rows = json::array();
  for (CaseResult& c : scored) {
    if (c.kind == "effect")
      c.noise_ratio = NoiseRatio(calibration.sigmas, c.platform, c.truth_name, c.truth_parameter, c.truth_value);
    rows.push_back(ScoreRow(c));
  }
  return {{"seed", options.seed},
          {"other_drive", options.other_drive},
          {"duration_s",
           {{"atv", platforms[0].scenario.duration_s},
            {"diffdrive", platforms[1].scenario.duration_s},
            {"mecanum", platforms[2].scenario.duration_s}}},
          {"figures", Summarize(scored)},
          {"thresholds", calibration.thresholds},
          {"calibration", calibration.section},
          {"cases", rows}};
}

// timings.json's "cases": each case's run time [s] by its directory under OUT.
json CaseSeconds(const std::vector<CaseResult>& calibration, const std::vector<CaseResult>& scored) {
  json seconds = json::object();
  for (const CaseResult& c : calibration) seconds["calibration/" + c.id] = c.seconds;
  for (const CaseResult& c : scored) seconds["cases/" + c.id] = c.seconds;
  return seconds;
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

Result<BenchmarkResult> RunBenchmark(const BenchmarkOptions& options, std::vector<Platform> platforms,
                                     std::ostream* progress) {
  // The platforms' baselines, in parallel.
  const auto start = std::chrono::steady_clock::now();
  const Status learned =
      RunParallel(static_cast<int>(platforms.size()), options.jobs, "baselines", progress,
                  [&](int i) { return LearnPlatformBaseline(&platforms[static_cast<std::size_t>(i)]); });
  if (!learned.ok()) return learned;
  const double baseline_s = SecondsSince(start);

  // 1. Calibration: the loosest thresholds, every passing candidate evaluated on the held-out part.
  const auto calibration_start = std::chrono::steady_clock::now();
  auto calibration_cases = RunPhase(platforms, CalibrationPhase(options), {Loosest(), true}, options.jobs,
                                    options.resume, progress);
  if (!calibration_cases.ok()) return calibration_cases.status();
  const Calibration calibration = CalibrationFrom(options, calibration_cases.value());
  const double calibration_s = SecondsSince(calibration_start);
  if (progress) *progress << "thresholds from the calibration cases: " << calibration.thresholds.dump() << "\n";

  // 2. The scored cases, diagnosed with the chosen thresholds.
  const auto scored_start = std::chrono::steady_clock::now();
  auto scored = RunPhase(platforms, ScoredPhase(options), {calibration.chosen, false}, options.jobs, options.resume,
                         progress);
  if (!scored.ok()) return scored.status();
  const double scored_s = SecondsSince(scored_start);
  const double total_s = SecondsSince(start);
  json timings = {
      {"jobs", options.jobs},
      {"seconds",
       {{"total", total_s},
        {"baselines", baseline_s},
        {"calibration", calibration_s},
        {"scored", scored_s},
        {"extrapolated_total_for_60_scored_cases", baseline_s + calibration_s + scored_s / options.cases * 60.0}}},
      {"cases", CaseSeconds(calibration_cases.value(), scored.value())}};
  return BenchmarkResult{ScoreJson(options, platforms, calibration, scored.value()), timings};
}

Status WriteBenchmarkResult(const std::string& out, const BenchmarkResult& result) {
  if (Status s = WriteFileAtomic(out + "/score.json", result.score.dump(2) + "\n"); !s.ok()) return s;
  return WriteFileAtomic(out + "/timings.json", result.timings.dump(2) + "\n");
}

int CaseCount(const BenchmarkOptions& options) { return options.calibration_cases + options.cases; }

std::string CaseDirectory(const BenchmarkOptions& options, int k) {
  const auto [phase, i] = LocateCase(options, k);
  return phase.dir + "/" + CaseId(i);
}

std::string CaseName(const BenchmarkOptions& options, int k) {
  const auto [phase, i] = LocateCase(options, k);
  return phase.label + " case " + CaseId(i) + " (noise seed " +
         std::to_string(phase.noise_seed0 + static_cast<std::uint64_t>(i)) + ")";
}

std::vector<int> PlatformsOfCases(const BenchmarkOptions& options, int first, int last) {
  const std::vector<Draw> calibration = PhaseDraws(CalibrationPhase(options));
  const std::vector<Draw> scored = PhaseDraws(ScoredPhase(options));
  std::vector<int> platforms;
  for (int k = std::max(first, 0); k < std::min(last, CaseCount(options)); ++k) {
    const Draw& draw = k < options.calibration_cases ? calibration[static_cast<std::size_t>(k)]
                                                     : scored[static_cast<std::size_t>(k - options.calibration_cases)];
    if (std::find(platforms.begin(), platforms.end(), draw.platform) == platforms.end())
      platforms.push_back(draw.platform);
  }
  std::sort(platforms.begin(), platforms.end());
  return platforms;
}

Status LearnBaselines(std::vector<Platform>* platforms, const std::vector<int>& which) {
  for (const int p : which) {
    auto learned = LearnPlatformBaseline(&(*platforms)[static_cast<std::size_t>(p)]);
    if (!learned.ok()) return learned.status();
  }
  return Status::Ok();
}

Result<Thresholds> ScoredThresholds(const BenchmarkOptions& options) {
  auto calibration = ReadPhase(CalibrationPhase(options));
  if (!calibration.ok()) return calibration.status();
  return ChooseOnCalibration(calibration.value(), nullptr);
}

Status RunOneCase(const BenchmarkOptions& options, const std::vector<Platform>& platforms, int k,
                  const Thresholds& scored) {
  const auto [phase, i] = LocateCase(options, k);
  const CaseSetup setup = k < options.calibration_cases ? CaseSetup{Loosest(), true} : CaseSetup{scored, false};
  const Result<CaseResult> c = RunPhaseCase(platforms, phase, PhaseDraws(phase), i, setup, false);
  return c.ok() ? Status::Ok() : c.status();
}

Result<BenchmarkResult> ScoreFromCaseFiles(const BenchmarkOptions& options, const std::vector<Platform>& platforms) {
  auto calibration = ReadPhase(CalibrationPhase(options));
  if (!calibration.ok()) return calibration.status();
  auto scored = ReadPhase(ScoredPhase(options));
  if (!scored.ok()) return scored.status();
  json timings = {{"cases", CaseSeconds(calibration.value(), scored.value())}};
  return BenchmarkResult{ScoreJson(options, platforms, CalibrationFrom(options, calibration.value()), scored.value()),
                         timings};
}

}  // namespace roamlab::gap::benchmark
