// Results of a regression run and the four ways they are reported: a table for people, report.html (common/html.h)
// for people in a browser, results.json for tools, and JUnit XML for CI systems (one <testcase classname="CASE"
// name="METRIC"> per check: <failure> when it fails, <error> when its value could not be read, <skipped> for an open
// target that does not hold (message: value, bound and reason) and for the checks of a case skipped for absent data).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace roamlab::regress {

struct CheckResult {
  // kOpen: an open target (`open:` in the suite) that does not hold; kSkipped: its case was skipped. Neither fails
  // the run. An open target that holds is kPassed (with `open` set: "met, remove the marker").
  enum class Outcome { kPassed, kFailed, kError, kOpen, kSkipped };
  std::string metric;               // the metric path as written
  std::string bound;                // the bound as written ("equals TEXT" for a text)
  std::optional<double> value;      // absent when it could not be read (or is a text)
  std::optional<double> baseline;   // absent when the bound has none or none is stored
  std::optional<double> threshold;  // the bound's right-hand side, when it could be computed
  Outcome outcome = Outcome::kError;
  std::string message;              // failure, error, open or skip: what and why, one line
  std::optional<std::string> text;  // the value of a text metric
  std::string open;                 // the open marker's reason; "" for an ordinary check
};

struct CaseResult {
  std::string name;
  std::string mode;
  std::string error;     // empty when the case ran
  std::string skipped;   // why the case did not run (absent data); empty when it ran
  double seconds = 0.0;  // wall time (reported, never checked)
  std::vector<CheckResult> checks;
};

struct SuiteResult {
  std::string file;
  std::string name;
  double seconds = 0.0;
  std::vector<CaseResult> cases;

  int Count(CheckResult::Outcome outcome) const;
  bool Passed() const;  // no check failed, no check or case errored (open and skipped do not count)
};

// "value V violates bound B (threshold T, baseline X)", "value 'unknown' is not 'named'".
std::string FailureMessage(const CheckResult& check);

std::string ResultsTable(const SuiteResult& result);
// results.json and junit.xml hold no wall time: the same cases give the same bytes, also when a run interrupted and
// resumed (`regress --resume`) gathers them. The times go to timings.json (TimingsJson) and the table.
nlohmann::json ResultsJson(const SuiteResult& result);
// timings.json: {"seconds": the run's wall time, "cases": {NAME: seconds}} (a resumed case keeps its first run's).
nlohmann::json TimingsJson(const SuiteResult& result);
std::string JunitXml(const SuiteResult& result);
// report.html: one self-contained page, the verdict and the counts first, case errors and skips, then every check
// (case, mode, metric, value, bound, threshold, baseline, result, message).
std::string ResultsHtml(const SuiteResult& result);

// `text` with &, <, >, " and ' escaped for XML, and characters XML 1.0 does not allow replaced by '?'.
std::string XmlEscape(const std::string& text);

}  // namespace roamlab::regress
