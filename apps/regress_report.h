// Results of a regression run and the three ways they are reported: a table for people, results.json for tools, and
// JUnit XML for CI systems (one <testcase classname="CASE" name="METRIC"> per check).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace roamlab::apps::regress {

struct CheckResult {
  enum class Outcome { kPassed, kFailed, kError };
  std::string metric;                 // the metric path as written
  std::string bound;                  // the bound as written
  std::optional<double> value;        // absent when it could not be read
  std::optional<double> baseline;     // absent when the bound has none or none is stored
  std::optional<double> threshold;    // the bound's right-hand side, when it could be computed
  Outcome outcome = Outcome::kError;
  std::string message;                // failure or error: what and why, one line
};

struct CaseResult {
  std::string name;
  std::string mode;
  std::string error;                  // empty when the case ran
  double seconds = 0.0;               // wall time (reported, never checked)
  std::vector<CheckResult> checks;
};

struct SuiteResult {
  std::string file;
  std::string name;
  double seconds = 0.0;
  std::vector<CaseResult> cases;

  int Count(CheckResult::Outcome outcome) const;
  bool Passed() const;                // every check of every case passed
};

// "value V violates bound B (threshold T, baseline X)" and friends.
std::string FailureMessage(const CheckResult& check);

std::string ResultsTable(const SuiteResult& result);
nlohmann::json ResultsJson(const SuiteResult& result);
std::string JunitXml(const SuiteResult& result);

// `text` with &, <, >, " and ' escaped for XML, and characters XML 1.0 does not allow replaced by '?'.
std::string XmlEscape(const std::string& text);

}  // namespace roamlab::apps::regress
