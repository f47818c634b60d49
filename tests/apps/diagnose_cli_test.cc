// `roamlab diagnose` end to end on short simulated drives: it never opens the recording's truth.yaml (garbage there
// changes nothing), writes gap.json with the documented keys, and refuses a recording of another robot kind with one
// line and exit code 2, as it does a time-shift range the recording cannot hold; a recording of another drive than the
// scenario's is replayed (detected, or forced with --replay; --no-replay forces the plain simulation), gap.json's
// "simulation" says which and why and report.html shows the twin's figures; --twin diagnoses it against the replay of
// that drive; --held-out shows the twin's patch on a recording of another drive.
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "eval/plots.h"
#include "tests/recording/temp_dir.h"
#include "tests/support/html_check.h"
#include "tests/support/paths.h"

namespace roamlab {
namespace {

std::string Source(const std::string& relative) { return roamlab::testing::SourceDir() + "/" + relative; }

using testing::CommandRun;

CommandRun Roamlab(const std::string& args, const testing::TempDir& dir) {
  return testing::RunCommand(std::string(ROAMLAB_BINARY) + " " + args, dir.path());
}

// atv_hills.yaml shortened to `duration_s` with `effects` as its effects section, written into dir.
std::string Scenario(const testing::TempDir& dir, double duration_s, const std::string& effects) {
  std::string text = testing::ReadFile(Source("scenarios/atv_hills.yaml"));
  const auto replace = [&text](const std::string& a, const std::string& b) {
    const std::size_t at = text.find(a);
    EXPECT_NE(at, std::string::npos) << a;
    if (at != std::string::npos) text.replace(at, a.size(), b);
  };
  replace("model: ../models/atv.xml", "model: " + Source("models/atv.xml"));
  replace("duration_s: 30.0", "duration_s: " + std::to_string(duration_s));
  replace("effects: []", "effects: " + effects);
  const std::string path = dir.File("scenario.yaml");
  testing::WriteFile(path, text);
  return path;
}

TEST(DiagnoseCliTest, NeverOpensTruthYamlAndWritesGapJson) {
  testing::TempDir dir;
  const std::string scenario = Scenario(dir, 6.0, "[{name: steering_offset, parameters: {offset_rad: 0.03}}]");
  ASSERT_EQ(Roamlab("simulate " + scenario + " --out " + dir.File("rec") + " --quiet", dir).exit_code, 0);
  // What a reader of truth.yaml would refuse (and what would give the effect away).
  testing::WriteFile(dir.File("rec/truth.yaml"), "{{{ not yaml: [steering_offset");
  const CommandRun run =
      Roamlab("diagnose --real " + dir.File("rec") + " --scenario " + Source("scenarios/atv_hills.yaml") + " --out " +
                  dir.File("out") + " --no-baseline --quiet",
              dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  std::ifstream in(dir.File("out/gap.json"));
  ASSERT_TRUE(in.good());
  const nlohmann::json gap = nlohmann::json::parse(in);
  for (const char* key : {"verdict", "located", "effects", "fit", "candidates"}) EXPECT_TRUE(gap.contains(key)) << key;
  EXPECT_TRUE(gap["fit"].contains("before"));
  EXPECT_TRUE(gap["fit"].contains("after"));
  EXPECT_TRUE(gap["fit"]["before"].contains("odometer"));
  const std::string verdict = gap["verdict"].get<std::string>();
  EXPECT_TRUE(verdict == "named" || verdict == "unknown" || verdict == "none") << verdict;
  // The ATV's: gps_latency, imu_time_offset, steering_offset, gyro_scale_error, gyro_bias_drift, lateral_slip,
  // magnetometer_motor_interference, longitudinal_slip, slope_slip (not axle_misalignment: the nominal model's IMU
  // misalignment is free).
  EXPECT_EQ(gap["candidates"].size(), 9u);
  EXPECT_TRUE(std::ifstream(dir.File("out/report.md")).good());
  EXPECT_TRUE(std::ifstream(dir.File("out/scenario_patch.yaml")).good());
  // The figures are drawn from complete data files (each flushed before gnuplot reads it).
  if (eval::GnuplotAvailable()) {
    const std::string report = testing::ReadFile(dir.File("out/report.md"));
    EXPECT_NE(report.find("![heldout_fit.png]"), std::string::npos) << report;
    EXPECT_GT(std::filesystem::file_size(dir.File("out/heldout_fit.png")), 0u);
  }
  // report.html: well-formed, the verdict first, the held-out fit before/after and the candidates, figures embedded.
  const std::string page = testing::ReadFile(dir.File("out/report.html"));
  const testing::HtmlSummary html = testing::CheckHtml(page);
  ASSERT_EQ(html.error, "");
  EXPECT_LT(page.find("Verdict: " + verdict), page.find("<table>"));
  ASSERT_GE(html.table_headers.size(), 3u);
  EXPECT_EQ(html.table_headers[0].front(), "stream");
  EXPECT_EQ(html.table_headers[0].back(), "chi2/dof after");
  EXPECT_EQ(html.table_headers[1].front(), "effect");
  EXPECT_EQ(html.table_headers[2].front(), "stream[component]");
  if (eval::GnuplotAvailable()) {
    ASSERT_FALSE(html.image_sources.empty());
    for (const std::string& src : html.image_sources) {
      ASSERT_EQ(src.rfind("data:image/png;base64,", 0), 0u);
      EXPECT_TRUE(testing::DecodeBase64(src.substr(22)).has_value());
    }
  }
  // The re-simulation as believed sees the hidden offset in the steering stream: 0.03 rad on a sensor of 0.014 rad
  // noise is a whitened RMS of sqrt(1 + (0.03 / 0.014)^2) = 2.36 (over 200 samples: +-0.05).
  ASSERT_TRUE(gap.contains("simulation") && gap["simulation"].contains("before")) << gap.dump();
  const nlohmann::json& steering = gap["simulation"]["before"]["steering"];
  EXPECT_NEAR(steering["rms"].get<double>(), 2.36, 0.2) << steering.dump();
  EXPECT_GT(steering["samples"].get<int>(), 100);
}

TEST(DiagnoseCliTest, RefusesARecordingOfAnotherRobotKind) {
  testing::TempDir dir;
  const std::string scenario = Scenario(dir, 1.0, "[]");
  ASSERT_EQ(Roamlab("simulate " + scenario + " --out " + dir.File("rec") + " --quiet", dir).exit_code, 0);
  const CommandRun run = Roamlab("diagnose --real " + dir.File("rec") + " --scenario " +
                                     Source("scenarios/indoor_diffdrive_slip.yaml") + " --out " + dir.File("out"),
                                 dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("roamlab diagnose: " + dir.File("rec") +
                         ": platform kind 'ackermann' does not match the robot kind 'differential_drive'"),
            std::string::npos)
      << run.err;
  EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1);
  EXPECT_FALSE(std::ifstream(dir.File("out/gap.json")).good());
}

// A scenario with effects (one patched with a diagnosis's scenario_patch.yaml) is not the nominal model: refused, not
// run without them.
TEST(DiagnoseCliTest, RefusesAScenarioWithEffects) {
  testing::TempDir dir;
  ASSERT_EQ(Roamlab("simulate " + Scenario(dir, 1.0, "[]") + " --out " + dir.File("rec") + " --quiet", dir).exit_code,
            0);
  const std::string patched = Scenario(dir, 1.0, "[{name: steering_offset, parameters: {offset_rad: 0.03}}]");
  const CommandRun run =
      Roamlab("diagnose --real " + dir.File("rec") + " --scenario " + patched + " --out " + dir.File("out"), dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("roamlab diagnose: " + patched + ": has effects (steering_offset); diagnose compares"),
            std::string::npos)
      << run.err;
  EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1);
  EXPECT_FALSE(std::ifstream(dir.File("out/gap.json")).good());
}

TEST(DiagnoseCliTest, RefusesAShiftRangeTheRecordingCannotHold) {
  testing::TempDir dir;
  const std::string scenario = Scenario(dir, 1.5, "[]");
  ASSERT_EQ(Roamlab("simulate " + scenario + " --out " + dir.File("rec") + " --quiet", dir).exit_code, 0);
  for (const std::string shift : {"0.5", "0"}) {
    const CommandRun run = Roamlab("diagnose --real " + dir.File("rec") + " --scenario " + scenario + " --out " +
                                       dir.File("out") + " --max-shift " + shift,
                                   dir);
    EXPECT_EQ(run.exit_code, 2) << shift;
    // The limit is 1/12 of the 1.5 s span, about 0.125 s.
    EXPECT_NE(run.err.find("roamlab diagnose: --max-shift " + shift + " s: must be above 0 and below 0.12"),
              std::string::npos)
        << run.err;
    EXPECT_NE(run.err.find(" s, 1/12 of " + dir.File("rec") + "'s span"), std::string::npos) << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1);
    EXPECT_FALSE(std::ifstream(dir.File("out/gap.json")).good());
  }
}

