// Regression reports: JUnit XML that is well-formed whatever the names and messages hold, one testcase per check,
// failures naming value, bound and baseline.
#include "regress/report.h"

#include <cctype>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/support/html_check.h"

namespace roamlab::regress {
namespace {

// A small XML 1.0 well-formedness checker for what JunitXml writes: declaration, elements with quoted attributes,
// character data, the five predefined entities. Returns "" when well-formed, else the problem.
class XmlChecker {
 public:
  explicit XmlChecker(const std::string& xml) : s_(xml) {}

  std::string Check() {
    if (s_.rfind("<?xml ", 0) == 0) pos_ = s_.find("?>") + 2;
    std::vector<std::string> open;
    bool root_seen = false;
    while (pos_ < s_.size()) {
      if (s_[pos_] != '<') {
        const std::string problem = Text('<');
        if (!problem.empty()) return problem;
        continue;
      }
      ++pos_;
      if (pos_ < s_.size() && s_[pos_] == '/') {
        ++pos_;
        const std::string name = Name();
        if (open.empty() || open.back() != name) return "unbalanced </" + name + ">";
        open.pop_back();
        if (!Expect('>')) return "bad end tag " + name;
        continue;
      }
      if (open.empty() && root_seen) return "a second root element";
      const std::string name = Name();
      if (name.empty()) return "an element without a name at " + std::to_string(pos_);
      root_seen = true;
      for (;;) {
        SkipSpace();
        if (Expect('>')) {
          open.push_back(name);
          break;
        }
        if (s_.compare(pos_, 2, "/>") == 0) {
          pos_ += 2;
          break;
        }
        const std::string attribute = Name();
        if (attribute.empty() || !Expect('=') || !Expect('"')) return "bad attribute in <" + name + ">";
        const std::string problem = Text('"');
        if (!problem.empty()) return problem;
        if (!Expect('"')) return "unterminated attribute " + attribute;
      }
    }
    return open.empty() && root_seen ? "" : "unclosed elements";
  }

 private:
  std::string Name() {
    const std::size_t start = pos_;
    while (pos_ < s_.size() && (std::isalnum(static_cast<unsigned char>(s_[pos_])) || s_[pos_] == '_' ||
                                s_[pos_] == '-' || s_[pos_] == ':' || s_[pos_] == '.'))
      ++pos_;
    return s_.substr(start, pos_ - start);
  }
  void SkipSpace() {
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_]))) ++pos_;
  }
  bool Expect(char c) {
    if (pos_ < s_.size() && s_[pos_] == c) {
      ++pos_;
      return true;
    }
    return false;
  }
  // Character data up to `end`: no raw '<' or '&' outside an entity, no control characters XML forbids.
  std::string Text(char end) {
    while (pos_ < s_.size() && s_[pos_] != end) {
      const unsigned char c = static_cast<unsigned char>(s_[pos_]);
      if (c == '<') return "raw '<' in text";
      if (c < 0x20 && c != '\t' && c != '\n' && c != '\r') return "control character in text";
      if (c == '&') {
        bool known = false;
        for (const char* entity : {"&amp;", "&lt;", "&gt;", "&quot;", "&apos;"})
          if (s_.compare(pos_, std::string(entity).size(), entity) == 0) {
            pos_ += std::string(entity).size();
            known = true;
            break;
          }
        if (!known) return "raw '&' in text";
        continue;
      }
      ++pos_;
    }
    return "";
  }
  const std::string& s_;
  std::size_t pos_ = 0;
};

