// Regression suites: the bound grammar, metric paths against the outputs' schemas, and one clear line for each kind
// of bad suite file.
#include "regress/suite.h"

#include <algorithm>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/recording/temp_dir.h"
#include "tests/support/paths.h"

namespace roamlab::regress {
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
      {"<= 0.5 * metrics.velocity.encoders_only.linear_rmse", Bound::Comparator::kLessEqual, false, 1.0},
      {"<= table.rows[model=nominal].ate_m - 0.5", Bound::Comparator::kLessEqual, false, 1.5},
  };
  for (const Case& c : cases) {
    const Result<Bound> b = ParseBound(c.text);
    ASSERT_TRUE(b.ok()) << c.text << ": " << b.status().message();
    EXPECT_EQ(b.value().comparator, c.comparator) << c.text;
    EXPECT_EQ(b.value().uses_baseline, c.uses_baseline) << c.text;
    EXPECT_DOUBLE_EQ(b.value().Threshold(2.0), c.threshold_at_2) << c.text;
    EXPECT_EQ(b.value().text, c.text);
  }
  EXPECT_EQ(ParseBound("<= 0.5 * metrics.velocity.encoders_only.linear_rmse").value().reference,
            "metrics.velocity.encoders_only.linear_rmse");
  EXPECT_EQ(ParseBound("<= table.rows[model=nominal].ate_m - 0.5").value().reference,
            "table.rows[model=nominal].ate_m");
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
                           "<= baseline + ", "<= baseline * 2", "<= - baseline", "<= nan", "<= inf", "<= 1e308",
                           "<= -9.2e18", "<= 2e9 * baseline", "<= baseline + 1.5e9"}) {
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
  static std::string Scenario(const std::string& name) { return roamlab::testing::SourceDir() + "/scenarios/" + name; }
  static std::string Config(const std::string& name) { return roamlab::testing::SourceDir() + "/configs/" + name; }
  std::string CalibrateCase(const std::string& checks, const std::string& extra = "") {
    return "  - name: cal\n    mode: calibrate\n    scenario: " + Scenario("atv_hills.yaml") +
           "\n    seed: 3\n    config: " + Config("atv_calibration.yaml") + "\n" + extra + "    checks:\n" + checks;
  }
  std::string Odometry(const std::string& checks, const std::string& models = "    models: [{model: gp}]\n") {
    return "  - name: cal\n    mode: odometry\n    train: [a.csv]\n    test: [b.csv]\n" + models + "    checks:\n" +
           checks;
  }
  std::string Diagnose(const std::string& extra) {
    return "  - name: cal\n    mode: diagnose\n    scenario: " + Scenario("atv_hills.yaml") + "\n" + extra +
           "    checks:\n      - {metric: gap.verdict, equals: named}\n";
  }
  testing::TempDir dir_;
};

