#include "batch/work.h"

#include "experiment/sweep.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <type_traits>
#include <utility>

namespace roamlab::batch {
namespace {

using experiment::Outcome;
using nlohmann::json;

class MonteCarlo : public Work {
 public:
  explicit MonteCarlo(experiment::MonteCarloOptions options) : options_(std::move(options)) {
    options_.log = nullptr;
    options_.progress = nullptr;
  }
  std::string kind() const override { return "montecarlo"; }
  int runs() const override { return options_.runs; }
  const std::string& out() const override { return options_.out; }
  json ToJson() const override {
    return {{"kind", kind()},
            {"scenario", options_.scenario},
            {"config", options_.config},
            {"calibration", options_.calibration},
            {"out", options_.out},
            {"runs", options_.runs},
            {"seed_base", options_.seed_base},
            {"t0_s", options_.t0_s},
            {"no_time_budget", options_.no_time_budget},
            {"calibrate_each_run", options_.calibrate_each_run},
            {"command", options_.command.command},
            {"command_dir", options_.command.working_dir},
            {"timeout_s", options_.command.timeout_s}};
  }
  Outcome Prepare(bool resume) override {
    experiment::MonteCarloOptions options = options_;
    options.resume = resume;
    return experiment::PrepareMonteCarlo(options, &shared_);
  }
  bool Done(int i) const override { return std::filesystem::exists(experiment::MonteCarloRunFile(options_.out, i)); }
  Outcome Run(int i) override { return experiment::RunMonteCarloRun(options_, *shared_, i); }
  Outcome Aggregate(std::string* headline) override {
    experiment::MonteCarloSummary summary;
    const Outcome outcome = experiment::AggregateMonteCarlo(options_, &summary);
    if (outcome.ok()) *headline = MonteCarloHeadline(options_, summary);
    return outcome;
  }
  std::string RunName(int i) const override {
    return "run " + std::to_string(i) + " (seed " + std::to_string(options_.seed_base + i) + ")";
  }
  Status Clear() override {
    for (int i = 0; i < options_.runs; ++i) {
      const std::string file = experiment::MonteCarloRunFile(options_.out, i);
      std::error_code ec;
      std::filesystem::remove(file, ec);
      if (ec) return Status::Error(file + ": cannot remove the earlier result file");
    }
    return Status::Ok();
  }

 private:
  experiment::MonteCarloOptions options_;
  std::shared_ptr<const experiment::MonteCarloShared> shared_;
};

// Run r of a sweep is run r % seeds of point r / seeds.
class Sweep : public Work {
 public:
  explicit Sweep(experiment::SweepPlan plan) : plan_(std::move(plan)), seeds_(plan_.montecarlo.runs) {
    plan_.montecarlo.log = nullptr;
    plan_.montecarlo.progress = nullptr;
  }
  std::string kind() const override { return "sweep"; }
  int runs() const override { return static_cast<int>(plan_.values.size()) * seeds_; }
  const std::string& out() const override { return plan_.out; }
  json ToJson() const override {
    return {{"kind", kind()},
            {"out", plan_.out},
            {"keys", plan_.keys},
            {"values", plan_.values},
            {"montecarlo", MonteCarlo(plan_.montecarlo).ToJson()}};
  }
  Outcome Prepare(bool resume) override { return PreparePoints(0, static_cast<int>(plan_.values.size()), resume); }
  // Only the points of runs [first, last): a task of a large sweep reads no other point's inputs.
  Outcome PrepareRuns(int first, int last) override {
    return PreparePoints(first / seeds_, (last - 1) / seeds_ + 1, true);
  }
  bool Done(int r) const override {
    return std::filesystem::exists(experiment::MonteCarloRunFile(Point(r / seeds_).out, r % seeds_));
  }
  Outcome Run(int r) override {
    return experiment::RunMonteCarloRun(Point(r / seeds_), *shared_[r / seeds_], r % seeds_);
  }
  Outcome Aggregate(std::string* headline) override {
    for (int p = 0; p < static_cast<int>(plan_.values.size()); ++p)
      if (Outcome o = experiment::AggregateMonteCarlo(Point(p)); !o.ok()) return o;
    return experiment::WriteSweepSummary(plan_, headline);
  }
  std::string RunName(int r) const override {
    return "point " + std::to_string(r / seeds_) + " run " + std::to_string(r % seeds_) + " (seed " +
           std::to_string(plan_.montecarlo.seed_base + r % seeds_) + ")";
  }
  Status Clear() override {
    for (int p = 0; p < static_cast<int>(plan_.values.size()); ++p)
      if (Status s = MonteCarlo(Point(p)).Clear(); !s.ok()) return s;
    return Status::Ok();
  }