std::size_t Occurrences(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

SuiteResult Example() {
  SuiteResult r;
  r.name = "suite <with> \"quotes\" & 'apostrophes'";
  r.file = "s.yaml";
  CaseResult a;
  a.name = "atv&calibration";
  a.mode = "calibrate";
  CheckResult pass{"metrics.ate_m", "<= 0.5", 0.25, std::nullopt, 0.5, CheckResult::Outcome::kPassed, "",
                   std::nullopt,    ""};
  CheckResult fail{"metrics.nees.fraction_in_band",
                   ">= baseline - 0.03",
                   0.5,
                   0.9,
                   0.87,
                   CheckResult::Outcome::kFailed,
                   "",
                   std::nullopt,
                   ""};
  fail.message = FailureMessage(fail);
  a.checks = {pass, fail};
  CaseResult b;
  b.name = "broken";
  b.mode = "track";
  b.error = "roamlab track: rec/<gps>.csv:3: bad \x01 byte & more";
  b.checks = {{"summary.poses", "> 10", std::nullopt, std::nullopt, std::nullopt, CheckResult::Outcome::kError,
               "case error: " + b.error, std::nullopt, ""}};
  r.cases = {a, b};
  return r;
}

TEST(JunitTest, WellFormedWithOneTestcasePerCheck) {
  const SuiteResult r = Example();
  const std::string xml = JunitXml(r);
  EXPECT_EQ(XmlChecker(xml).Check(), "") << xml;
  EXPECT_EQ(Occurrences(xml, "<testcase "), 3u);
  EXPECT_EQ(Occurrences(xml, "<failure "), 1u);
  EXPECT_EQ(Occurrences(xml, "<error "), 1u);
  EXPECT_NE(xml.find("tests=\"3\" failures=\"1\" errors=\"1\""), std::string::npos) << xml;
  EXPECT_NE(xml.find("<testcase classname=\"atv&amp;calibration\" name=\"metrics.nees.fraction_in_band\">"),
            std::string::npos)
      << xml;
  // The failure message names the value, the bound and the baseline.
  EXPECT_NE(xml.find("message=\"value 0.5 violates bound &apos;&gt;= baseline - 0.03&apos; (threshold 0.87, "
                     "baseline 0.9)\""),
            std::string::npos)
      << xml;
}

// Open targets and skipped cases: <skipped> testcases (message with value, bound and reason), a met open target a
// passing testcase that says so; none of them fails the run.
TEST(JunitTest, OpenTargetsAndSkippedCasesAreSkippedTestcases) {
  SuiteResult r;
  r.name = "open";
  CaseResult a;
  a.name = "targets";
  a.mode = "calibrate";
  CheckResult open{"metrics.ate_m", "<= 0.1", 0.25, std::nullopt, 0.1, CheckResult::Outcome::kOpen, "",
                   std::nullopt,    ""};
  open.open = "calibration target, not met yet";
  open.message = "open target not met (" + open.open + "): " + FailureMessage(open);
  CheckResult met{"metrics.rpe_trans_m", "<= 0.5", 0.25, std::nullopt, 0.5, CheckResult::Outcome::kPassed, "",
                  std::nullopt,          ""};
  met.open = "calibration target";
  CheckResult text{"gap.verdict",
                   "equals named",
                   std::nullopt,
                   std::nullopt,
                   std::nullopt,
                   CheckResult::Outcome::kFailed,
                   "",
                   std::nullopt,
                   ""};
  text.text = "unknown";
  text.message = FailureMessage(text);
  EXPECT_EQ(text.message, "value 'unknown' is not 'named'");
  a.checks = {open, met, text};
  CaseResult b;
  b.name = "real_data";
  b.mode = "odometry";
  b.skipped = "data directory /x is absent";
  b.checks = {{"table.interval_s", "<= 1", std::nullopt, std::nullopt, std::nullopt, CheckResult::Outcome::kSkipped,
               "case skipped: " + b.skipped, std::nullopt, ""}};
  r.cases = {a, b};
  const std::string xml = JunitXml(r);
  EXPECT_EQ(XmlChecker(xml).Check(), "") << xml;
  EXPECT_EQ(Occurrences(xml, "<testcase "), 4u);
  EXPECT_NE(xml.find("tests=\"4\" failures=\"1\" errors=\"0\" skipped=\"2\""), std::string::npos) << xml;
  EXPECT_NE(xml.find("<skipped message=\"open target not met (calibration target, not met yet): value 0.25 violates "
                     "bound &apos;&lt;= 0.1&apos;\"/>"),
            std::string::npos)
      << xml;
  EXPECT_NE(xml.find("<system-out>open target met (calibration target)"), std::string::npos) << xml;
  EXPECT_NE(xml.find("<skipped message=\"case skipped: data directory /x is absent\"/>"), std::string::npos) << xml;
  const nlohmann::json j = ResultsJson(r);
  EXPECT_EQ(j["cases"][0]["checks"][0]["result"], "open");
  EXPECT_EQ(j["cases"][0]["checks"][0]["open"], "calibration target, not met yet");
  EXPECT_EQ(j["cases"][0]["checks"][1]["result"], "open met");
  EXPECT_EQ(j["cases"][0]["checks"][2]["value"], "unknown");
  EXPECT_EQ(j["cases"][1]["skipped"], b.skipped);
  EXPECT_EQ(j["checks"]["open_not_met"], 1);
  EXPECT_EQ(j["checks"]["open_met"], 1);
  EXPECT_EQ(j["checks"]["skipped"], 1);
  const std::string table = ResultsTable(r);
  EXPECT_NE(table.find("MET (open: remove the marker)"), std::string::npos) << table;
  EXPECT_NE(table.find("4 checks: 0 passed, 1 failed, 0 errors, 1 open targets not met, 1 open targets met, "
                       "1 skipped"),
            std::string::npos)
      << table;
  EXPECT_FALSE(r.Passed());  // the text check failed
  r.cases[0].checks.pop_back();
  EXPECT_TRUE(r.Passed());  // open and skipped alone do not fail
}

TEST(JunitTest, CheckerCatchesMalformedXml) {
  EXPECT_EQ(XmlChecker("<a x=\"1\"><b/></a>").Check(), "");
  EXPECT_NE(XmlChecker("<a><b></a></b>").Check(), "");
  EXPECT_NE(XmlChecker("<a x=\"1 & 2\"/>").Check(), "");
  EXPECT_NE(XmlChecker("<a>1 < 2</a>").Check(), "");
  EXPECT_NE(XmlChecker("<a>\x01</a>").Check(), "");
  EXPECT_NE(XmlChecker("<a/><b/>").Check(), "");
}

TEST(JunitTest, EscapesEveryMarkupCharacter) {
  EXPECT_EQ(XmlEscape("a<b>&\"c'\x02\n"), "a&lt;b&gt;&amp;&quot;c&apos;?\n");
}

TEST(ResultsTest, CountsAndTableShowEveryCheck) {
  const SuiteResult r = Example();
  EXPECT_EQ(r.Count(CheckResult::Outcome::kPassed), 1);
  EXPECT_EQ(r.Count(CheckResult::Outcome::kFailed), 1);
  EXPECT_EQ(r.Count(CheckResult::Outcome::kError), 1);
  EXPECT_FALSE(r.Passed());
  const nlohmann::json j = ResultsJson(r);
  EXPECT_EQ(j["cases"][0]["checks"][1]["result"], "failed");
  EXPECT_DOUBLE_EQ(j["cases"][0]["checks"][1]["baseline"].get<double>(), 0.9);
  EXPECT_TRUE(j["cases"][1]["checks"][0]["value"].is_null());
  const std::string table = ResultsTable(r);
  EXPECT_NE(table.find("FAIL"), std::string::npos);
  EXPECT_NE(table.find("ERROR"), std::string::npos);
  EXPECT_NE(table.find("3 checks: 1 passed, 1 failed, 1 errors"), std::string::npos) << table;

  SuiteResult ok;
  ok.cases = {Example().cases[0]};
  ok.cases[0].checks = {ok.cases[0].checks[0]};
  EXPECT_TRUE(ok.Passed());
  ok.cases[0].error = "late failure";
  EXPECT_FALSE(ok.Passed());
}

// report.html: well-formed, the verdict first, one row per check with the markup of names escaped.
TEST(ResultsTest, HtmlReportHasTheVerdictFirstAndEveryCheck) {
  const std::string page = ResultsHtml(Example());
  const testing::HtmlSummary html = testing::CheckHtml(page);
  ASSERT_EQ(html.error, "") << page;
  EXPECT_LT(page.find("class=\"verdict-fail\">FAILED: 3 checks: 1 passed, 1 failed, 1 errors"), page.find("<table>"));
  ASSERT_EQ(html.table_headers.size(), 1u);
  EXPECT_EQ(html.table_headers[0].front(), "case");
  EXPECT_EQ(html.table_headers[0].back(), "message");
  EXPECT_EQ(Occurrences(page, "<tr><td>"), 3u);
  EXPECT_NE(page.find("<td>atv&amp;calibration</td>"), std::string::npos);
  EXPECT_NE(page.find("case broken: error: roamlab track: rec/&lt;gps&gt;.csv"), std::string::npos);
}

}  // namespace
}  // namespace roamlab::regress
