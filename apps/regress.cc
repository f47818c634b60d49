#include "apps/regress.h"

#include <fnmatch.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <thread>

#include <nlohmann/json.hpp>

#include "apps/regress_modes.h"
#include "apps/regress_report.h"
#include "apps/regress_suite.h"
#include "common/check.h"

namespace roamlab::apps {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using regress::Case;
using regress::CaseResult;
using regress::CheckResult;

// Baseline values of one case: metric path -> value.
using Baseline = std::map<std::string, double>;

std::string BaselineFile(const std::string& dir, const std::string& name) { return dir + "/" + name + ".json"; }

// The stored baseline of a case; empty when there is no file. A malformed file is bad input.
Result<Baseline> ReadBaseline(const std::string& dir, const std::string& name) {
  const std::string path = BaselineFile(dir, name);
  Baseline values;
  if (dir.empty() || !fs::exists(path)) return values;
  std::ifstream in(path);
  const json j = json::parse(in, nullptr, false);
  if (j.is_discarded() || !j.is_object() || !j.contains("values") || !j["values"].is_object())
    return Status::Error(path + ": not a baseline file (JSON with an object 'values')");
  for (const auto& [metric, value] : j["values"].items()) {
    if (!value.is_number()) return Status::Error(path + ": values." + metric + " is not a number");
    values[metric] = value.get<double>();
  }
  return values;
}

Status WriteBaseline(const std::string& dir, const Case& c, const Baseline& values) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return Status::Error(dir + ": cannot create the baseline directory: " + ec.message());
  json j = {{"case", c.name}, {"mode", c.mode}, {"values", json::object()}};
  for (const auto& [metric, value] : values) j["values"][metric] = value;
  const std::string path = BaselineFile(dir, c.name);
  std::ofstream out(path);
  out << j.dump(2) << "\n";
  return out ? Status::Ok() : Status::Error(path + ": cannot write");
}