 private:
  experiment::MonteCarloOptions Point(int p) const { return experiment::SweepPointOptions(plan_, p); }
  // Points [first, last) prepared; the others stay unprepared (Run must not be asked for their runs).
  Outcome PreparePoints(int first, int last, bool resume) {
    shared_.assign(plan_.values.size(), nullptr);
    for (int p = first; p < last; ++p) {
      experiment::MonteCarloOptions options = Point(p);
      options.resume = resume;
      if (Outcome o = experiment::PrepareMonteCarlo(options, &shared_[p]); !o.ok()) return o;
    }
    return Outcome::Ok();
  }
  experiment::SweepPlan plan_;
  int seeds_;
  std::vector<std::shared_ptr<const experiment::MonteCarloShared>> shared_;
};

// Run k is case k of the benchmark (gap/benchmark/benchmark.h).
class GapBenchmark : public Work {
 public:
  explicit GapBenchmark(gap::benchmark::BenchmarkOptions options) : options_(std::move(options)) {}
  std::string kind() const override { return "gap-benchmark"; }
  int runs() const override { return gap::benchmark::CaseCount(options_); }
  const std::string& out() const override { return options_.out; }
  // The scored cases once every calibration case is done.
  int Ready() const override {
    for (int k = 0; k < options_.calibration_cases; ++k)
      if (!Done(k)) return options_.calibration_cases;
    return runs();
  }
  json ToJson() const override {
    return {{"kind", kind()},
            {"out", options_.out},
            {"cases", options_.cases},
            {"calibration_cases", options_.calibration_cases},
            {"seed", options_.seed},
            {"duration_s", options_.duration_s},
            {"other_drive", options_.other_drive},
            {"atv", options_.atv_scenario},
            {"diffdrive", options_.diffdrive_scenario},
            {"mecanum", options_.mecanum_scenario}};
  }
  // The scenarios load and OUT exists; the baselines are learned by each task (they are deterministic).
  Outcome Prepare(bool resume) override {
    (void)resume;
    auto platforms = gap::benchmark::LoadPlatforms(options_);
    if (!platforms.ok()) return Outcome::BadInput(platforms.status());
    platforms_ = std::move(platforms).value();
    if (Status made = experiment::MakeOutputDirectory(options_.out); !made.ok()) return Outcome::BadInput(made);
    return Outcome::Ok();
  }
  // The baselines of the platforms the cases are drawn on, and the thresholds of the scored ones.
  Outcome PrepareRuns(int first, int last) override {
    if (Outcome prepared = Prepare(true); !prepared.ok()) return prepared;
    const Status learned =
        gap::benchmark::LearnBaselines(&platforms_, gap::benchmark::PlatformsOfCases(options_, first, last));
    if (!learned.ok()) return Outcome::Failed(learned);
    if (last <= options_.calibration_cases) return Outcome::Ok();
    auto thresholds = gap::benchmark::ScoredThresholds(options_);
    if (!thresholds.ok()) return Outcome::Failed(thresholds.status());
    thresholds_ = thresholds.value();
    return Outcome::Ok();
  }
  bool Done(int k) const override {
    return std::filesystem::exists(gap::benchmark::CaseDirectory(options_, k) + "/case.json");
  }
  Outcome Run(int k) override {
    if (Status ran = gap::benchmark::RunOneCase(options_, platforms_, k, thresholds_); !ran.ok())
      return Outcome::Failed(ran);
    return Outcome::Ok();
  }
  Outcome Aggregate(std::string* headline) override {
    if (Outcome prepared = Prepare(true); !prepared.ok()) return prepared;
    auto result = gap::benchmark::ScoreFromCaseFiles(options_, platforms_);
    if (!result.ok()) return Outcome::Failed(result.status());
    if (Status s = gap::benchmark::WriteBenchmarkResult(options_.out, result.value()); !s.ok())
      return Outcome::Failed(s);
    *headline = "figures: " + result.value().score["figures"].dump() + " (" + options_.out + "/score.json)";
    return Outcome::Ok();
  }
  std::string RunName(int k) const override { return gap::benchmark::CaseName(options_, k); }
  Status Clear() override {
    for (int k = 0; k < runs(); ++k) {
      const std::string file = gap::benchmark::CaseDirectory(options_, k) + "/case.json";
      std::error_code ec;
      std::filesystem::remove(file, ec);
      if (ec) return Status::Error(file + ": cannot remove the earlier result file");
    }
    return Status::Ok();
  }

