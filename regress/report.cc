#include "regress/report.h"

#include <algorithm>
#include <cstdio>

#include "common/html.h"

namespace roamlab::regress {
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
    case CheckResult::Outcome::kPassed:
      return "pass";
    case CheckResult::Outcome::kFailed:
      return "FAIL";
    case CheckResult::Outcome::kError:
      return "ERROR";
    case CheckResult::Outcome::kOpen:
      return "open (not met)";
    case CheckResult::Outcome::kSkipped:
      return "skipped";
  }
  return "?";
}

const char* ResultName(const CheckResult& k) {
  switch (k.outcome) {
    case CheckResult::Outcome::kPassed:
      return k.open.empty() ? "passed" : "open met";
    case CheckResult::Outcome::kFailed:
      return "failed";
    case CheckResult::Outcome::kError:
      return "error";
    case CheckResult::Outcome::kOpen:
      return "open";
    case CheckResult::Outcome::kSkipped:
      return "skipped";
  }
  return "?";
}

std::string ValueText(const CheckResult& k) { return k.text ? "'" + *k.text + "'" : Format(k.value); }

int OpenMet(const SuiteResult& result) {
  int n = 0;
  for (const CaseResult& c : result.cases)
    for (const CheckResult& k : c.checks) n += k.outcome == CheckResult::Outcome::kPassed && !k.open.empty();
  return n;
}

int Total(const SuiteResult& result) {
  int n = 0;
  for (const CaseResult& c : result.cases) n += static_cast<int>(c.checks.size());
  return n;
}

// "N checks: ... (C cases, S s)".
std::string SummaryLine(const SuiteResult& result) {
  char line[512];
  std::snprintf(line, sizeof line,
                "%d checks: %d passed, %d failed, %d errors, %d open targets not met, %d open targets met, %d skipped "
                "(%zu cases, %.1f s)",
                Total(result), result.Count(CheckResult::Outcome::kPassed) - OpenMet(result),
                result.Count(CheckResult::Outcome::kFailed), result.Count(CheckResult::Outcome::kError),
                result.Count(CheckResult::Outcome::kOpen), OpenMet(result),
                result.Count(CheckResult::Outcome::kSkipped), result.cases.size(), result.seconds);
  return line;
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
  if (check.text)
    return "value " + ValueText(check) + " is not '" + check.bound.substr(check.bound.find(' ') + 1) + "'";
  std::string message = "value " + Format(check.value) + " violates bound '" + check.bound + "'";
  if (check.baseline) {
    message += " (threshold " + Format(check.threshold) + ", baseline " + Format(check.baseline) + ")";
  } else if (check.threshold && check.bound.find('*') != std::string::npos) {
    message += " (threshold " + Format(check.threshold) + ")";
  }
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
      row(c.name, k.metric, ValueText(k), k.bound, Format(k.baseline),
          k.outcome == CheckResult::Outcome::kPassed && !k.open.empty() ? "MET (open: remove the marker)"
                                                                        : OutcomeName(k.outcome));
  for (const CaseResult& c : result.cases) {
    if (!c.error.empty()) out += "case " + c.name + ": error: " + c.error + "\n";
    if (!c.skipped.empty()) out += "case " + c.name + ": skipped: " + c.skipped + "\n";
  }
  for (const CaseResult& c : result.cases)
    for (const CheckResult& k : c.checks)
      if (k.outcome == CheckResult::Outcome::kOpen) out += c.name + " " + k.metric + ": " + k.message + "\n";
  return out + SummaryLine(result) + "\n";
}

json ResultsJson(const SuiteResult& result) {
  json cases = json::array();
  for (const CaseResult& c : result.cases) {
    json checks = json::array();
    for (const CheckResult& k : c.checks) {
      json check = {{"metric", k.metric},
                    {"bound", k.bound},
                    {"value", k.text ? json(*k.text) : Optional(k.value)},
                    {"baseline", Optional(k.baseline)},
                    {"threshold", Optional(k.threshold)},
                    {"result", ResultName(k)}};
      if (!k.message.empty()) check["message"] = k.message;
      if (!k.open.empty()) check["open"] = k.open;
      checks.push_back(check);
    }
    json entry = {{"name", c.name}, {"mode", c.mode}, {"checks", checks}};
    if (!c.error.empty()) entry["error"] = c.error;
    if (!c.skipped.empty()) entry["skipped"] = c.skipped;
    cases.push_back(entry);
  }
  return {{"suite", result.name},
          {"file", result.file},
          {"passed", result.Passed()},
          {"checks",
           {{"passed", result.Count(CheckResult::Outcome::kPassed)},
            {"failed", result.Count(CheckResult::Outcome::kFailed)},
            {"errors", result.Count(CheckResult::Outcome::kError)},
            {"open_not_met", result.Count(CheckResult::Outcome::kOpen)},
            {"open_met", OpenMet(result)},
            {"skipped", result.Count(CheckResult::Outcome::kSkipped)}}},
          {"cases", cases}};
}

