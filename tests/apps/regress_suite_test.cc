// Regression suites: the bound grammar, metric paths against the outputs' schemas, and one clear line for each kind
// of bad suite file.
#include "apps/regress_suite.h"

#include <algorithm>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/recording/temp_dir.h"

namespace roamlab::apps::regress {
namespace {

using nlohmann::json;

TEST(BoundTest, ParsesNumbersAndBaselineExpressions) {
  struct Case {
    const char* text;
    Bound::Comparator comparator;
    bool uses_baseline;
    double threshold_at_2;  // threshold for a baseline of 2
  };
  const Case cases[] = {
      {"<= 0.5", Bound::Comparator::kLessEqual, false, 0.5},
      {"<=0.5", Bound::Comparator::kLessEqual, false, 0.5},
      {">= -0.25", Bound::Comparator::kGreaterEqual, false, -0.25},
      {"< 1e-3", Bound::Comparator::kLess, false, 1e-3},
      {"> 3", Bound::Comparator::kGreater, false, 3.0},
      {">= baseline - 0.03", Bound::Comparator::kGreaterEqual, true, 1.97},
      {"<= baseline + 0.5", Bound::Comparator::kLessEqual, true, 2.5},
      {"<= 1.10 * baseline", Bound::Comparator::kLessEqual, true, 2.2},
      {"<= 1.5*baseline+1", Bound::Comparator::kLessEqual, true, 4.0},
      {"  >   baseline  ", Bound::Comparator::kGreater, true, 2.0},
  };
  for (const Case& c : cases) {
    const Result<Bound> b = ParseBound(c.text);
    ASSERT_TRUE(b.ok()) << c.text << ": " << b.status().message();
    EXPECT_EQ(b.value().comparator, c.comparator) << c.text;
    EXPECT_EQ(b.value().uses_baseline, c.uses_baseline) << c.text;
    EXPECT_DOUBLE_EQ(b.value().Threshold(2.0), c.threshold_at_2) << c.text;
    EXPECT_EQ(b.value().text, c.text);
  }
}

TEST(BoundTest, ComparesStrictlyOrNotAndRejectsNaN) {
  const Bound le = ParseBound("<= 1").value(), lt = ParseBound("< 1").value();
  const Bound ge = ParseBound(">= 1").value(), gt = ParseBound("> 1").value();
  EXPECT_TRUE(le.Holds(1.0, 1.0));
  EXPECT_FALSE(lt.Holds(1.0, 1.0));
  EXPECT_TRUE(ge.Holds(1.0, 1.0));
  EXPECT_FALSE(gt.Holds(1.0, 1.0));
  EXPECT_FALSE(le.Holds(1.0001, 1.0));
  EXPECT_TRUE(ge.Holds(1.0001, 1.0));
  EXPECT_FALSE(le.Holds(std::nan(""), 1.0));
  EXPECT_FALSE(ge.Holds(std::nan(""), 1.0));
}

TEST(BoundTest, MalformedBoundsSayWhatIsWrong) {
  for (const char* text : {"0.5", "", "<=", "<= abc", "<= 0.5 m", "== 1", "<= baseline *", "<= 2 *", "<= 2 * 3",
                           "<= baseline + ", "<= baseline * 2", "<= - baseline", "<= nan", "<= inf"}) {
    const Result<Bound> b = ParseBound(text);
    ASSERT_FALSE(b.ok()) << "'" << text << "' parsed";
    EXPECT_NE(b.status().message().find(std::string("bound '") + text + "'"), std::string::npos)
        << b.status().message();
    EXPECT_EQ(b.status().message().find('\n'), std::string::npos);
  }
}

class SuiteTest : public ::testing::Test {
 protected:
  // A suite file in the temporary directory with `cases` (YAML text of the cases list) whose config and scenario
  // paths point into the source tree.
  std::string WriteSuite(const std::string& cases) {
    const std::string path = dir_.File("suite.yaml");
    testing::WriteFile(path, "suite: test\ncases:\n" + cases);
    return path;
  }
  static std::string Config(const std::string& name) {
    return std::string(ROAMLAB_SOURCE_DIR) + "/scenarios/" + name;
  }
  std::string CalibrateCase(const std::string& checks, const std::string& extra = "") {
    return "  - name: cal\n    mode: calibrate\n    scenario: " + Config("atv_hills.yaml") +
           "\n    seed: 3\n    config: " + Config("atv_calibration.yaml") + "\n" + extra + "    checks:\n" + checks;
  }
  testing::TempDir dir_;
};

TEST_F(SuiteTest, LoadsCasesWithTheirChecks) {
  const std::string path = WriteSuite(
      CalibrateCase("      - {metric: metrics.parameters.gps.lever_arm.error.norm, bound: \"<= 0.10\"}\n"
                    "      - {metric: metrics.parameters.odometer.kv_over_L.relative_error, bound: \"<= 0.005\"}\n"
                    "      - {metric: metrics.ate_m, bound: \"<= 1.10 * baseline\"}\n"
                    "      - {metric: calibration.measurements.gps.rejected, bound: \"<= 3\"}\n",
                    "    quick: true\n") +
      "  - name: mc\n    mode: montecarlo\n    scenario: " + Config("atv_hills.yaml") + "\n    config: " +
      Config("atv_tracking.yaml") + "\n    runs: 4\n    checks:\n"
      "      - {metric: nees.fraction_in_band, bound: \">= baseline - 0.03\"}\n"
      "      - {metric: runs.runs.ate_m.max, bound: \"<= 2\"}\n"
      "      - {metric: nees.band.1, bound: \"<= 4\"}\n");
  const Result<Suite> suite = LoadSuite(path);
  ASSERT_TRUE(suite.ok()) << suite.status().message();
  ASSERT_EQ(suite.value().cases.size(), 2u);
  const Case& cal = suite.value().cases[0];
  EXPECT_TRUE(cal.quick);
  EXPECT_EQ(cal.seed, 3u);
  ASSERT_EQ(cal.checks.size(), 4u);
  EXPECT_EQ(cal.checks[0].metric.output, "metrics");
  EXPECT_EQ(cal.checks[0].metric.keys, (std::vector<std::string>{"parameters", "gps.lever_arm", "error"}));
  EXPECT_EQ(cal.checks[0].metric.reduction, "norm");
  EXPECT_EQ(cal.checks[3].metric.keys, (std::vector<std::string>{"measurements", "gps", "rejected"}));
  const Case& mc = suite.value().cases[1];
  EXPECT_FALSE(mc.quick);
  EXPECT_EQ(mc.runs, 4);
  EXPECT_EQ(mc.checks[1].metric.keys, (std::vector<std::string>{"runs", "ate_m"}));
  EXPECT_EQ(mc.checks[1].metric.reduction, "max");
  EXPECT_EQ(mc.checks[2].metric.reduction, "1");
}

TEST_F(SuiteTest, EachKindOfBadSuiteIsOneLineNamingFileCaseAndProblem) {
  const std::string check = "      - {metric: metrics.ate_m, bound: \"<= 1\"}\n";
  struct Bad {
    std::string cases;
    std::string problem;
  };
  const std::string hills = Config("atv_hills.yaml"), cal = Config("atv_calibration.yaml");
  const Bad bad[] = {
      {CalibrateCase("      - {metric: metrics.ate_meters, bound: \"<= 1\"}\n"), "unknown key 'ate_meters'"},
      {CalibrateCase("      - {metric: metrics.parameters.gps.lever_arm.eror.norm, bound: \"<= 1\"}\n"),
       "unknown key 'eror'"},
      {CalibrateCase("      - {metric: metrics.parameters.wheel.radius.error.0, bound: \"<= 1\"}\n"),
       "does not start with a parameter"},
      {CalibrateCase("      - {metric: metrics.parameters.gps.lever_arm.error, bound: \"<= 1\"}\n"),
       "is an array"},
      {CalibrateCase("      - {metric: metrics.ate_m.norm, bound: \"<= 1\"}\n"), "is a number"},
      {CalibrateCase("      - {metric: nees.fraction_in_band, bound: \"<= 1\"}\n"), "writes no output 'nees'"},
      {CalibrateCase("      - {metric: calibration.solver.seconds, bound: \"<= 1\"}\n"), "timing value"},
      {CalibrateCase("      - {metric: metrics.ate_m, bound: \"<= fast\"}\n"), "bound '<= fast'"},
      {CalibrateCase("      - {metric: metrics.ate_m, bound: \"0.5\"}\n"), "must start with"},
      {CalibrateCase("      - {metric: metrics.ate_m}\n"), "a check is {metric: PATH, bound: BOUND}"},
      {CalibrateCase(""), "no 'checks'"},
      {CalibrateCase(check, "    window: 3\n"), "unknown key 'window'"},
      {CalibrateCase(check, "    quick: maybe\n"), "malformed value"},
      {"  - name: cal\n    mode: calbrate\n    checks:\n" + check, "unknown mode 'calbrate'"},
      {"  - name: cal\n    mode: odometry\n    checks:\n" + check, "mode odometry is not available in this build"},
      {"  - name: cal\n    mode: diagnose\n    checks:\n" + check, "mode diagnose is not available in this build"},
      {"  - name: cal\n    mode: calibrate\n    scenario: nowhere.yaml\n    config: " + cal + "\n    checks:\n" +
           check,
       "missing scenario"},
      {"  - name: cal\n    mode: calibrate\n    recording: no_rec\n    config: " + cal + "\n    checks:\n" + check,
       "missing recording"},
      {"  - name: cal\n    mode: calibrate\n    config: " + cal + "\n    checks:\n" + check,
       "exactly one of 'scenario' and 'recording'"},
      {"  - name: cal\n    mode: calibrate\n    scenario: " + hills + "\n    config: nowhere.yaml\n    checks:\n" +
           check,
       "bad config"},
      {"  - name: cal\n    mode: montecarlo\n    scenario: " + hills + "\n    config: " + cal + "\n    checks:\n" +
           check,
       "needs 'runs'"},
      {CalibrateCase(check) + CalibrateCase(check), "a second case of this name"},
  };
  for (const Bad& b : bad) {
    const std::string path = WriteSuite(b.cases);
    const Result<Suite> suite = LoadSuite(path);
    ASSERT_FALSE(suite.ok()) << b.problem;
    const std::string& message = suite.status().message();
    EXPECT_EQ(message.rfind(path + ":", 0), 0u) << message;
    EXPECT_NE(message.find("case 'cal'"), std::string::npos) << message;
    EXPECT_NE(message.find(b.problem), std::string::npos) << "expected '" << b.problem << "' in: " << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

TEST_F(SuiteTest, BadSuiteFileOutsideCases) {
  for (const std::string& text : {std::string("cases: []\n"), std::string("suite: x\n"),
                                  std::string("cases:\n  - {name: a\n"), std::string("cases: 3\nextra: 1\n")}) {
    const std::string path = dir_.File("suite.yaml");
    testing::WriteFile(path, text);
    const Result<Suite> suite = LoadSuite(path);
    ASSERT_FALSE(suite.ok()) << text;
    EXPECT_EQ(suite.status().message().rfind(path, 0), 0u) << suite.status().message();
  }
  EXPECT_FALSE(LoadSuite(dir_.File("absent.yaml")).ok());
}

TEST(ResolveMetricTest, WalksKeysReducesArraysAndDerivesRelativeErrors) {
  const json metrics = json::parse(R"({
    "ate_m": 0.25, "nees_mean": null,
    "parameters": {"gps.lever_arm": {"error": [0.03, -0.04, 0.0], "truth": [0.57, -0.46, 0.32]},
                   "odometer.kv_over_L": {"error": [0.002], "truth": [0.8]}}})");
  const auto path = [](std::vector<std::string> keys, std::string reduction) {
    MetricPath p;
    p.output = "metrics";
    p.keys = std::move(keys);
    p.reduction = std::move(reduction);
    return p;
  };
  EXPECT_DOUBLE_EQ(ResolveMetric(metrics, path({"ate_m"}, "")).value(), 0.25);
  EXPECT_DOUBLE_EQ(ResolveMetric(metrics, path({"parameters", "gps.lever_arm", "error"}, "norm")).value(), 0.05);
  EXPECT_DOUBLE_EQ(ResolveMetric(metrics, path({"parameters", "gps.lever_arm", "error"}, "max_abs")).value(), 0.04);
  EXPECT_DOUBLE_EQ(ResolveMetric(metrics, path({"parameters", "gps.lever_arm", "error"}, "min")).value(), -0.04);
  EXPECT_DOUBLE_EQ(ResolveMetric(metrics, path({"parameters", "gps.lever_arm", "error"}, "1")).value(), -0.04);
  EXPECT_DOUBLE_EQ(ResolveMetric(metrics, path({"parameters", "odometer.kv_over_L", "relative_error"}, "")).value(),
                   0.0025);
  EXPECT_FALSE(ResolveMetric(metrics, path({"nees_mean"}, "")).ok());                            // null
  EXPECT_FALSE(ResolveMetric(metrics, path({"rpe_trans_m"}, "")).ok());                          // absent
  EXPECT_FALSE(ResolveMetric(metrics, path({"parameters", "gps.lever_arm", "error"}, "3")).ok());  // out of range

  const json runs = json::parse(R"({"runs": [{"ate_m": 0.5}, {"ate_m": 1.5}, {"ate_m": 1.0}]})");
  EXPECT_DOUBLE_EQ(ResolveMetric(runs, path({"runs", "ate_m"}, "max")).value(), 1.5);
  EXPECT_DOUBLE_EQ(ResolveMetric(runs, path({"runs", "ate_m"}, "mean")).value(), 1.0);
}

}  // namespace
}  // namespace roamlab::apps::regress