// indoor_diffdrive_gap.yaml shortened to `duration_s` with its turn-rate profile's amplitude `turn_radps`, written to
// `name`.
std::string DiffDrive(const testing::TempDir& dir, const std::string& turn_radps, const std::string& name,
                      const std::string& duration_s = "3.0") {
  std::string text = testing::ReadFile(Source("scenarios/indoor_diffdrive_gap.yaml"));
  for (const auto& [a, b] : std::vector<std::pair<std::string, std::string>>{
           {"model: ../models/diffdrive.xml", "model: " + Source("models/diffdrive.xml")},
           {"duration_s: 30.0", "duration_s: " + duration_s},
           {"amplitude: 0.6, period_s: 11.0", "amplitude: " + turn_radps + ", period_s: 11.0"}}) {
    const std::size_t at = text.find(a);
    EXPECT_NE(at, std::string::npos) << a;
    if (at != std::string::npos) text.replace(at, a.size(), b);
  }
  testing::WriteFile(dir.File(name), text);
  return dir.File(name);
}

TEST(DiagnoseCliTest, TheTwinOfARecordingOfAnotherDriveIsItsReplay) {
  testing::TempDir dir;
  // Long enough for the estimator's held-out part.
  const std::string nominal = DiffDrive(dir, "0.6", "nominal.yaml", "9.0");
  const std::string other = DiffDrive(dir, "-0.6", "other.yaml", "9.0");
  ASSERT_EQ(Roamlab("simulate " + other + " --out " + dir.File("rec") + " --quiet", dir).exit_code, 0);
  const CommandRun run = Roamlab("diagnose --real " + dir.File("rec") + " --scenario " + nominal + " --out " +
                                     dir.File("out") + " --twin --no-baseline",
                                 dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("other drive detected"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("the twin replays the recorded drive"), std::string::npos) << run.out;
  std::ifstream in(dir.File("out/twin.json"));
  ASSERT_TRUE(in.good());
  const nlohmann::json twin = nlohmann::json::parse(in);
  EXPECT_TRUE(twin.at("replayed").get<bool>());
  // --std auto on a simulated recording: the white std is reported, the HAC one beside it.
  EXPECT_EQ(twin.at("std_method"), "white");
  ASSERT_FALSE(twin.at("candidates").empty());
  for (const nlohmann::json& c : twin.at("candidates")) {
    if (!c.contains("std") || c.at("std").empty()) continue;  // a candidate that was not fitted
    for (const auto& [name, value] : c.at("std").items()) {
      EXPECT_EQ(value, c.at("std_white").at(name)) << c.at("name");
      EXPECT_TRUE(c.at("std_hac").contains(name)) << c.at("name");
    }
  }
}

// The drive's clock named as a twin candidate of a recording of the scenario's own drive, whose twin is the plain
// simulation: one line naming the recording, exit 2, before any diagnosis; with --replay it is accepted.
TEST(DiagnoseCliTest, TheDriveClockNeedsAReplayedTwin) {
  testing::TempDir dir;
  const std::string nominal = DiffDrive(dir, "0.6", "nominal.yaml", "9.0");
  ASSERT_EQ(Roamlab("simulate " + nominal + " --out " + dir.File("rec") + " --quiet", dir).exit_code, 0);
  const std::string common = "diagnose --real " + dir.File("rec") + " --scenario " + nominal +
                             " --no-baseline --quiet --twin --twin-candidates drive_time_offset ";
  const CommandRun refused = Roamlab(common + "--out " + dir.File("bad"), dir);
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(refused.err.find("'drive_time_offset' shifts a replay's recorded drive inputs, and " + dir.File("rec") +
                             " is twinned by the plain simulation of its own drive"),
            std::string::npos)
      << refused.err;
  EXPECT_EQ(std::count(refused.err.begin(), refused.err.end(), '\n'), 1);
  EXPECT_FALSE(std::filesystem::exists(dir.File("bad/twin.json")));
  const CommandRun replayed = Roamlab(common + "--replay --no-plots --out " + dir.File("out"), dir);
  ASSERT_EQ(replayed.exit_code, 0) << replayed.err;
  std::ifstream in(dir.File("out/twin.json"));
  ASSERT_TRUE(in.good());
  const nlohmann::json twin = nlohmann::json::parse(in);
  ASSERT_EQ(twin.at("candidates").size(), 1u);
  EXPECT_EQ(twin.at("candidates")[0].at("name"), "drive_time_offset");
}

// scenarios/real/optiodom_diff.yaml (motion capture: the twin's drift is measured) shortened to `duration_s`, with its
// turn-rate amplitude `turn_radps` and `effects`, written to `name`.
std::string OptiOdomDiff(const testing::TempDir& dir, const std::string& turn_radps, const std::string& effects,
                         const std::string& name, const std::string& duration_s = "12.0") {
  std::string text = testing::ReadFile(Source("scenarios/real/optiodom_diff.yaml"));
  for (const auto& [a, b] : std::vector<std::pair<std::string, std::string>>{
           {"model: ../../models/optiodom_diff.xml", "model: " + Source("models/optiodom_diff.xml")},
           {"duration_s: 20.0", "duration_s: " + duration_s},
           {"amplitude: 0.14", "amplitude: " + turn_radps},
           {"effects: []", "effects: " + effects}}) {
    const std::size_t at = text.find(a);
    EXPECT_NE(at, std::string::npos) << a;
    if (at != std::string::npos) text.replace(at, a.size(), b);
  }
  testing::WriteFile(dir.File(name), text);
  return dir.File(name);
}

// A wheel radius 3 % large hidden in two drives: the patch fitted on the scenario's own drive is shown on a recording
// of another drive (replayed), where the patched twin's 10 s drift is well below the nominal twin's; gap.json names
// twin.json. A held-out or training recording without --twin is bad input, and so are a training recording of another
// robot kind and a twin candidate the scenario does not support.
TEST(DiagnoseCliTest, HeldOutShowsTheTwinsPatchOnARecordingOfAnotherDrive) {
  testing::TempDir dir;
  const std::string effect = "[{name: wheel_radius_scale, parameters: {scale: 1.03}}]";
  const std::string nominal = OptiOdomDiff(dir, "0.14", "[]", "nominal.yaml");
  ASSERT_EQ(
      Roamlab("simulate " + OptiOdomDiff(dir, "0.14", effect, "own.yaml") + " --out " + dir.File("rec") + " --quiet",
              dir)
          .exit_code,
      0);
  ASSERT_EQ(
      Roamlab("simulate " + OptiOdomDiff(dir, "-0.3", effect, "other.yaml") + " --out " + dir.File("held") + " --quiet",
              dir)
          .exit_code,
      0);
  const std::string common = "diagnose --real " + dir.File("rec") + " --scenario " + nominal + " --config " +
                             Source("configs/real/optiodom_diff_nominal.yaml") + " --no-baseline ";
  const CommandRun refused = Roamlab(common + "--out " + dir.File("bad") + " --held-out " + dir.File("held"), dir);
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(refused.err.find("--held-out needs --twin"), std::string::npos) << refused.err;
  // A training recording of another robot kind: one line naming it, exit 2, before any diagnosis.
  ASSERT_EQ(Roamlab("simulate " + Scenario(dir, 1.0, "[]") + " --out " + dir.File("atv") + " --quiet", dir).exit_code,
            0);
  const CommandRun other_kind =
      Roamlab(common + "--out " + dir.File("bad") + " --twin --quiet --train-with " + dir.File("atv"), dir);
  EXPECT_EQ(other_kind.exit_code, 2);
  EXPECT_NE(other_kind.err.find(dir.File("atv") + ": platform kind 'ackermann' does not match the robot kind "
                                                  "'differential_drive'"),
            std::string::npos)
      << other_kind.err;
  EXPECT_EQ(std::count(other_kind.err.begin(), other_kind.err.end(), '\n'), 1);
  const CommandRun no_twin = Roamlab(common + "--out " + dir.File("bad") + " --train-with " + dir.File("held"), dir);
  EXPECT_EQ(no_twin.exit_code, 2);
  EXPECT_NE(no_twin.err.find("--train-with needs --twin"), std::string::npos) << no_twin.err;
  const CommandRun bad_weight = Roamlab(
      common + "--out " + dir.File("bad") + " --twin --train-with " + dir.File("held") + " --train-weight equal", dir);
  EXPECT_EQ(bad_weight.exit_code, 2);
  EXPECT_NE(bad_weight.err.find("--train-weight equal: must be windows or runs"), std::string::npos) << bad_weight.err;
  const CommandRun unknown = Roamlab(
      common + "--out " + dir.File("bad") + " --twin --twin-candidates wheel_radius_scale gyro_scale_error", dir);
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_NE(unknown.err.find("'gyro_scale_error' is not a twin candidate of the scenario"), std::string::npos)
      << unknown.err;

  const CommandRun run =
      Roamlab(common + "--out " + dir.File("out") + " --twin --no-plots --held-out " + dir.File("held"), dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  std::ifstream in(dir.File("out/twin.json"));
  ASSERT_TRUE(in.good());
  const nlohmann::json twin = nlohmann::json::parse(in);
  ASSERT_EQ(twin.at("patch").size(), 1u) << twin.at("candidates").dump();
  EXPECT_EQ(twin.at("patch")[0].at("name"), "wheel_radius_scale");
  ASSERT_EQ(twin.at("heldout_runs").size(), 1u);
  const nlohmann::json& held = twin.at("heldout_runs")[0];
  EXPECT_EQ(held.at("recording"), dir.File("held"));
  EXPECT_TRUE(held.at("replayed").get<bool>());
  const double before = held.at("before").at("drift").at("mocap").at("mean_position_m").get<double>();
  const double after = held.at("after").at("drift").at("mocap").at("mean_position_m").get<double>();
  // 3 % of the 1 m a 10 s window travels, against a floor of about a millimetre (the windows align on their first 2 s
  // of motion capture).
  EXPECT_GT(before, 0.015);
  EXPECT_LT(after, 0.5 * before) << before << " -> " << after << "; patch " << twin.at("patch").dump();
  EXPECT_LT(held.at("after").at("chi2").get<double>(), held.at("before").at("chi2").get<double>());
  std::ifstream gap_in(dir.File("out/gap.json"));
  const nlohmann::json gap = nlohmann::json::parse(gap_in);
  // gap.json's "simulation" names twin.json rather than copying it, and runs the twin with its patch.
  EXPECT_FALSE(gap.contains("twin"));
  EXPECT_EQ(gap.at("simulation").at("twin_diagnosis"), "twin.json");
  EXPECT_FALSE(gap.at("simulation").at("replayed").get<bool>());
  EXPECT_EQ(gap.at("simulation").at("effects"), twin.at("patch"));

  // The twin's values are the accepted ones: the summary and the report lead with its verdict, and scenario_patch.yaml
  // is its patch, which a scenario takes as its effects as it is.
  EXPECT_EQ(run.out.rfind("twin verdict: named; wheel_radius_scale scale = "),
            run.out.rfind("\n", run.out.size() - 2) + 1)
      << run.out;
  const std::string report = testing::ReadFile(dir.File("out/report.md"));
  EXPECT_LT(report.find("## Verdict against the twin: **named**"), report.find("## Estimator-side verdict"));
  // Its candidates, round by round, come before the estimator side's.
  EXPECT_NE(report.find("| 1 | wheel_radius_scale | scale = "), std::string::npos) << report;
  EXPECT_LT(report.find("## The twin diagnosis"), report.find("## Estimator side: candidates"));
  const std::string patch = testing::ReadFile(dir.File("out/scenario_patch.yaml"));
  const std::string entry = "  - name: wheel_radius_scale\n    parameters:\n      scale: ";
  ASSERT_NE(patch.find(entry), std::string::npos) << patch;
  EXPECT_NEAR(std::stod(patch.substr(patch.find(entry) + entry.size())),
              twin.at("patch")[0].at("parameters").at("scale").get<double>(), 1e-9)
      << patch;
  std::string patched = testing::ReadFile(nominal);
  const std::size_t at = patched.find("effects: []");
  ASSERT_NE(at, std::string::npos);
  patched.replace(at, std::string("effects: []").size(), patch.substr(patch.find("\neffects:") + 1));
  testing::WriteFile(dir.File("patched.yaml"), patched);
  const CommandRun simulated =
      Roamlab("simulate " + dir.File("patched.yaml") + " --out " + dir.File("patched") + " --quiet", dir);
  EXPECT_EQ(simulated.exit_code, 0) << simulated.err;
  const std::string truth = testing::ReadFile(dir.File("patched/truth.yaml"));
  EXPECT_NE(truth.find("wheel_radius_scale"), std::string::npos) << truth;
}

// A recording of another drive of the OptiOdom differential drive (motion capture): detected and replayed, gap.json's
// "simulation" says why and gives the twins' held-out drift, and report.html embeds the twin's top view and its
// residual against a motion condition; --no-replay forces the plain simulation, and --replay with it is refused.
TEST(DiagnoseCliTest, TheReportShowsTheTwinAgainstTheRecording) {
  testing::TempDir dir;
  // 33 s: the held-out third holds two 10 s drift windows.
  const std::string nominal = OptiOdomDiff(dir, "0.14", "[]", "nominal.yaml", "33.0");
  const std::string effect = "[{name: wheel_radius_scale, parameters: {scale: 1.03}}]";
  ASSERT_EQ(Roamlab("simulate " + OptiOdomDiff(dir, "-0.3", effect, "other.yaml", "33.0") + " --out " +
                        dir.File("rec") + " --quiet",
                    dir)
                .exit_code,
            0);
  const std::string common = "diagnose --real " + dir.File("rec") + " --scenario " + nominal + " --config " +
                             Source("configs/real/optiodom_diff_nominal.yaml") + " --no-baseline --quiet ";
  const auto simulation = [&](const std::string& out) {
    std::ifstream in(dir.File(out + "/gap.json"));
    return nlohmann::json::parse(in).at("simulation");
  };
  ASSERT_EQ(Roamlab(common + "--out " + dir.File("out"), dir).exit_code, 0);
  const nlohmann::json detected = simulation("out");
  EXPECT_TRUE(detected.at("replayed").get<bool>()) << detected.dump();
  EXPECT_EQ(detected.at("twin").at("reason"), "other drive detected");
  EXPECT_GT(detected.at("twin").at("drive_mismatch").get<double>(), detected.at("twin").at("max_drive_mismatch"));
  EXPECT_TRUE(detected.at("twin_diagnosis").is_null());
  const nlohmann::json& drift = detected.at("drift").at("mocap");
  // The 3 % larger wheels drive (0.1 m/s) and turn (0.3 rad/s) 3 % more than the nominal twin over the 8 s of each
  // window after its 2 s alignment: 24 mm and 0.072 rad; at least half of each.
  EXPECT_GT(drift.at("before").at("mean_position_m").get<double>(), 0.5 * 0.024) << drift.dump();
  EXPECT_GT(drift.at("before").at("mean_heading_rad").get<double>(), 0.5 * 0.072) << drift.dump();
  const std::string page = testing::ReadFile(dir.File("out/report.html"));
  const testing::HtmlSummary html = testing::CheckHtml(page);
  ASSERT_EQ(html.error, "");
  EXPECT_NE(page.find("The twin replays the recorded drive"), std::string::npos);
  if (eval::GnuplotAvailable()) {
    for (const char* figure : {"twin_top_view.png", "twin_residual_vs_condition.png"}) {
      const std::size_t at = page.find(std::string("<figcaption>") + figure + "</figcaption>");
      EXPECT_NE(at, std::string::npos) << figure;
      EXPECT_GT(std::filesystem::file_size(dir.File(std::string("out/") + figure)), 0u) << figure;
    }
    for (const std::string& src : html.image_sources) {
      ASSERT_EQ(src.rfind("data:image/png;base64,", 0), 0u);
      EXPECT_TRUE(testing::DecodeBase64(src.substr(22)).has_value());
    }
    EXPECT_NE(testing::ReadFile(dir.File("out/report.md")).find("![twin_top_view.png](twin_top_view.png)"),
              std::string::npos);
  }

  ASSERT_EQ(Roamlab(common + "--no-plots --no-replay --out " + dir.File("plain"), dir).exit_code, 0);
  const nlohmann::json plain = simulation("plain");
  EXPECT_FALSE(plain.at("replayed").get<bool>());
  EXPECT_EQ(plain.at("twin").at("reason"), "forced: the scenario's own drive");
  EXPECT_TRUE(plain.at("twin").at("drive_mismatch").is_null());
  // The plain simulation misses the other drive by far more than its replay does.
  EXPECT_GT(plain.at("before").at("mocap").at("rms").get<double>(),
            3.0 * detected.at("before").at("mocap").at("rms").get<double>());
  const CommandRun both = Roamlab(common + "--replay --no-replay --out " + dir.File("both"), dir);
  EXPECT_EQ(both.exit_code, 2) << both.err;
}

}  // namespace
}  // namespace roamlab