// Odometry and diagnose cases: inputs, models, effects; row selectors, texts, references to other metrics and
// open targets in checks; a case whose data directory is absent loads (it is skipped when run).
TEST_F(SuiteTest, LoadsOdometryAndDiagnoseCasesWithSelectorsTextsAndOpenTargets) {
  const std::string path = WriteSuite(
      "  - name: odo\n    mode: odometry\n    data: no_such_data\n    train: [\"diff/square/*.csv\", rec]\n"
      "    test: [\"diff/circular/*.csv\"]\n    interval_s: 0.25\n"
      "    models: [{model: linear}, {model: gp, mean: linear, kernel: rbf+linear}]\n    checks:\n"
      "      - {metric: \"table.rows[model=gp,mean=linear,kernel=rbf+linear].ate_m\",\n"
      "         bound: \"<= 0.5 * table.rows[model=nominal].ate_m\", open: \"odometry target\"}\n"
      "      - {metric: table.rows.ate_m.max, bound: \"<= 1\"}\n"
      "  - name: gap\n    mode: diagnose\n    scenario: " +
      Scenario("atv_hills.yaml") +
      "\n    seed: 13\n"
      "    effects: [{name: steering_offset, offset_rad: 0.03}]\n    checks:\n"
      "      - {metric: gap.verdict, equals: named}\n"
      "      - {metric: \"gap.effects[name=steering_offset].parameters.offset_rad\", bound: \"<= 0.035\"}\n");
  const Result<Suite> suite = LoadSuite(path);
  ASSERT_TRUE(suite.ok()) << suite.status().message();
  const Case& odo = suite.value().cases[0];
  EXPECT_EQ(odo.data, dir_.File("no_such_data"));
  EXPECT_EQ(odo.train,
            (std::vector<std::string>{dir_.File("no_such_data/diff/square/*.csv"), dir_.File("no_such_data/rec")}));
  ASSERT_EQ(odo.models.size(), 2u);
  EXPECT_EQ(odo.models[1].kernel, "rbf+linear");
  EXPECT_EQ(odo.interval_s, 0.25);
  const Check& ratio = odo.checks[0];
  EXPECT_EQ(ratio.metric.keys, (std::vector<std::string>{"rows", "ate_m"}));
  EXPECT_EQ(ratio.metric.select.at(0), (Selector{{"model", "gp"}, {"mean", "linear"}, {"kernel", "rbf+linear"}}));
  EXPECT_EQ(ratio.open, "odometry target");
  ASSERT_TRUE(ratio.reference.has_value());
  EXPECT_EQ(ratio.reference->select.at(0), (Selector{{"model", "nominal"}}));
  EXPECT_DOUBLE_EQ(ratio.bound.Threshold(0.1), 0.05);
  EXPECT_TRUE(odo.checks[1].open.empty());
  const Case& gap = suite.value().cases[1];
  ASSERT_EQ(gap.effects.size(), 1u);
  EXPECT_EQ(gap.effects[0].first, "steering_offset");
  EXPECT_EQ(gap.effects[0].second.at("offset_rad"), 0.03);
  EXPECT_TRUE(gap.checks[0].metric.is_string);
  EXPECT_EQ(gap.checks[0].equals, "named");
  EXPECT_EQ(gap.checks[1].metric.keys, (std::vector<std::string>{"effects", "parameters", "offset_rad"}));
}

