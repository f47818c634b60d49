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
#include <optional>
#include <set>
#include <thread>
#include <tuple>

#include <nlohmann/json.hpp>

#include "common/atomic_file.h"
#include "common/check.h"
#include "common/interrupt.h"
#include "common/progress.h"
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
  return WriteFileAtomic(BaselineFile(dir, c.name), j.dump(2) + "\n");
}

constexpr char kCaseRecord[] = "case_result.json";

std::string CaseDirectory(const std::string& out_dir, const std::string& name) { return out_dir + "/cases/" + name; }

// The check as a case result names it: its metric and its bound as written.
std::pair<std::string, std::string> CheckNames(const Check& check) {
  return {check.metric.text, check.equals ? "equals " + *check.equals : check.bound.text};
}

json OptionalNumber(const std::optional<double>& value) { return value ? json(*value) : json(); }

// OUT/cases/NAME/case_result.json: what RunCase found (before the bounds), written when the case has finished; the
// record `--resume` reads instead of running the case again.
Status WriteCaseRecord(const std::string& out_dir, const CaseResult& r) {
  json checks = json::array();
  for (const CheckResult& k : r.checks) {
    json check = {{"metric", k.metric},
                  {"bound", k.bound},
                  {"outcome", static_cast<int>(k.outcome)},
                  {"value", OptionalNumber(k.value)},
                  {"threshold", OptionalNumber(k.threshold)},
                  {"message", k.message},
                  {"open", k.open}};
    if (k.text) check["text"] = *k.text;
    checks.push_back(check);
  }
  const json record = {{"name", r.name},       {"mode", r.mode},       {"error", r.error},
                       {"skipped", r.skipped}, {"seconds", r.seconds}, {"checks", checks}};
  const std::string dir = CaseDirectory(out_dir, r.name);
  std::error_code ec;
  fs::create_directories(dir, ec);  // a skipped case has none yet
  if (ec) return Status::Error(dir + ": cannot create the case directory: " + ec.message());
  return WriteFileAtomic(dir + "/" + kCaseRecord, record.dump(1) + "\n");
}

std::optional<double> ReadOptionalNumber(const json& value) {
  if (value.is_number()) return value.get<double>();
  return std::nullopt;
}

// The record of a finished case, when it exists and matches the case as the suite defines it now (mode, checks);
// nullopt otherwise (the case runs again).
std::optional<CaseResult> ReadCaseRecord(const std::string& out_dir, const Case& c) {
  std::ifstream in(CaseDirectory(out_dir, c.name) + "/" + kCaseRecord);
  if (!in) return std::nullopt;
  const json j = json::parse(in, nullptr, false);
  try {
    if (j.is_discarded() || j.at("name") != c.name || j.at("mode") != c.mode) return std::nullopt;
    const json& checks = j.at("checks");
    if (!checks.is_array() || checks.size() != c.checks.size()) return std::nullopt;
    CaseResult r;
    r.name = c.name;
    r.mode = c.mode;
    r.error = j.at("error").get<std::string>();
    r.skipped = j.at("skipped").get<std::string>();
    r.seconds = j.at("seconds").get<double>();
    for (std::size_t i = 0; i < c.checks.size(); ++i) {
      const json& k = checks[i];
      CheckResult check;
      check.metric = k.at("metric").get<std::string>();
      check.bound = k.at("bound").get<std::string>();
      if (std::make_pair(check.metric, check.bound) != CheckNames(c.checks[i])) return std::nullopt;
      const int outcome = k.at("outcome").get<int>();
      if (outcome < 0 || outcome > static_cast<int>(CheckResult::Outcome::kSkipped)) return std::nullopt;
      check.outcome = static_cast<CheckResult::Outcome>(outcome);
      check.value = ReadOptionalNumber(k.at("value"));
      check.threshold = ReadOptionalNumber(k.at("threshold"));
      check.message = k.at("message").get<std::string>();
      check.open = k.at("open").get<std::string>();
      if (k.contains("text")) check.text = k.at("text").get<std::string>();
      r.checks.push_back(check);
    }
    return r;
  } catch (const json::exception&) {
    return std::nullopt;
  }
}