json TimingsJson(const SuiteResult& result) {
  json cases = json::object();
  for (const CaseResult& c : result.cases) cases[c.name] = c.seconds;
  return {{"seconds", result.seconds}, {"cases", cases}};
}

std::string XmlEscape(const std::string& text) {
  std::string out;
  for (const char ch : text) {
    const unsigned char u = static_cast<unsigned char>(ch);
    switch (ch) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += (u < 0x20 && ch != '\t' && ch != '\n' && ch != '\r') ? '?' : ch;
    }
  }
  return out;
}

std::string JunitXml(const SuiteResult& result) {
  const int skipped = result.Count(CheckResult::Outcome::kOpen) + result.Count(CheckResult::Outcome::kSkipped);
  const std::string counts = " tests=\"" + std::to_string(Total(result)) + "\" failures=\"" +
                             std::to_string(result.Count(CheckResult::Outcome::kFailed)) + "\" errors=\"" +
                             std::to_string(result.Count(CheckResult::Outcome::kError)) + "\" skipped=\"" +
                             std::to_string(skipped) + "\"";
  std::string xml = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  xml += "<testsuites name=\"roamlab regress\"" + counts + ">\n";
  xml += "  <testsuite name=\"" + XmlEscape(result.name) + "\"" + counts + ">\n";
  for (const CaseResult& c : result.cases)
    for (const CheckResult& k : c.checks) {
      xml += "    <testcase classname=\"" + XmlEscape(c.name) + "\" name=\"" + XmlEscape(k.metric) + "\"";
      const std::string detail = "mode " + c.mode + ", metric " + k.metric + ", bound " + k.bound + ", value " +
                                 ValueText(k) + ", threshold " + Format(k.threshold) + ", baseline " +
                                 Format(k.baseline);
      if (k.outcome == CheckResult::Outcome::kPassed && k.open.empty()) {
        xml += "/>\n";
      } else if (k.outcome == CheckResult::Outcome::kPassed) {
        xml += ">\n      <system-out>" +
               XmlEscape("open target met (" + k.open + "): remove the 'open' marker; " + detail) +
               "</system-out>\n    </testcase>\n";
      } else if (k.outcome == CheckResult::Outcome::kOpen || k.outcome == CheckResult::Outcome::kSkipped) {
        xml += ">\n      <skipped message=\"" + XmlEscape(k.message) + "\"/>\n    </testcase>\n";
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

std::string ResultsHtml(const SuiteResult& result) {
  html::Page page("Regression suite " + result.name);
  page.Paragraph((result.Passed() ? "PASSED: " : "FAILED: ") + SummaryLine(result),
                 result.Passed() ? "verdict-pass" : "verdict-fail");
  page.Paragraph("Suite " + result.file + ".");
  for (const CaseResult& c : result.cases) {
    if (!c.error.empty()) page.Paragraph("case " + c.name + ": error: " + c.error, "verdict-fail");
    if (!c.skipped.empty()) page.Paragraph("case " + c.name + ": skipped: " + c.skipped, "note");
  }
  page.Heading(2, "Checks");
  html::Table table{{"case", "mode", "metric", "value", "bound", "threshold", "baseline", "result", "message"}, {}};
  for (const CaseResult& c : result.cases)
    for (const CheckResult& k : c.checks)
      table.rows.push_back({c.name, c.mode, k.metric, ValueText(k), k.bound, Format(k.threshold), Format(k.baseline),
                            k.outcome == CheckResult::Outcome::kPassed && !k.open.empty()
                                ? "MET (open: remove the marker)"
                                : OutcomeName(k.outcome),
                            k.message});
  page.AddTable(table);
  return page.Document();
}

}  // namespace roamlab::regress
