#include "regress/regress.h"

#include <fnmatch.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <thread>

#include <nlohmann/json.hpp>

#include "common/check.h"
#include "regress/modes.h"
#include "regress/suite.h"

namespace roamlab::regress {
namespace {

namespace fs = std::filesystem;
using experiment::Outcome;
using nlohmann::json;

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
  const ModeSpec& mode = *FindMode(c.mode);
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
      const Status st = mode.run(CaseContext{c, dir, jobs});
      if (!st.ok()) result.error = st.message();
    }
  }

  // The values, from the output files the checks name.
  std::map<std::string, json> outputs;
  const auto output = [&](const std::string& name, std::string* file) -> const json* {
    const auto o =
        std::find_if(mode.outputs.begin(), mode.outputs.end(), [&](const ModeOutput& m) { return m.name == name; });
    ROAMLAB_CHECK(o != mode.outputs.end(), "output " << name << " was validated against mode " << c.mode);
    *file = dir + "/" + o->file;
    if (!outputs.count(name)) {
      std::ifstream in(*file);
      outputs[name] = json::parse(in, nullptr, false);
    }
    return outputs[name].is_discarded() ? nullptr : &outputs[name];
  };
  for (const Check& check : c.checks) {
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
      const Result<std::string> text = ResolveText(*out, check.metric);
      if (text.ok()) {
        r.text = text.value();
      } else {
        r.message = file + ": " + text.status().message();
      }
    } else {
      const Result<double> value = ResolveMetric(*out, check.metric);
      if (value.ok()) {
        r.value = value.value();
      } else {
        r.message = file + ": " + value.status().message();
      }
    }
    // The bound's reference metric: its value stands in `baseline`'s place in the threshold.
    if (check.reference && r.message.empty()) {
      const json* ref = output(check.reference->output, &file);
      const Result<double> value =
          ref ? ResolveMetric(*ref, *check.reference) : Result<double>(Status::Error("missing or not valid JSON"));
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
    const Check& check = c.checks[i];
    const Bound& bound = check.bound;
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
      r.message = "open target not met (" + check.open + "): " + FailureMessage(r);
    } else {
      r.outcome = CheckResult::Outcome::kFailed;
      r.message = FailureMessage(r);
    }
  }
}

// The selected cases of the suite.
std::vector<const Case*> SelectCases(const Suite& suite, const RunOptions& options) {
  std::vector<const Case*> cases;
  for (const Case& c : suite.cases)
    if ((!options.quick || c.quick) &&
        (options.filter.empty() || fnmatch(options.filter.c_str(), c.name.c_str(), 0) == 0))
      cases.push_back(&c);
  return cases;
}

// The cases over worker threads, each writing only its own slot; a progress line per finished case.
void RunCases(const std::vector<const Case*>& cases, const RunOptions& options, SuiteResult* result) {
  const int jobs =
      options.jobs > 0 ? options.jobs : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  result->cases.resize(cases.size());
  std::atomic<std::size_t> next{0}, done{0};
  std::mutex print;
  const auto worker = [&] {
    for (std::size_t i = next++; i < cases.size(); i = next++) {
      result->cases[i] = RunCase(*cases[i], options.out, jobs);
      const std::size_t finished = ++done;
      if (options.progress) {
        const CaseResult& r = result->cases[i];
        char line[512];
        std::snprintf(line, sizeof line, "regress [%zu/%zu] %s (%s): %s in %.1f s", finished, cases.size(),
                      cases[i]->name.c_str(), cases[i]->mode.c_str(),
                      !r.error.empty()     ? "error"
                      : !r.skipped.empty() ? "skipped"
                                           : "ran",
                      r.seconds);
        std::lock_guard<std::mutex> lock(print);
        options.progress(line);
      }
    }
  };
  std::vector<std::thread> threads;
  for (int k = 0; k < std::min<int>(jobs, static_cast<int>(cases.size())); ++k) threads.emplace_back(worker);
  for (std::thread& t : threads) t.join();
}

}  // namespace

Outcome RunSuite(const RunOptions& options, SuiteResult* result, RunReports* reports) {
  const auto start = std::chrono::steady_clock::now();
  const auto bad = [](const std::string& message) { return Outcome::BadInput(Status::Error(message)); };
  if (options.jobs < 0) return bad("--jobs must be >= 0");
  Result<Suite> loaded = LoadSuite(options.suite);
  if (!loaded.ok()) return Outcome::BadInput(loaded.status());
  const Suite& suite = loaded.value();

  // The selected cases and their baselines, all read before any case runs.
  const std::vector<const Case*> cases = SelectCases(suite, options);
  if (cases.empty()) return bad(options.suite + ": no case matches the --filter/--quick selection");
  const std::string baseline_dir = options.baseline.empty() ? suite.baseline_dir : options.baseline;
  if (options.update_baseline && baseline_dir.empty())
    return bad(options.suite + ": --update-baseline needs --baseline DIR or a 'baseline' in the suite");
  std::vector<Baseline> baselines;
  for (const Case* c : cases) {
    auto b = ReadBaseline(baseline_dir, c->name);
    if (!b.ok()) return Outcome::BadInput(b.status());
    baselines.push_back(std::move(b).value());
  }
  if (const Status dir = experiment::MakeOutputDirectory(options.out); !dir.ok()) return Outcome::BadInput(dir);

  result->file = options.suite;
  result->name = suite.name;
  RunCases(cases, options, result);

  // New baselines (cases that ran), then the bounds.
  for (std::size_t i = 0; i < cases.size(); ++i) {
    if (options.update_baseline && result->cases[i].error.empty() && result->cases[i].skipped.empty()) {
      Baseline values;
      for (const CheckResult& r : result->cases[i].checks)
        if (r.value) values[r.metric] = *r.value;
      const Status st = WriteBaseline(baseline_dir, *cases[i], values);
      if (!st.ok()) result->cases[i].error = st.message();
      baselines[i] = values;
    }
    ApplyBounds(*cases[i], baselines[i], BaselineFile(baseline_dir, cases[i]->name), &result->cases[i]);
  }
  result->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  // Reports.
  reports->baseline_dir = baseline_dir;
  reports->results_json = options.out + "/results.json";
  reports->junit_xml = options.out + "/junit.xml";
  std::ofstream results(reports->results_json);
  results << ResultsJson(*result).dump(2) << "\n";
  std::ofstream junit(reports->junit_xml);
  junit << JunitXml(*result);
  if (!results || !junit)
    return Outcome::Failed(Status::Error((results ? reports->junit_xml : reports->results_json) + ": cannot write"));
  reports->report_html = options.out + "/report.html";
  std::ofstream page(reports->report_html);
  page << ResultsHtml(*result);
  if (!page) return Outcome::Failed(Status::Error(reports->report_html + ": cannot write"));
  return Outcome::Ok();
}

}  // namespace roamlab::regress