TEST_F(SuiteTest, LoadsCasesWithTheirChecks) {
  const std::string path = WriteSuite(
      CalibrateCase("      - {metric: metrics.parameters.gps.lever_arm.error.norm, bound: \"<= 0.10\"}\n"
                    "      - {metric: metrics.parameters.odometer.kv_over_L.relative_error, bound: \"<= 0.005\"}\n"
                    "      - {metric: metrics.ate_m, bound: \"<= 1.10 * baseline\"}\n"
                    "      - {metric: calibration.measurements.gps.rejected, bound: \"<= 3\"}\n",
                    "    quick: true\n") +
      "  - name: mc\n    mode: montecarlo\n    scenario: " + Scenario("atv_hills.yaml") +
      "\n    config: " + Config("atv_tracking.yaml") +
      "\n    runs: 4\n    checks:\n"
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

// Cases that name the same scenario and configuration as earlier ones (each file is loaded once per suite): every
// case's metrics are checked against its own configuration's parameters.
TEST_F(SuiteTest, EachCaseIsCheckedAgainstItsOwnConfigurationWhenFilesRepeat) {
  const std::string lever_arm = "      - {metric: metrics.parameters.gps.lever_arm.error.norm, bound: \"<= 0.1\"}\n";
  const auto Named = [&](const std::string& name, const std::string& config) {
    return "  - name: " + name + "\n    mode: calibrate\n    scenario: " + Scenario("atv_hills.yaml") +
           "\n    config: " + Config(config) + "\n    checks:\n" + lever_arm;
  };
  const std::string repeated = Named("first", "atv_calibration.yaml") + Named("second", "atv_calibration.yaml");
  const Result<Suite> suite = LoadSuite(WriteSuite(repeated));
  ASSERT_TRUE(suite.ok()) << suite.status().message();
  EXPECT_EQ(suite.value().cases[1].checks[0].metric.keys,
            (std::vector<std::string>{"parameters", "gps.lever_arm", "error"}));

  // The indoor configuration has no GPS: its case's lever-arm check is refused, after two that hold it.
  const Result<Suite> mixed =
      LoadSuite(WriteSuite(repeated + Named("indoor", "indoor_diffdrive_mocap_calibration.yaml")));
  ASSERT_FALSE(mixed.ok());
  EXPECT_NE(mixed.status().message().find("case 'indoor'"), std::string::npos) << mixed.status().message();
  EXPECT_NE(mixed.status().message().find("does not start with a parameter"), std::string::npos)
      << mixed.status().message();
}

// A case with an external estimator: its command kept as written, run in the suite file's directory.
TEST_F(SuiteTest, LoadsExternalCommandCases) {
  const std::string path =
      WriteSuite("  - name: dr\n    mode: montecarlo\n    scenario: " + Scenario("atv_hills.yaml") +
                 "\n    command: \"sh ../dr.sh {recording} {out}\"\n    timeout_s: 30\n"
                 "    runs: 2\n    checks:\n"
                 "      - {metric: runs.runs.ate_m.max, bound: \"<= 1\"}\n");
  const Result<Suite> suite = LoadSuite(path);
  ASSERT_TRUE(suite.ok()) << suite.status().message();
  const Case& c = suite.value().cases[0];
  EXPECT_EQ(c.command, "sh ../dr.sh {recording} {out}");
  EXPECT_EQ(c.command_dir, dir_.path());
  EXPECT_EQ(c.timeout_s, 30.0);
  EXPECT_TRUE(c.config.empty());
}

TEST_F(SuiteTest, EachKindOfBadSuiteIsOneLineNamingFileCaseAndProblem) {
  const std::string check = "      - {metric: metrics.ate_m, bound: \"<= 1\"}\n";
  struct Bad {
    std::string cases;
    std::string problem;
  };
  const std::string hills = Scenario("atv_hills.yaml"), cal = Config("atv_calibration.yaml");
  const std::string tracking = Config("atv_tracking.yaml");
  const auto Track = [&](const std::string& estimator, const std::string& checks) {
    return "  - name: cal\n    mode: track\n    scenario: " + hills + "\n" + estimator + "    checks:\n" + checks;
  };
  const Bad bad[] = {
      {CalibrateCase("      - {metric: metrics.ate_meters, bound: \"<= 1\"}\n"), "unknown key 'ate_meters'"},
      {CalibrateCase("      - {metric: metrics.parameters.gps.lever_arm.eror.norm, bound: \"<= 1\"}\n"),
       "unknown key 'eror'"},
      {CalibrateCase("      - {metric: metrics.parameters.wheel.radius.error.0, bound: \"<= 1\"}\n"),
       "does not start with a parameter"},
      {CalibrateCase("      - {metric: metrics.parameters.gps.lever_arm.error, bound: \"<= 1\"}\n"), "is an array"},
      {CalibrateCase("      - {metric: metrics.ate_m.norm, bound: \"<= 1\"}\n"), "is a number"},
      {CalibrateCase("      - {metric: nees.fraction_in_band, bound: \"<= 1\"}\n"), "writes no output 'nees'"},
      {CalibrateCase("      - {metric: calibration.solver.seconds, bound: \"<= 1\"}\n"), "timing value"},
      {CalibrateCase("      - {metric: metrics.ate_m, bound: \"<= fast\"}\n"), "bound '<= fast'"},
      {CalibrateCase("      - {metric: metrics.ate_m, bound: \"0.5\"}\n"), "must start with"},
      {CalibrateCase("      - {metric: metrics.ate_m}\n"), "a check is {metric: PATH, bound: BOUND}"},
      {CalibrateCase(""), "no 'checks'"},
      {CalibrateCase(check, "    window: 3\n"), "unknown key 'window'"},
      {CalibrateCase(check, "    quick: maybe\n"), "malformed value"},
      {CalibrateCase(check, "    faults: [{type: outage, stream: lidar, start_s: 1, duration_s: 2}]\n"),
       "no stream 'lidar'"},
      {CalibrateCase(check, "    faults: [{type: outage, stream: gps, start_s: 1, size: 2}]\n"), "has no key size"},
      {CalibrateCase(check, "    faults: [{type: outage, stream: gps, start_s: 1}]\n"), "needs duration_s"},
      {CalibrateCase(check, "    faults: [{type: clock_jump, stream: gps, at_s: 1, jump_s: -1}]\n"), "backward jump"},
      {"  - name: cal\n    mode: calbrate\n    checks:\n" + check, "unknown mode 'calbrate'"},
      {"  - name: cal\n    mode: odometry\n    checks:\n" + check, "mode odometry needs 'train'"},
      {"  - name: cal\n    mode: diagnose\n    checks:\n" + check, "mode diagnose needs 'scenario'"},
      {Odometry("      - {metric: table.rows.ate_m, bound: \"<= 1\"}\n", "    models: [{model: svm}]\n"),
       "bad model entry 'model: svm'"},
      {Odometry("      - {metric: table.rows.ate_m, bound: \"<= 1\"}\n", "    models: [{model: linear, mean: zero}]\n"),
       "mean and kernel are options of the gp model only"},
      {Odometry("      - {metric: \"table.rows[mdl=gp].ate_m\", bound: \"<= 1\"}\n"), "no text field 'mdl'"},
      {Odometry("      - {metric: \"table.rows[model].ate_m\", bound: \"<= 1\"}\n"), "is not FIELD=VALUE"},
      {Odometry("      - {metric: \"table.rows[model=gp].model\", bound: \"<= 1\"}\n"), "is a text: check it with"},
      {Odometry("      - {metric: table.rows.model, equals: gp}\n"), "column of texts"},
      {Odometry("      - {metric: table.interval_s, equals: gp}\n"), "is a number: give a bound"},
      {Odometry("      - {metric: table.interval_s, bound: \"<= 1\", equals: gp}\n"), "a check is"},
      {Odometry("      - {metric: table.interval_s, bound: \"<= 1\", open: \"\"}\n"), "'open' needs the reason"},
      {Odometry("      - {metric: table.interval_s, bound: \"<= 1\", opne: x}\n"), "a check is"},
      {Odometry("      - {metric: table.interval_s, bound: \"<= 2 * table.rows[model=gp].ate\"}\n"),
       "unknown key 'ate'"},
      {Odometry("      - {metric: table.interval_s, bound: \"<= 2 * table.rows[model=gp].model\"}\n"), "is a text"},
      {Diagnose("    effects: [{name: steering_ofset, offset_rad: 0.03}]\n"), "unknown effect 'steering_ofset'"},
      {Diagnose("    effects: [{name: steering_offset, offset: 0.03}]\n"), "has no parameter offset"},
      {Diagnose("    effects: [{name: steering_offset, offset_rad: big}]\n"), "is not a number"},
      {Diagnose("    effects: [{name: steering_offset, offset_rad: 9.2e18}]\n"), "beyond any physical value"},
      {CalibrateCase("      - {metric: metrics.ate_m, bound: \"<= 1e308\"}\n"), "beyond any metric"},
      {"  - name: cal\n    mode: calibrate\n    scenario: nowhere.yaml\n    config: " + cal + "\n    checks:\n" + check,
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
      {"  - name: cal\n    mode: montecarlo\n    scenario: " + hills + "\n    config: " + cal +
           "\n    runs: 2\n    t0_s: .nan\n    checks:\n      - {metric: nees.fraction_in_band, bound: \">= 0.9\"}\n",
       "t0_s must be finite"},
      {CalibrateCase(check) + CalibrateCase(check), "a second case of this name"},
      {Track("    config: " + tracking + "\n    command: prog\n", check), "exactly one of 'config' and 'command'"},
      {Track("", check), "exactly one of 'config' and 'command'"},
      {Track("    command: prog\n    calibrate: " + cal + "\n", check), "an external 'command' calibrates itself"},
      {Track("    config: " + tracking + "\n    timeout_s: 5\n", check), "'timeout_s' is for a 'command'"},
      {Track("    command: prog\n    timeout_s: 0\n", check), "timeout_s must be positive"},
      {Track("    command: \" \"\n", check), "the estimator command is empty"},
      {Track("    command: prog\n", "      - {metric: summary.poses, bound: \">= 1\"}\n"),
       "an external command writes no summary.json"},
      {CalibrateCase(check, "    command: prog\n"), "unknown key 'command' for mode calibrate"},
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
                                  std::string("cases:\n  - {name: a\n"), std::string("cases: 3\nextra: 1\n"),
                                  // A key that is a list or a map (the fuzzer's find: an exception escaped).
                                  std::string("? [suite, x]\n: 1\ncases: []\n"),
                                  std::string("cases:\n  - name: a\n    ? {mode: track}\n    : 1\n")}) {
    const std::string path = dir_.File("suite.yaml");
    testing::WriteFile(path, text);
    const Result<Suite> suite = LoadSuite(path);
    ASSERT_FALSE(suite.ok()) << text;
    EXPECT_EQ(suite.status().message().rfind(path, 0), 0u) << suite.status().message();
    EXPECT_EQ(suite.status().message().find('\n'), std::string::npos) << suite.status().message();
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
  EXPECT_FALSE(ResolveMetric(metrics, path({"nees_mean"}, "")).ok());                              // null
  EXPECT_FALSE(ResolveMetric(metrics, path({"rpe_trans_m"}, "")).ok());                            // absent
  EXPECT_FALSE(ResolveMetric(metrics, path({"parameters", "gps.lever_arm", "error"}, "3")).ok());  // out of range

  const json runs = json::parse(R"({"runs": [{"ate_m": 0.5}, {"ate_m": 1.5}, {"ate_m": 1.0}]})");
  EXPECT_DOUBLE_EQ(ResolveMetric(runs, path({"runs", "ate_m"}, "max")).value(), 1.5);
  EXPECT_DOUBLE_EQ(ResolveMetric(runs, path({"runs", "ate_m"}, "mean")).value(), 1.0);
}

TEST(ResolveMetricTest, SelectsOneRowByItsTextFields) {
  const json table = json::parse(R"({"rows": [
    {"model": "nominal", "mean": null, "kernel": null, "ate_m": 0.09},
    {"model": "linear", "mean": null, "kernel": null, "ate_m": 0.02},
    {"model": "gp", "mean": "linear", "kernel": "rbf", "ate_m": 0.03},
    {"model": "gp", "mean": "zero", "kernel": "rbf", "ate_m": 0.18}]})");
  const auto path = [](Selector selector, std::string leaf) {
    MetricPath p;
    p.output = "table";
    p.keys = {"rows", std::move(leaf)};
    p.select[0] = std::move(selector);
    return p;
  };
  EXPECT_DOUBLE_EQ(ResolveMetric(table, path({{"model", "nominal"}}, "ate_m")).value(), 0.09);
  EXPECT_DOUBLE_EQ(ResolveMetric(table, path({{"model", "gp"}, {"mean", "zero"}}, "ate_m")).value(), 0.18);
  EXPECT_DOUBLE_EQ(ResolveMetric(table, path({{"model", "linear"}, {"kernel", "null"}}, "ate_m")).value(), 0.02);
  const Result<double> two = ResolveMetric(table, path({{"model", "gp"}}, "ate_m"));
  ASSERT_FALSE(two.ok());
  EXPECT_NE(two.status().message().find("2 rows match [model=gp]"), std::string::npos) << two.status().message();
  EXPECT_FALSE(ResolveMetric(table, path({{"model", "parametric"}}, "ate_m")).ok());
  EXPECT_EQ(ResolveText(table, path({{"model", "gp"}, {"mean", "zero"}}, "kernel")).value(), "rbf");
  EXPECT_FALSE(ResolveText(table, path({{"model", "nominal"}}, "mean")).ok());  // null: not a text
  EXPECT_FALSE(ResolveText(table, path({{"model", "nominal"}}, "ate_m")).ok());

  const json gap = json::parse(R"({"verdict": "named", "effects": [{"name": "gps_latency",
                                   "parameters": {"latency_s": 0.43}}]})");
  MetricPath verdict;
  verdict.output = "gap";
  verdict.keys = {"verdict"};
  EXPECT_EQ(ResolveText(gap, verdict).value(), "named");
  MetricPath latency;
  latency.output = "gap";
  latency.keys = {"effects", "parameters", "latency_s"};
  latency.select[0] = {{"name", "gps_latency"}};
  EXPECT_DOUBLE_EQ(ResolveMetric(gap, latency).value(), 0.43);
  latency.select[0] = {{"name", "steering_offset"}};
  EXPECT_FALSE(ResolveMetric(gap, latency).ok());  // not named: an error of the check, never a pass
}

}  // namespace
}  // namespace roamlab::regress
