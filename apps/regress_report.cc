#include "apps/regress_report.h"

#include <algorithm>
#include <cstdio>

namespace roamlab::apps::regress {
namespace {

using nlohmann::json;

std::string Format(std::optional<double> x) {
  if (!x) return "-";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.6g", *x);
  return buffer;
}

const char* OutcomeName(CheckResult::Outcome outcome) {
  switch (outcome) {
    case CheckResult::Outcome::kPassed: return "pass";
    case CheckResult::Outcome::kFailed: return "FAIL";
    case CheckResult::Outcome::kError: return "ERROR";
  }
  return "?";
}

json Optional(std::optional<double> x) { return x ? json(*x) : json(nullptr); }

}  // namespace

int SuiteResult::Count(CheckResult::Outcome outcome) const {
  int n = 0;
  for (const CaseResult& c : cases)
    for (const CheckResult& k : c.checks) n += k.outcome == outcome;
  return n;
}

bool SuiteResult::Passed() const {
  for (const CaseResult& c : cases)
    if (!c.error.empty()) return false;
  return Count(CheckResult::Outcome::kFailed) == 0 && Count(CheckResult::Outcome::kError) == 0;
}

std::string FailureMessage(const CheckResult& check) {
  std::string message = "value " + Format(check.value) + " violates bound '" + check.bound + "'";
  if (check.baseline)
    message += " (threshold " + Format(check.threshold) + ", baseline " + Format(check.baseline) + ")";
  return message;
}

std::string ResultsTable(const SuiteResult& result) {
  std::size_t case_width = 4, metric_width = 6, bound_width = 5;
  for (const CaseResult& c : result.cases)
    for (const CheckResult& k : c.checks) {
      case_width = std::max(case_width, c.name.size());
      metric_width = std::max(metric_width, k.metric.size());
      bound_width = std::max(bound_width, k.bound.size());
    }
  std::string out;
  char line[1024];
  const auto row = [&](const std::string& a, const std::string& b, const std::string& c, const std::string& d,
                       const std::string& e, const std::string& f) {
    std::snprintf(line, sizeof line, "%-*s  %-*s  %12s  %-*s  %12s  %s\n", static_cast<int>(case_width), a.c_str(),
                  static_cast<int>(metric_width), b.c_str(), c.c_str(), static_cast<int>(bound_width), d.c_str(),
                  e.c_str(), f.c_str());
    out += line;
  };
  row("case", "metric", "value", "bound", "baseline", "result");
  for (const CaseResult& c : result.cases)
    for (const CheckResult& k : c.checks)
      row(c.name, k.metric, Format(k.value), k.bound, Format(k.baseline), OutcomeName(k.outcome));
  for (const CaseResult& c : result.cases) {
    if (!c.error.empty()) out += "case " + c.name + ": error: " + c.error + "\n";
  }
  std::snprintf(line, sizeof line, "%d checks: %d passed, %d failed, %d errors (%zu cases, %.1f s)\n",
                result.Count(CheckResult::Outcome::kPassed) + result.Count(CheckResult::Outcome::kFailed) +
                    result.Count(CheckResult::Outcome::kError),
                result.Count(CheckResult::Outcome::kPassed), result.Count(CheckResult::Outcome::kFailed),
                result.Count(CheckResult::Outcome::kError), result.cases.size(), result.seconds);
  return out + line;
}

json ResultsJson(const SuiteResult& result) {
  json cases = json::array();
  for (const CaseResult& c : result.cases) {
    json checks = json::array();
    for (const CheckResult& k : c.checks) {
      json check = {{"metric", k.metric},
                    {"bound", k.bound},
                    {"value", Optional(k.value)},
                    {"baseline", Optional(k.baseline)},
                    {"threshold", Optional(k.threshold)},
                    {"result", k.outcome == CheckResult::Outcome::kPassed   ? "passed"
                               : k.outcome == CheckResult::Outcome::kFailed ? "failed"
                                                                            : "error"}};
      if (!k.message.empty()) check["message"] = k.message;
      checks.push_back(check);
    }
    json entry = {{"name", c.name}, {"mode", c.mode}, {"seconds", c.seconds}, {"checks", checks}};
    if (!c.error.empty()) entry["error"] = c.error;
    cases.push_back(entry);
  }
  return {{"suite", result.name},
          {"file", result.file},
          {"passed", result.Passed()},
          {"checks",
           {{"passed", result.Count(CheckResult::Outcome::kPassed)},
            {"failed", result.Count(CheckResult::Outcome::kFailed)},
            {"errors", result.Count(CheckResult::Outcome::kError)}}},
          {"seconds", result.seconds},
          {"cases", cases}};
}

std::string XmlEscape(const std::string& text) {
  std::string out;
  for (const char ch : text) {
    const unsigned char u = static_cast<unsigned char>(ch);
    switch (ch) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += (u < 0x20 && ch != '\t' && ch != '\n' && ch != '\r') ? '?' : ch;
    }
  }
  return out;
}

std::string JunitXml(const SuiteResult& result) {
  const int tests = static_cast<int>(result.Count(CheckResult::Outcome::kPassed) +
                                     result.Count(CheckResult::Outcome::kFailed) +
                                     result.Count(CheckResult::Outcome::kError));
  const std::string counts = " tests=\"" + std::to_string(tests) + "\" failures=\"" +
                             std::to_string(result.Count(CheckResult::Outcome::kFailed)) + "\" errors=\"" +
                             std::to_string(result.Count(CheckResult::Outcome::kError)) + "\"";
  char seconds[32];
  std::snprintf(seconds, sizeof seconds, "%.3f", result.seconds);
  std::string xml = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  xml += "<testsuites name=\"roamlab regress\"" + counts + " time=\"" + seconds + "\">\n";
  xml += "  <testsuite name=\"" + XmlEscape(result.name) + "\"" + counts + " time=\"" + seconds + "\">\n";
  for (const CaseResult& c : result.cases)
    for (const CheckResult& k : c.checks) {
      xml += "    <testcase classname=\"" + XmlEscape(c.name) + "\" name=\"" + XmlEscape(k.metric) + "\"";
      const std::string detail = "mode " + c.mode + ", metric " + k.metric + ", bound " + k.bound + ", value " +
                                 Format(k.value) + ", threshold " + Format(k.threshold) + ", baseline " +
                                 Format(k.baseline);
      if (k.outcome == CheckResult::Outcome::kPassed) {
        xml += "/>\n";
      } else if (k.outcome == CheckResult::Outcome::kFailed) {
        xml += ">\n      <failure message=\"" + XmlEscape(k.message) + "\" type=\"bound\">" + XmlEscape(detail) +
               "</failure>\n    </testcase>\n";
      } else {
        xml += ">\n      <error message=\"" + XmlEscape(k.message) + "\" type=\"error\">" + XmlEscape(detail) +
               "</error>\n    </testcase>\n";
      }
    }
  xml += "  </testsuite>\n</testsuites>\n";
  return xml;
}

}  // namespace roamlab::apps::regress