 private:
  gap::benchmark::BenchmarkOptions options_;
  std::vector<gap::benchmark::Platform> platforms_;
  gap::benchmark::Thresholds thresholds_;
};

// json[key] read into *value when it has the value's type; false otherwise.
template <typename T>
bool Read(const json& j, const char* key, T* value) {
  const auto it = j.find(key);
  if (it == j.end()) return false;
  if constexpr (std::is_same_v<T, bool>) {
    if (!it->is_boolean()) return false;
  } else if constexpr (std::is_same_v<T, std::string>) {
    if (!it->is_string()) return false;
  } else if constexpr (std::is_floating_point_v<T>) {
    if (!it->is_number()) return false;
  } else if constexpr (std::is_unsigned_v<T>) {
    if (!it->is_number_unsigned()) return false;
  } else {
    if (!it->is_number_integer()) return false;
  }
  *value = it->get<T>();
  return true;
}

Result<experiment::MonteCarloOptions> MonteCarloFromJson(const json& j) {
  experiment::MonteCarloOptions o;
  const bool ok = Read(j, "scenario", &o.scenario) && Read(j, "config", &o.config) &&
                  Read(j, "calibration", &o.calibration) && Read(j, "out", &o.out) && Read(j, "runs", &o.runs) &&
                  Read(j, "seed_base", &o.seed_base) && Read(j, "t0_s", &o.t0_s) &&
                  Read(j, "no_time_budget", &o.no_time_budget) && Read(j, "calibrate_each_run", &o.calibrate_each_run);
  // The external estimator's keys: absent in the work of roamlab's own estimator written before they existed.
  const bool command = !j.contains("command") ||
                       (Read(j, "command", &o.command.command) && Read(j, "command_dir", &o.command.working_dir) &&
                        Read(j, "timeout_s", &o.command.timeout_s));
  if (!ok || !command) return Status::Error("the montecarlo work lacks a key or has one of the wrong type");
  return o;
}

Result<gap::benchmark::BenchmarkOptions> GapBenchmarkFromJson(const json& j) {
  gap::benchmark::BenchmarkOptions o;
  const bool ok = Read(j, "out", &o.out) && Read(j, "cases", &o.cases) &&
                  Read(j, "calibration_cases", &o.calibration_cases) && Read(j, "seed", &o.seed) &&
                  Read(j, "duration_s", &o.duration_s) && Read(j, "other_drive", &o.other_drive) &&
                  Read(j, "atv", &o.atv_scenario) &&
                  Read(j, "diffdrive", &o.diffdrive_scenario) && Read(j, "mecanum", &o.mecanum_scenario);
  const auto in_range = [](int n) { return n >= 1 && n <= gap::benchmark::kMaxCases; };
  const bool fraction = o.other_drive >= 0.0 && o.other_drive <= 1.0;
  if (!ok || !in_range(o.cases) || !in_range(o.calibration_cases) || !fraction)
    return Status::Error("the gap-benchmark work lacks a key or has one of the wrong type");
  return o;
}

// A sweep's plan from its ToJson: the points' keys and values and the Monte-Carlo template.
Result<experiment::SweepPlan> SweepFromJson(const json& j) {
  experiment::SweepPlan plan;
  const auto montecarlo = j.find("montecarlo");
  if (montecarlo == j.end()) return Status::Error("the sweep work has no montecarlo");
  auto options = MonteCarloFromJson(*montecarlo);
  if (!options.ok()) return options.status();
  plan.montecarlo = std::move(options).value();
  const auto keys = j.find("keys"), values = j.find("values");
  const auto strings = [](const json& v) {
    return v.is_array() && std::all_of(v.begin(), v.end(), [](const json& e) { return e.is_string(); });
  };
  if (!Read(j, "out", &plan.out) || keys == j.end() || !strings(*keys) || values == j.end() || !values->is_array())
    return Status::Error("the sweep work lacks out, keys or values");
  plan.keys = keys->get<std::vector<std::string>>();
  for (const json& point : *values) {
    if (!strings(point) || point.size() != plan.keys.size())
      return Status::Error("the sweep work has a point without a value per key");
    plan.values.push_back(point.get<std::vector<std::string>>());
  }
  if (plan.values.empty() || plan.montecarlo.runs < 1) return Status::Error("the sweep work has no runs");
  return plan;
}

}  // namespace

std::string MonteCarloHeadline(const experiment::MonteCarloOptions& options,
                               const experiment::MonteCarloSummary& summary) {
  const eval::MonteCarloNees& nees = summary.nees;
  if (!summary.has_nees)
    return std::to_string(options.runs) + " runs; wrote " + options.out + "/runs.json" + summary.plot_note;
  char line[256];
  std::snprintf(line, sizeof line,
                "%d runs: mean NEES in the 95%% band [%.3f, %.3f] for %.1f%% of the time steps after %.1f s; wrote ",
                options.runs, nees.band.lo, nees.band.hi, 100.0 * nees.fraction_in_band, options.t0_s);
  return line + options.out + "/nees.json" + summary.plot_note;
}

std::unique_ptr<Work> SweepWork(experiment::SweepPlan plan) { return std::make_unique<Sweep>(std::move(plan)); }

std::unique_ptr<Work> GapBenchmarkWork(gap::benchmark::BenchmarkOptions options) {
  return std::make_unique<GapBenchmark>(std::move(options));
}

std::unique_ptr<Work> MonteCarloWork(experiment::MonteCarloOptions options) {
  return std::make_unique<MonteCarlo>(std::move(options));
}

Result<std::unique_ptr<Work>> WorkFromJson(const json& j) {
  const std::string kind =
      j.is_object() && j.contains("kind") && j["kind"].is_string() ? j["kind"].get<std::string>() : std::string();
  if (kind == "sweep") {
    auto plan = SweepFromJson(j);
    if (!plan.ok()) return plan.status();
    return SweepWork(std::move(plan).value());
  }
  if (kind == "gap-benchmark") {
    auto options = GapBenchmarkFromJson(j);
    if (!options.ok()) return options.status();
    return GapBenchmarkWork(std::move(options).value());
  }
  if (kind == "montecarlo") {
    auto options = MonteCarloFromJson(j);
    if (!options.ok()) return options.status();
    return MonteCarloWork(std::move(options).value());
  }
  return Status::Error("unknown work kind '" + kind + "'");
}

}  // namespace roamlab::batch