// Runs one case in DIR/cases/NAME and reads the value of each of its checks (bounds are applied later).
CaseResult RunCase(const Case& c, const std::string& out_dir, int jobs) {
  const auto start = std::chrono::steady_clock::now();
  CaseResult result;
  result.name = c.name;
  result.mode = c.mode;
  const ModeSpec& mode = *FindMode(c.mode);
  const std::string dir = CaseDirectory(out_dir, c.name);
  std::error_code ec;
  fs::remove_all(dir, ec);
  if (!c.data.empty() && !fs::is_directory(c.data)) {
    result.skipped = "data directory " + c.data + " is absent";
  } else {
    fs::create_directories(dir, ec);
    if (ec) {
      result.error = dir + ": cannot create the case directory: " + ec.message();
    } else {
      const Status st = FindModeRunner(c.mode)(CaseContext{c, dir, jobs});
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
    std::tie(r.metric, r.bound) = CheckNames(check);
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

// The progress line of a finished case, `elapsed_s` after the first started: "regress [3/9] NAME (MODE): ran in
// 12.5 s, 40s elapsed, about 1m20s left".
std::string ProgressLine(std::size_t finished, std::size_t total, const CaseResult& r, bool resumed, double elapsed_s) {
  const char* what = resumed              ? "resumed, ran earlier"
                     : !r.error.empty()   ? "error"
                     : !r.skipped.empty() ? "skipped"
                                          : "ran";
  char line[512];
  std::snprintf(line, sizeof line, "regress [%zu/%zu] %s (%s): %s in %.1f s", finished, total, r.name.c_str(),
                r.mode.c_str(), what, r.seconds);
  return line + ElapsedAndLeft(elapsed_s, SecondsLeft(elapsed_s, static_cast<double>(finished) / total));
}

// One case: with `resume`, from its record when that matches; otherwise run and recorded. nullopt when an interrupt
// stopped it (its directory is removed: it runs again on --resume).
std::optional<CaseResult> FinishCase(const Case& c, const RunOptions& options, int jobs, bool* resumed) {
  std::optional<CaseResult> r = options.resume ? ReadCaseRecord(options.out, c) : std::nullopt;
  *resumed = r.has_value();
  if (*resumed) return r;
  r = RunCase(c, options.out, jobs);
  if (InterruptRequested() && !r->error.empty()) {
    std::error_code ec;
    fs::remove_all(CaseDirectory(options.out, c.name), ec);
    return std::nullopt;
  }
  if (const Status recorded = WriteCaseRecord(options.out, *r); !recorded.ok() && r->error.empty())
    r->error = recorded.message();
  return r;
}

// The cases over worker threads, each writing only its own slot and `finished` flag; a progress line and a line in
// the marker per finished case. Once an interrupt is requested no case starts.
void RunCases(const std::vector<const Case*>& cases, const RunOptions& options, IncompleteMarker* marker,
              SuiteResult* result, std::vector<char>* finished) {
  const int jobs =
      options.jobs > 0 ? options.jobs : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  result->cases.resize(cases.size());
  finished->assign(cases.size(), 0);
  std::atomic<std::size_t> next{0}, done{0};
  std::mutex print;
  const auto start = std::chrono::steady_clock::now();
  const auto worker = [&] {
    for (std::size_t i = next++; i < cases.size() && !InterruptRequested(); i = next++) {
      bool resumed = false;
      std::optional<CaseResult> r = FinishCase(*cases[i], options, jobs, &resumed);
      if (!r) continue;
      result->cases[i] = std::move(*r);
      (*finished)[i] = 1;
      const double elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const std::string line = ProgressLine(++done, cases.size(), result->cases[i], resumed, elapsed_s);
      std::lock_guard<std::mutex> lock(print);
      // The marker is best effort here: it was written at the start, and says "running" whatever fails now.
      (void)marker->AddDone("case " + cases[i]->name);
      if (options.progress) options.progress(line);
    }
  };
  std::vector<std::thread> threads;
  for (int k = 0; k < std::min<int>(jobs, static_cast<int>(cases.size())); ++k) threads.emplace_back(worker);
  for (std::thread& t : threads) t.join();
}

// The reports of an earlier run in OUT, and the directories of cases not selected now; with `resume` the selected
// cases' directories are kept (their records are read), without it each is replaced when its case runs.
Status RemoveStaleOutputs(const std::string& out, const std::vector<const Case*>& cases) {
  for (const char* file : {"results.json", "junit.xml", "report.html", "timings.json"})
    if (Status s = RemoveStaleFile(out + "/" + file); !s.ok()) return s;
  std::set<std::string> selected;
  for (const Case* c : cases) selected.insert(c->name);
  std::vector<fs::path> stale;
  std::error_code ec;
  for (fs::directory_iterator it(out + "/cases", ec), end; !ec && it != end; it.increment(ec))
    if (!selected.count(it->path().filename().string())) stale.push_back(it->path());
  for (const fs::path& path : stale) {
    fs::remove_all(path, ec);
    if (ec) return Status::Error(path.string() + ": cannot remove stale case: " + ec.message());
  }
  return Status::Ok();
}

// The cases not finished dropped from `result`; the error that names the interruption.
Status StopInterrupted(const std::vector<char>& finished, IncompleteMarker* marker, SuiteResult* result) {
  std::vector<CaseResult> kept;
  for (std::size_t i = 0; i < finished.size(); ++i)
    if (finished[i]) kept.push_back(std::move(result->cases[i]));
  result->cases = std::move(kept);
  const Status stopped =
      Status::Error(InterruptedError().message() + " after " + std::to_string(result->cases.size()) + " of " +
                    std::to_string(finished.size()) + " cases (" + marker->path() + " lists them; --resume continues)");
  marker->SetMessage(stopped.message());
  return stopped;
}

// results.json, junit.xml, timings.json and report.html.
Status WriteReports(const RunOptions& options, const SuiteResult& result, RunReports* reports) {
  reports->results_json = options.out + "/results.json";
  reports->junit_xml = options.out + "/junit.xml";
  reports->report_html = options.out + "/report.html";
  Status st = WriteFileAtomic(reports->results_json, ResultsJson(result).dump(2) + "\n");
  if (st.ok()) st = WriteFileAtomic(reports->junit_xml, JunitXml(result));
  if (st.ok()) st = WriteFileAtomic(options.out + "/timings.json", TimingsJson(result).dump(2) + "\n");
  if (st.ok()) st = WriteFileAtomic(reports->report_html, ResultsHtml(result));
  return st;
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
  if (const Status stale = RemoveStaleOutputs(options.out, cases); !stale.ok()) return Outcome::Failed(stale);
  IncompleteMarker marker(options.out);
  if (const Status started = marker.Start(); !started.ok()) return Outcome::Failed(started);

  result->file = options.suite;
  result->name = suite.name;
  std::vector<char> finished;
  RunCases(cases, options, &marker, result, &finished);
  if (std::count(finished.begin(), finished.end(), 1) < static_cast<std::ptrdiff_t>(cases.size()))
    return Outcome::Failed(StopInterrupted(finished, &marker, result));

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

  reports->baseline_dir = baseline_dir;
  if (const Status written = WriteReports(options, *result, reports); !written.ok()) return Outcome::Failed(written);
  if (const Status completed = marker.Complete(); !completed.ok()) return Outcome::Failed(completed);
  return Outcome::Ok();
}

}  // namespace roamlab::regress
