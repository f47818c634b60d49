// The scoring of the gap benchmark (gap/benchmark/score.h) on made-up cases (no simulation): replay of the first
// round's decision, threshold choice on calibration cases, noise ratios and the benchmark's figures.
#include "gap/benchmark/score.h"

#include <cmath>

#include <gtest/gtest.h>

namespace roamlab::gap::benchmark {
namespace {

CandidateStats Candidate(const std::string& name, double p, double delta_bic, double heldout, bool evaluated = true) {
  return {name, p, delta_bic, evaluated, heldout, {}};
}

CaseResult Case(const std::string& kind, const std::string& truth, std::vector<CandidateStats> candidates) {
  CaseResult c;
  c.kind = kind;
  c.truth_name = truth;
  c.candidates = std::move(candidates);
  return c;
}

TEST(GapBenchmarkScore, ReplayTakesTheFirstPassingCandidateInBicOrder) {
  const std::vector<CandidateStats> candidates = {Candidate("b", 1e-5, -20.0, 0.05),
                                                  Candidate("a", 1e-9, -50.0, -0.01),  // fails the held-out part
                                                  Candidate("c", 0.5, 1.0, 0.0, false)};
  EXPECT_EQ(ReplayFirstRound(candidates, {1e-3, 0.0, 0.0}), "b");
  EXPECT_EQ(ReplayFirstRound(candidates, {1e-6, 0.0, 0.0}), "");    // a passes p but not the held-out test
  EXPECT_EQ(ReplayFirstRound(candidates, {1e-3, -30.0, 0.0}), "");  // b's Delta BIC not low enough
  EXPECT_EQ(ReplayFirstRound(candidates, {1e-3, 0.0, 0.1}), "");    // b's held-out drop too small
  // Passing p and BIC without a held-out evaluation counts as failing it.
  EXPECT_EQ(ReplayFirstRound({Candidate("x", 1e-8, -40.0, 0.2, false)}, {1e-3, 0.0, 0.0}), "");
}

TEST(GapBenchmarkScore, ChoosesTheThresholdsThatKeepFalseDiscoveriesDown) {
  // Two effect cases (strong and moderate) and two effect-free ones, one of which has a spurious candidate at
  // p = 1e-5, Delta BIC -15, held-out drop 0.5 %. The defaults (1e-3, 0, 0) name it: 1 of 2 effect-free cases, above
  // 10 %. Stricter points that still identify both effects: alpha 1e-6 loses the moderate one (p 1e-5), Delta BIC -30
  // loses it too (-20), a held-out drop above 1 % keeps both effects and rejects the spurious one.
  std::vector<CaseResult> calibration = {
      Case("effect", "a", {Candidate("a", 1e-12, -200.0, 0.2), Candidate("b", 0.3, 5.0, 0.0, false)}),
      Case("effect", "b", {Candidate("b", 1e-5, -20.0, 0.04), Candidate("a", 0.2, 3.0, 0.0, false)}),
      Case("none", "", {Candidate("a", 1e-5, -15.0, 0.005), Candidate("b", 0.4, 4.0, 0.0, false)}),
      Case("decoy", "m", {Candidate("a", 0.01, -1.0, -0.02), Candidate("b", 0.6, 6.0, 0.0, false)}),
  };
  nlohmann::json table;
  const Thresholds t = ChooseThresholds(calibration, 0.10, 0.30, &table);
  EXPECT_DOUBLE_EQ(t.alpha, 1e-3);
  EXPECT_DOUBLE_EQ(t.max_delta_bic, 0.0);
  EXPECT_DOUBLE_EQ(t.min_heldout_improvement, 0.01);
  EXPECT_EQ(table.size(), ThresholdGrid().size());
  for (const CaseResult& c : calibration) EXPECT_TRUE(ReplayCorrect(c, ReplayFirstRound(c.candidates, t)));
  // Without the spurious candidate the defaults are kept (ties go to the point nearest to them).
  calibration[2].candidates[0].lr_pvalue = 0.5;
  const Thresholds d = ChooseThresholds(calibration, 0.10, 0.30);
  EXPECT_DOUBLE_EQ(d.alpha, 1e-3);
  EXPECT_DOUBLE_EQ(d.max_delta_bic, 0.0);
  EXPECT_DOUBLE_EQ(d.min_heldout_improvement, 0.0);
  // A decoy whose first round keeps a library effect is a false discovery too (the score's rule): with its spurious
  // candidate passing the defaults but not a 1 % held-out drop, the defaults are infeasible (1 of 1 decoys > 30 %).
  const auto defaults_feasible = [](const nlohmann::json& grid) {
    for (const nlohmann::json& p : grid)
      if (p["alpha"] == 1e-3 && p["max_delta_bic"] == 0.0 && p["min_heldout_improvement"] == 0.0)
        return p["feasible"].get<bool>();
    return false;
  };
  calibration[3].candidates[0] = Candidate("a", 1e-5, -15.0, 0.005);
  const Thresholds s = ChooseThresholds(calibration, 0.10, 0.30, &table);
  EXPECT_DOUBLE_EQ(s.min_heldout_improvement, 0.01);
  EXPECT_FALSE(defaults_feasible(table));
  // Within the decoys' allowance (1 of 4 = 25 % <= 30 %) the defaults are feasible (the 1 % point, which names
  // nothing on any decoy, still identifies more cases).
  for (int i = 0; i < 3; ++i) calibration.push_back(Case("decoy", "m", {Candidate("b", 0.6, 6.0, 0.0, false)}));
  ChooseThresholds(calibration, 0.10, 0.30, &table);
  EXPECT_TRUE(defaults_feasible(table));
}

CandidateStats Explaining(const std::string& name, double p, double delta_bic, double heldout, double share) {
  CandidateStats c = Candidate(name, p, delta_bic, heldout);
  c.explained_share = share;
  return c;
}

TEST(GapBenchmarkScore, ReplayRejectsACandidateThatExplainsTooLittleOfTheLocatedMismatch) {
  // A decoy's pull: the best candidate passes p, BIC and the held-out drop but explains 2 % of the held-out mismatch;
  // the next one explains 60 %. A share not recorded (NaN): the share test does not apply.
  const std::vector<CandidateStats> candidates = {Explaining("pulled", 1e-12, -300.0, 0.012, 0.02),
                                                  Explaining("next", 1e-6, -40.0, 0.01, 0.6)};
  EXPECT_EQ(ReplayFirstRound(candidates, {1e-3, 0.0, 0.0, 0.0}), "pulled");
  EXPECT_EQ(ReplayFirstRound(candidates, {1e-3, 0.0, 0.0, 0.25}), "next");
  EXPECT_EQ(ReplayFirstRound(candidates, {1e-3, 0.0, 0.0, 0.75}), "");
  EXPECT_EQ(ReplayFirstRound({Explaining("x", 1e-8, -40.0, 0.02, std::nan(""))}, {1e-3, 0.0, 0.0, 0.5}), "x");
}

TEST(GapBenchmarkScore, ChoosesTheShareThatTurnsDecoysAwayAndKeepsSmallEffects) {
  // Two decoys pull a library effect in with a large Delta BIC (-500, -200) and a held-out drop, but explain 1-5 %
  // of the held-out mismatch; the small effects pass at Delta BIC -20 to -40 and explain 40-90 % of it. No Delta BIC
  // or held-out point turns the decoys away without losing the small effects; a share of 0.25 or 0.1 does it; ties go
  // to the default share.
  std::vector<CaseResult> calibration = {
      Case("effect", "a", {Explaining("a", 1e-9, -40.0, 0.01, 0.9)}),
      Case("effect", "b", {Explaining("b", 1e-6, -20.0, 0.004, 0.4)}),
      Case("none", "", {Candidate("a", 0.2, 3.0, 0.0, false)}),
      Case("decoy", "m", {Explaining("a", 1e-30, -500.0, 0.012, 0.01)}),
      Case("decoy", "m", {Explaining("b", 1e-20, -200.0, 0.05, 0.05)}),
  };
  nlohmann::json table;
  const Thresholds t = ChooseThresholds(calibration, 0.10, 0.30, &table);
  EXPECT_DOUBLE_EQ(t.alpha, 1e-3);
  EXPECT_DOUBLE_EQ(t.max_delta_bic, 0.0);
  EXPECT_DOUBLE_EQ(t.min_heldout_improvement, 0.0);
  EXPECT_DOUBLE_EQ(t.min_explained_share, 0.25);
  for (const CaseResult& c : calibration) EXPECT_TRUE(ReplayCorrect(c, ReplayFirstRound(c.candidates, t)));
  for (const nlohmann::json& p : table) EXPECT_TRUE(p["min_explained_share"] != 0.0 || !p["feasible"].get<bool>());
  // The default share is one of the grid's, and the loosest point applies none.
  EXPECT_DOUBLE_EQ(Loosest().min_explained_share, 0.0);
  EXPECT_DOUBLE_EQ(Thresholds{}.min_explained_share, gap::kDefaultMinExplainedShare);
}

TEST(GapBenchmarkScore, CalibrationDrawsAreStratified) {
  // Any first n calibration cases hold a quarter none and a quarter decoys (rounded up), the rest effects.
  for (int n : {1, 4, 8, 16, 17, 60}) {
    int none = 0, decoy = 0, effect = 0;
    for (int i = 0; i < n; ++i) {
      const std::string kind = CalibrationKind(i);
      none += kind == "none";
      decoy += kind == "decoy";
      effect += kind == "effect";
    }
    EXPECT_EQ(none, (n + 3) / 4) << n;
    EXPECT_EQ(decoy, (n + 2) / 4) << n;
    EXPECT_EQ(none + decoy + effect, n) << n;
  }
  EXPECT_EQ(CalibrationKind(0), "none");
  EXPECT_EQ(CalibrationKind(1), "decoy");
  EXPECT_EQ(CalibrationKind(2), "effect");
  EXPECT_EQ(CalibrationKind(3), "effect");
}

TEST(GapBenchmarkScore, CalibrationAndScoreJudgeByOneRule) {
  // A decoy and a none case reported `unknown` beside a kept library effect are false discoveries; an effect case
  // whose effect is kept first beside a verdict `unknown` is identified. The replay and the score agree on each.
  CaseResult decoy = Case("decoy", "accelerometer_scale_error", {});
  decoy.verdict = "unknown";
  decoy.named = {"slope_slip"};
  CaseResult none = Case("none", "", {});
  none.verdict = "unknown";
  none.named = {"gyro_bias_drift"};
  CaseResult effect = Case("effect", "steering_offset", {});
  effect.verdict = "unknown";
  effect.named = {"steering_offset"};
  effect.ranked = effect.named;
  effect.noise_ratio = 5.0;
  EXPECT_TRUE(FalseDiscovery(decoy, FirstKept(decoy)));
  EXPECT_TRUE(FalseDiscovery(none, FirstKept(none)));
  EXPECT_FALSE(FalseDiscovery(effect, FirstKept(effect)));
  EXPECT_TRUE(Identified(effect, FirstKept(effect)));
  EXPECT_FALSE(ReplayCorrect(decoy, FirstKept(decoy)));
  EXPECT_FALSE(ReplayCorrect(none, FirstKept(none)));
  EXPECT_TRUE(ReplayCorrect(effect, FirstKept(effect)));
  EXPECT_TRUE(ReplayCorrect(decoy, ""));
  const nlohmann::json f = Summarize({decoy, none, effect});
  EXPECT_DOUBLE_EQ(f["false_discovery_rate"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(f["decoy_false_discovery_rate"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(f["decoys_unknown"].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(f["decoys_unknown_effect_kept_or_not"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(f["top1_strong"].get<double>(), 1.0);
  EXPECT_EQ(f["top1_with_verdict_unknown"], 1);
}

TEST(GapBenchmarkScore, NoiseRatioUsesTheMedianReportedStd) {
  CaseResult a = Case("none", "", {{"steering_offset", 0.5, 1.0, false, 0.0, {{"offset_rad", 0.001}}}});
  CaseResult b = Case("effect", "gps_latency", {{"steering_offset", 0.5, 1.0, false, 0.0, {{"offset_rad", 0.003}}}});
  CaseResult c = Case("none", "",
                      {{"steering_offset", 0.5, 1.0, false, 0.0, {{"offset_rad", 0.002}}},
                       {"gps_latency", 0.5, 1.0, false, 0.0, {{"latency_s", std::nan("")}}}});
  a.platform = b.platform = c.platform = "atv";
  const auto sigmas = CalibrationSigmas({a, b, c});
  EXPECT_DOUBLE_EQ(sigmas.at("atv").at("steering_offset/offset_rad"), 0.002);
  EXPECT_EQ(sigmas.at("atv").count("gps_latency/latency_s"), 0u);  // NaN skipped
  EXPECT_DOUBLE_EQ(NoiseRatio(sigmas, "atv", "steering_offset", "offset_rad", -0.02), 10.0);
  EXPECT_DOUBLE_EQ(NoiseRatio(sigmas, "atv", "gps_latency", "latency_s", 0.3), -1.0);
  EXPECT_DOUBLE_EQ(NeutralValue("scale_z"), 1.0);
  EXPECT_DOUBLE_EQ(NeutralValue("ratio_right_left"), 1.0);
  EXPECT_DOUBLE_EQ(NeutralValue("track_error_m"), 0.0);
}

TEST(GapBenchmarkScore, RearCorneringComplianceIsTheSideSlipPerLateralAcceleration) {
  // A drive whose body velocity drifts outwards by c a_y and sideways with the roll rate (O above the contact): the
  // poses integrated step by step with the body rates and velocities at the middle of each step, as the measurement
  // reads them back. The first 2 s and a slow part are skipped.
  const double c = 0.03, lever = 0.25;
  Trajectory truth;
  StampedPose pose;
  const double dt = 0.01;
  for (int k = 0; k <= 2000; ++k) {
    pose.t = Time::FromNanoseconds(static_cast<std::int64_t>(k) * 10000000);
    truth.push_back(pose);
    const double t = (k + 0.5) * dt;
    const double v_x = t < 5.0 ? 0.3 : 4.0 + 0.5 * std::sin(0.7 * t);
    const Eigen::Vector3d omega(0.05 * std::cos(1.3 * t), 0.02 * std::sin(0.9 * t), 0.3 * std::sin(0.5 * t));
    const Eigen::Vector3d v(v_x, -c * v_x * omega.z() - lever * omega.x() + 0.001, 0.0);
    const Eigen::Quaterniond half(Eigen::AngleAxisd(0.5 * omega.norm() * dt, omega.normalized()));
    pose.p_world_body += (pose.q_world_body * half) * v * dt;
    pose.q_world_body = (pose.q_world_body * half * half).normalized();
  }
  EXPECT_NEAR(RearCorneringCompliance(truth), c, 1e-9);
  EXPECT_TRUE(std::isnan(RearCorneringCompliance(Trajectory(truth.begin(), truth.begin() + 300))));  // all in 2 s
}

CaseResult Scored(const std::string& kind, const std::string& truth, const std::string& verdict,
                  std::vector<std::string> named, double noise_ratio) {
  CaseResult c;
  c.kind = kind;
  c.truth_name = truth;
  c.verdict = verdict;
  c.named = named;
  c.ranked = std::move(named);
  c.noise_ratio = noise_ratio;
  return c;
}

// The re-simulation's RMS of a case's stream, per sample and of the 1 s means, as believed and with the effects.
void Resimulated(CaseResult* c, const std::string& stream, double before, double after, double before_1s,
                 double after_1s) {
  c->sim_stream = stream;
  c->sim_rms_before = before;
  c->sim_rms_after = after;
  c->sim_rms_1s_before = before_1s;
  c->sim_rms_1s_after = after_1s;
  c->has_sim_rms = true;
}

TEST(GapBenchmarkScore, SummarizesTheBenchmarksFigures) {
  std::vector<CaseResult> cases;
  // Strong effect named right, with a 10 % parameter error on a scale (1.05 vs 1.045: error 0.005 of 0.05) and the
  // affected stream's held-out RMS from 2.0 to 1.0.
  CaseResult right = Scored("effect", "gyro_scale_error", "named", {"gyro_scale_error"}, 8.0);
  right.truth_parameter = "scale_z";
  right.truth_value = 1.05;
  right.estimate = 1.045;
  right.has_estimate = true;
  right.rms_before = 2.0;
  right.rms_after = 1.0;
  right.has_rms = true;
  // The re-simulation: 1.5 -> 1.2 per sample (20 %), 0.4 -> 0.1 in the 1 s means (75 %).
  Resimulated(&right, "gyroscope", 1.5, 1.2, 0.4, 0.1);
  cases.push_back(right);
  // Strong effect, second in the ranking: top-3 but not top-1; RMS 1.2 -> 1.14 (5 %).
  CaseResult second = Scored("effect", "gps_latency", "named", {"imu_time_offset"}, 4.0);
  second.ranked.push_back("steering_offset");
  second.ranked.push_back("gps_latency");
  second.rms_before = 1.2;
  second.rms_after = 1.14;
  second.has_rms = true;
  Resimulated(&second, "", 2.0, 1.0, 1.0, 0.5);
  cases.push_back(second);
  // Weak effect (below 3 x noise) not found: counts overall only.
  cases.push_back(Scored("effect", "imu_time_offset", "unknown", {}, 1.5));
  cases.push_back(Scored("none", "", "none", {}, -1.0));
  cases.push_back(Scored("none", "", "named", {"lateral_slip"}, -1.0));
  cases.push_back(Scored("none", "", "unknown", {}, -1.0));
  cases.push_back(Scored("none", "", "none", {}, -1.0));
  cases.push_back(Scored("decoy", "magnetometer_motor_interference", "unknown", {}, -1.0));
  cases.push_back(Scored("decoy", "magnetometer_motor_interference", "none", {}, -1.0));
  cases.push_back(Scored("decoy", "gyro_bias_drift", "named", {"wheel_radius_asymmetry"}, -1.0));

  const nlohmann::json f = Summarize(cases);
  EXPECT_EQ(f["effect_cases"], 3);
  EXPECT_NEAR(f["top1"].get<double>(), 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(f["top3"].get<double>(), 2.0 / 3.0, 1e-12);
  EXPECT_EQ(f["strong_effect_cases"], 2);
  EXPECT_DOUBLE_EQ(f["top1_strong"].get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(f["top3_strong"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(f["false_discovery_rate"].get<double>(), 0.25);
  EXPECT_DOUBLE_EQ(f["none_reported_none"].get<double>(), 0.5);
  EXPECT_NEAR(f["decoys_unknown"].get<double>(), 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(f["decoy_false_discovery_rate"].get<double>(), 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(f["median_parameter_relative_error"].get<double>(), 0.1, 1e-9);
  EXPECT_DOUBLE_EQ(f["median_heldout_rms_reduction"].get<double>(), 0.5);  // top-1 cases only
  EXPECT_NEAR(f["median_heldout_rms_reduction_all_effect_cases"].get<double>(), 0.275, 1e-12);
  EXPECT_NEAR(f["median_resimulated_rms_reduction"].get<double>(), 0.2, 1e-12);  // top-1 cases only
  EXPECT_NEAR(f["median_resimulated_rms_reduction_all_effect_cases"].get<double>(), 0.35, 1e-12);
  EXPECT_NEAR(f["median_resimulated_rms_1s_reduction"].get<double>(), 0.75, 1e-12);
  EXPECT_NEAR(f["median_resimulated_rms_1s_reduction_all_effect_cases"].get<double>(), 0.625, 1e-12);
  // The one top-1 case's simulation as believed misses its stream by 1.5 >= sqrt(2) times the noise.
  EXPECT_EQ(f["above_noise"]["cases"], 1);
  EXPECT_NEAR(f["above_noise"]["median_resimulated_rms_reduction"].get<double>(), 0.2, 1e-12);
  EXPECT_DOUBLE_EQ(f["above_noise"]["median_heldout_rms_reduction"].get<double>(), 0.5);
  EXPECT_EQ(f["below_noise"]["cases"], 0);
  EXPECT_TRUE(f["below_noise"]["median_resimulated_rms_reduction"].is_null());
  EXPECT_FALSE(f["targets"]["median_resimulated_rms_reduction"]["met"].get<bool>());
  EXPECT_TRUE(f["targets"]["median_resimulated_rms_1s_reduction"]["met"].get<bool>());
  EXPECT_FALSE(f["targets"]["top1_strong"]["met"].get<bool>());
  EXPECT_FALSE(f["targets"]["false_discovery_rate"]["met"].get<bool>());
  EXPECT_FALSE(f["targets"]["decoys_unknown"]["met"].get<bool>());
  EXPECT_TRUE(f["targets"]["median_parameter_relative_error"]["met"].get<bool>());
  EXPECT_TRUE(f["targets"]["median_heldout_rms_reduction"]["met"].get<bool>());
  EXPECT_EQ(f["by_effect"]["gyro_scale_error"]["top1"], 1);
  // All of one drive: no split by drive.
  EXPECT_FALSE(f.contains("by_drive"));

  // The same cases with the right one and two none cases (one a false discovery) of another drive, the right one
  // replayed: each drive's figures over its own cases.
  for (std::size_t i : {std::size_t{0}, std::size_t{3}, std::size_t{4}}) cases[i].other_drive = true;
  cases[0].replayed = true;
  const nlohmann::json split = Summarize(cases);
  EXPECT_EQ(split["drive"]["other_cases"], 3);
  EXPECT_EQ(split["drive"]["other_replayed"], 1);
  EXPECT_EQ(split["drive"]["own_cases"], 7);
  EXPECT_EQ(split["drive"]["own_replayed"], 0);
  EXPECT_DOUBLE_EQ(split["by_drive"]["other"]["top1_strong"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(split["by_drive"]["other"]["false_discovery_rate"].get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(split["by_drive"]["own"]["top1_strong"].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(split["by_drive"]["own"]["false_discovery_rate"].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(split["top1_strong"].get<double>(), 0.5);  // the whole's figures unchanged

  // Nothing to count: fractions are null and the targets not met.
  const nlohmann::json empty = Summarize({});
  EXPECT_TRUE(empty["top1_strong"].is_null());
  EXPECT_FALSE(empty["targets"]["top1_strong"]["met"].get<bool>());
}

}  // namespace
}  // namespace roamlab::gap::benchmark

namespace roamlab::gap::benchmark {
namespace {

// case.json is what --resume reads back: every field the score uses comes back exactly, through a text round trip.
TEST(GapBenchmarkScore, CaseRowReadsBackExactly) {
  CaseResult c = Case("effect", "gps_latency", {Candidate("gps_latency", 1.0 / 3.0, -12.25, 0.1)});
  c.candidates[0].std = {{"latency_s", 0.0123456789}, {"unknown", std::nan("")}};
  c.candidates.push_back(Candidate("steering_offset", 0.5, 2.0, 0.0, false));
  c.id = "007";
  c.platform = "atv";
  c.truth_parameter = "latency_s";
  c.truth_value = 0.1 + 0.2;
  c.noise_ratio = 4.5;
  c.verdict = "named";
  c.named = {"gps_latency"};
  c.ranked = {"gps_latency", "steering_offset"};
  c.estimate = 0.29999;
  c.has_estimate = true;
  c.rms_before = 2.5;
  c.rms_after = 1.0 / 7.0;
  c.rms_1s_before = 1.5;
  c.rms_1s_after = 0.25;
  c.has_rms = true;
  c.seconds = 12.5;
  c.other_drive = true;
  c.replayed = true;
  const nlohmann::json row = nlohmann::json::parse(CaseRow(c).dump(2));
  const Result<CaseResult> back = CaseFromRow(row);
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(CaseRow(back.value()).dump(), CaseRow(c).dump());
  EXPECT_EQ(back.value().truth_value, c.truth_value);
  EXPECT_TRUE(back.value().other_drive && back.value().replayed);
  EXPECT_FALSE(back.value().has_sim_rms);
  EXPECT_TRUE(std::isnan(back.value().candidates[0].std.at("unknown")));
  EXPECT_TRUE(std::isnan(back.value().candidates[0].explained_share));

  // A missing key or one of another type is an error, never an exception.
  for (const char* key : {"case", "truth", "candidates", "estimate", "other_drive", "seconds"}) {
    nlohmann::json damaged = row;
    damaged.erase(key);
    EXPECT_FALSE(CaseFromRow(damaged).ok()) << key;
    damaged[key] = nlohmann::json::object();
    EXPECT_FALSE(CaseFromRow(damaged).ok()) << key;
  }
  EXPECT_FALSE(CaseFromRow(nlohmann::json::array()).ok());
  EXPECT_FALSE(CaseFromRow(nlohmann::json()).ok());
}

}  // namespace
}  // namespace roamlab::gap::benchmark