// Runs one case in DIR/cases/NAME and reads the value of each of its checks (bounds are applied later).
CaseResult RunCase(const Case& c, const std::string& out_dir, int jobs) {
  const auto start = std::chrono::steady_clock::now();
  CaseResult result;
  result.name = c.name;
  result.mode = c.mode;
  const regress::ModeSpec& mode = *regress::FindMode(c.mode);
  const std::string dir = out_dir + "/cases/" + c.name;
  std::error_code ec;
  fs::remove_all(dir, ec);
  if (!c.data.empty() && !fs::is_directory(c.data)) {
    result.skipped = "data directory " + c.data + " is absent";
  } else {
    fs::create_directories(dir, ec);
    if (ec) {
      result.error = dir + ": cannot create the case directory: " + ec.message();
    } else {
      const Status st = mode.run(regress::CaseContext{c, dir, jobs});
      if (!st.ok()) result.error = st.message();
    }
  }

  // The values, from the output files the checks name.
  std::map<std::string, json> outputs;
  const auto output = [&](const std::string& name, std::string* file) -> const json* {
    const auto o = std::find_if(mode.outputs.begin(), mode.outputs.end(),
                                [&](const regress::ModeOutput& m) { return m.name == name; });
    ROAMLAB_CHECK(o != mode.outputs.end(), "output " << name << " was validated against mode " << c.mode);
    *file = dir + "/" + o->file;
    if (!outputs.count(name)) {
      std::ifstream in(*file);
      outputs[name] = json::parse(in, nullptr, false);
    }
    return outputs[name].is_discarded() ? nullptr : &outputs[name];
  };
  for (const regress::Check& check : c.checks) {
    CheckResult r;
    r.metric = check.metric.text;
    r.bound = check.equals ? "equals " + *check.equals : check.bound.text;
    r.open = check.open;
    r.outcome = CheckResult::Outcome::kError;
    if (!result.skipped.empty()) {
      r.outcome = CheckResult::Outcome::kSkipped;
      r.message = "case skipped: " + result.skipped;
      result.checks.push_back(r);
      continue;
    }
    if (!result.error.empty()) {
      r.message = "case error: " + result.error;
      result.checks.push_back(r);
      continue;
    }
    std::string file;
    const json* out = output(check.metric.output, &file);
    if (!out) {
      r.message = file + ": missing or not valid JSON";
    } else if (check.metric.is_string) {
      const Result<std::string> text = regress::ResolveText(*out, check.metric);
      if (text.ok()) {
        r.text = text.value();
      } else {
        r.message = file + ": " + text.status().message();
      }
    } else {
      const Result<double> value = regress::ResolveMetric(*out, check.metric);
      if (value.ok()) {
        r.value = value.value();
      } else {
        r.message = file + ": " + value.status().message();
      }
    }
    // The bound's reference metric: its value stands in `baseline`'s place in the threshold.
    if (check.reference && r.message.empty()) {
      const json* ref = output(check.reference->output, &file);
      const Result<double> value = ref ? regress::ResolveMetric(*ref, *check.reference)
                                       : Result<double>(Status::Error("missing or not valid JSON"));
      if (value.ok()) {
        r.threshold = check.bound.Threshold(value.value());
      } else {
        r.value.reset();
        r.message = file + ": bound's reference " + check.reference->text + ": " + value.status().message();
      }
    }
    result.checks.push_back(r);
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

// Applies each check's bound to its value (and baseline); an open target that does not hold becomes kOpen.
void ApplyBounds(const Case& c, const Baseline& baseline, const std::string& baseline_file, CaseResult* result) {
  for (std::size_t i = 0; i < c.checks.size(); ++i) {
    const regress::Check& check = c.checks[i];
    const regress::Bound& bound = check.bound;
    CheckResult& r = result->checks[i];
    bool holds = false;
    if (r.text) {
      holds = *r.text == *check.equals;
    } else if (r.value) {
      double base = 0.0;
      if (bound.uses_baseline) {
        const auto stored = baseline.find(r.metric);
        if (stored == baseline.end()) {
          r.message = "no baseline value for " + r.metric + " in " + baseline_file + " (run with --update-baseline)";
          continue;
        }
        base = stored->second;
        r.baseline = base;
      }
      if (!check.reference) r.threshold = bound.Threshold(base);
      holds = bound.Holds(*r.value, *r.threshold);
    } else {
      continue;  // an error (or a skipped case) already
    }
    if (holds) {
      r.outcome = CheckResult::Outcome::kPassed;
      if (!check.open.empty()) r.message = "open target met (" + check.open + "): remove the 'open' marker";
    } else if (!check.open.empty()) {
      r.outcome = CheckResult::Outcome::kOpen;
      r.message = "open target not met (" + check.open + "): " + regress::FailureMessage(r);
    } else {
      r.outcome = CheckResult::Outcome::kFailed;
      r.message = regress::FailureMessage(r);
    }
  }
}

int BadInput(const std::string& message) {
  std::cerr << "roamlab regress: " << message << "\n";
  return 2;
}

}  // namespace

int RunRegress(const RegressArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  if (args.jobs < 0) return BadInput("--jobs must be >= 0");
  Result<regress::Suite> loaded = regress::LoadSuite(args.suite);
  if (!loaded.ok()) return BadInput(loaded.status().message());
  const regress::Suite& suite = loaded.value();

  // The selected cases and their baselines, all read before any case runs.
  std::vector<const Case*> cases;
  for (const Case& c : suite.cases)
    if ((!args.quick || c.quick) && (args.filter.empty() || fnmatch(args.filter.c_str(), c.name.c_str(), 0) == 0))
      cases.push_back(&c);
  if (cases.empty()) return BadInput(args.suite + ": no case matches the --filter/--quick selection");
  const std::string baseline_dir = args.baseline.empty() ? suite.baseline_dir : args.baseline;
  if (args.update_baseline && baseline_dir.empty())
    return BadInput(args.suite + ": --update-baseline needs --baseline DIR or a 'baseline' in the suite");
  std::vector<Baseline> baselines;
  for (const Case* c : cases) {
    auto b = ReadBaseline(baseline_dir, c->name);
    if (!b.ok()) return BadInput(b.status().message());
    baselines.push_back(std::move(b).value());
  }
  std::error_code ec;
  fs::create_directories(args.out, ec);
  if (ec) return BadInput(args.out + ": cannot create the output directory: " + ec.message());

  // Cases over worker threads, each writing only its own slot; a progress line per finished case.
  const int jobs = args.jobs > 0 ? args.jobs : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  regress::SuiteResult result;
  result.file = args.suite;
  result.name = suite.name;
  result.cases.resize(cases.size());
  std::atomic<std::size_t> next{0}, done{0};
  std::mutex print;
  const auto worker = [&] {
    for (std::size_t i = next++; i < cases.size(); i = next++) {
      result.cases[i] = RunCase(*cases[i], args.out, jobs);
      const std::size_t finished = ++done;
      if (!args.quiet) {
        std::lock_guard<std::mutex> lock(print);
        std::fprintf(stderr, "regress [%zu/%zu] %s (%s): %s in %.1f s\n", finished, cases.size(),
                     cases[i]->name.c_str(), cases[i]->mode.c_str(),
                     !result.cases[i].error.empty() ? "error" : !result.cases[i].skipped.empty() ? "skipped" : "ran",
                     result.cases[i].seconds);
      }
    }
  };
  std::vector<std::thread> threads;
  for (int k = 0; k < std::min<int>(jobs, static_cast<int>(cases.size())); ++k) threads.emplace_back(worker);
  for (std::thread& t : threads) t.join();

  // New baselines (cases that ran), then the bounds.
  for (std::size_t i = 0; i < cases.size(); ++i) {
    if (args.update_baseline && result.cases[i].error.empty() && result.cases[i].skipped.empty()) {
      Baseline values;
      for (const CheckResult& r : result.cases[i].checks)
        if (r.value) values[r.metric] = *r.value;
      const Status st = WriteBaseline(baseline_dir, *cases[i], values);
      if (!st.ok()) result.cases[i].error = st.message();
      baselines[i] = values;
    }
    ApplyBounds(*cases[i], baselines[i], BaselineFile(baseline_dir, cases[i]->name), &result.cases[i]);
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  // Reports.
  std::fputs(regress::ResultsTable(result).c_str(), stdout);
  const std::string results_path = args.out + "/results.json", junit_path = args.out + "/junit.xml";
  std::ofstream results(results_path);
  results << regress::ResultsJson(result).dump(2) << "\n";
  std::ofstream junit(junit_path);
  junit << regress::JunitXml(result);
  if (!results || !junit) {
    std::cerr << "roamlab regress: " << (results ? junit_path : results_path) << ": cannot write\n";
    return 1;
  }
  if (args.update_baseline) std::printf("baseline written to %s\n", baseline_dir.c_str());
  std::printf("wrote %s, %s\n", results_path.c_str(), junit_path.c_str());
  return result.Passed() ? 0 : 1;
}

}  // namespace roamlab::apps
