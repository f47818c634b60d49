// The twin's patch fitted on several training runs (gap/twin.h DiagnoseTwin with TwinTrainingRun): a hidden wheel
// radius asymmetry, and a hidden geometry (radius scale and track), in two seeded 30 s recordings of the OptiOdom
// differential drive (wheel encoders, motion capture) of different drives, the scenario's own (its twin the plain
// simulation) and one turning the other way at twice the rate (its twin the replay of its drive); and two runs of one
// drive of very different lengths, weighed by their windows or alike (TwinDiagnoseOptions::train_weight).
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gap/twin.h"
#include "tests/gap/gap_testing.h"
#include "tests/support/paths.h"

namespace roamlab::gap {
namespace {

constexpr double kRatio = 1.02;

sim::Scenario Nominal() {
  auto s = sim::LoadScenario(roamlab::testing::SourceDir() + "/scenarios/real/optiodom_diff.yaml");
  EXPECT_TRUE(s.ok()) << s.status().message();
  sim::Scenario scenario = s.value();
  scenario.effects.clear();
  scenario.duration_s = 30.0;
  return scenario;
}

// `drive` with the hidden `effects` (default: the asymmetry), simulated with noise seed `seed`.
recording::Recording Real(sim::Scenario drive, std::uint64_t seed,
                          std::vector<sim::EffectOptions> effects = {
                              {"wheel_radius_asymmetry", {{"ratio_right_left", kRatio}}}}) {
  drive.effects = std::move(effects);
  return testing::SimulatedWithSeed(drive, seed).recording;
}

// The scenario's drive turning the other way at twice the rate.
sim::Scenario Turned(sim::Scenario drive) {
  for (sim::ProfileTerm& term : drive.driver.angular_radps.terms) term.amplitude = -0.3;
  return drive;
}

// The fitted ratio and its std; fails the test when the asymmetry is not the kept effect.
std::pair<double, double> Ratio(const TwinDiagnosis& d) {
  EXPECT_EQ(d.verdict, "named");
  if (d.effects.empty() || d.effects.front().estimate.name != "wheel_radius_asymmetry") {
    ADD_FAILURE() << "the asymmetry is not the kept effect";
    return {0.0, 0.0};
  }
  const EffectEstimate& e = d.effects.front().estimate;
  std::printf("  ratio_right_left %.6f +- %.3g, %d twin runs\n", e.parameters.at("ratio_right_left"),
              e.std.at("ratio_right_left"), d.runs);
  return {e.parameters.at("ratio_right_left"), e.std.at("ratio_right_left")};
}

// The mean 10 s drift of a comparison's motion capture track.
double Drift(const TwinComparison& c) {
  EXPECT_TRUE(c.drift.count("mocap"));
  return c.drift.count("mocap") ? c.drift.at("mocap").mean_position_m : 0.0;
}

// The hidden geometry of the joint-geometry tests: every wheel's radius scaled by kHiddenScale, the track
// kHiddenTrackErrorM [m] wider.
constexpr double kHiddenScale = 0.985, kHiddenTrackErrorM = 0.008;
std::vector<sim::EffectOptions> HiddenGeometry() {
  return {{"wheel_radius_scale", {{"scale", kHiddenScale}}},
          {"track_width_error", {{"track_error_m", kHiddenTrackErrorM}}}};
}

// The fitted drive geometry of `kept`: each parameter has a positive std and lies within three of it of `hidden`.
void ExpectGeometryWithinThreeStd(const TwinEffect& kept, const std::map<std::string, double>& hidden) {
  std::printf("  iterations %d, chi2 %.6g -> %.6g, runs %d\n", kept.iterations, kept.chi2_before, kept.chi2_after,
              kept.runs);
  for (const auto& [name, value] : hidden) {
    ASSERT_TRUE(kept.estimate.std.count(name)) << name << " not fitted";
    const double fitted = kept.estimate.parameters.at(name), std = kept.estimate.std.at(name);
    std::printf("  %s %.6f +- %.3g (hidden %.6f)\n", name.c_str(), fitted, std, value);
    EXPECT_GT(std, 0.0) << name;
    EXPECT_NEAR(fitted, value, 3.0 * std) << name;
  }
}

// The ratio fitted on both runs is named and within three of its std of the hidden one, with a smaller std than
// fitted on the first run alone; each run's series enter the HAC covariance as series of their own; the second run's
// held-out drift shrinks with the patch.
TEST(TwinTrainingRunsTest, AnEffectFittedOnTwoRunsOfDifferentDrivesUsesBoth) {
  const sim::Scenario nominal = Nominal();
  const recording::Recording own = Real(nominal, 41), turned = Real(Turned(nominal), 42);
  TwinDiagnoseOptions options;
  options.candidates = {"wheel_radius_asymmetry", "wheel_radius_scale"};
  options.max_effects = 1;

  auto one = DiagnoseTwin(nominal, own, PlainSimulationRunner(), options);
  ASSERT_TRUE(one.ok()) << one.status().message();
  std::printf("fitted on the own drive:\n");
  const auto [ratio_one, std_one] = Ratio(one.value());
  EXPECT_TRUE(one.value().training_runs.empty());

  const std::vector<TwinTrainingRun> runs = {{"own", &own, PlainSimulationRunner(), false},
                                             {"turned", &turned, ReplayRunner(turned), true}};
  auto two = DiagnoseTwin(nominal, runs, options);
  ASSERT_TRUE(two.ok()) << two.status().message();
  const TwinDiagnosis& d = two.value();
  std::printf("fitted on both drives:\n");
  const auto [ratio, std] = Ratio(d);
  ASSERT_GT(std, 0.0);
  EXPECT_NEAR(ratio, kRatio, 3.0 * std);
  EXPECT_LT(std, std_one);
  EXPECT_GT(d.runs, one.value().runs);

  const std::map<std::string, int>& lags = d.effects.front().hac_lags;
  EXPECT_TRUE(lags.count("own: mocap") && lags.count("turned: mocap")) << "series: " << lags.size();

  ASSERT_EQ(d.training_runs.size(), 1u);
  const TwinTrainingFigures& t = d.training_runs.front();
  EXPECT_EQ(t.recording, "turned");
  EXPECT_TRUE(t.replayed);
  const double before = Drift(t.heldout_before), after = Drift(t.heldout_after);
  std::printf("turned drive, held-out 10 s drift %.4f m -> %.4f m\n", before, after);
  EXPECT_LT(after, 0.5 * before);
  EXPECT_LT(t.heldout_after.chi2, t.heldout_before.chi2);
}

// The twin of a recording of `drive`'s own drive: the patched scenario with that drive, simulated without noise.
TwinRunner PlainSimulationOf(const sim::Scenario& drive) {
  const TwinRunner plain = PlainSimulationRunner();
  return [plain, driver = drive.driver](const sim::Scenario& patched) {
    sim::Scenario s = patched;
    s.driver = driver;
    return plain(s);
  };
}

// A hidden geometry with both the radius scale and the track off, on the same two drives, each run's twin the plain
// simulation of its own drive: the joint geometry is kept over each of its parameters alone (its two extra parameters
// penalized by Delta BIC), its patch sets the three simulator effects, and each parameter is within three of its std
// of the hidden value (the ratio of the neutral 1).
TEST(TwinTrainingRunsTest, AJointGeometryIsRecoveredOnTwoRunsOfDifferentDrives) {
  const sim::Scenario nominal = Nominal(), other = Turned(nominal);
  const recording::Recording own = Real(nominal, 43, HiddenGeometry()), turned = Real(other, 44, HiddenGeometry());
  TwinDiagnoseOptions options;
  options.candidates = {"wheel_radius_asymmetry", "wheel_radius_scale", "track_width_error", "diff_drive_geometry"};
  options.max_effects = 1;
  const std::vector<TwinTrainingRun> runs = {{"own", &own, PlainSimulationRunner(), false},
                                             {"turned", &turned, PlainSimulationOf(other), false}};
  auto d = DiagnoseTwin(nominal, runs, options);
  ASSERT_TRUE(d.ok()) << d.status().message();
  ASSERT_EQ(d.value().effects.size(), 1u);
  const TwinEffect& kept = d.value().effects.front();
  ASSERT_EQ(kept.estimate.name, "diff_drive_geometry");
  ASSERT_EQ(kept.applied.size(), 3u);
  EXPECT_EQ(d.value().patch.size(), 3u);
  ASSERT_EQ(d.value().rounds.size(), 1u);
  EXPECT_EQ(d.value().rounds.front().size(), options.candidates.size());
  ExpectGeometryWithinThreeStd(
      kept, {{"scale", kHiddenScale}, {"ratio_right_left", 1.0}, {"track_error_m", kHiddenTrackErrorM}});
}

// The same hidden geometry with each run's twin the replay of its recorded drive (wheel encoders in whole ticks,
// starting at the first motion-capture pose): each parameter within three of its std of the hidden value. The replay
// starts where its first 10 s fit the recorded track (not at one noisy pose), and the encoder stream that drives it is
// not compared (its twin tracks it through the servo, a tick or two behind), so neither biases the geometry.
TEST(TwinTrainingRunsTest, AJointGeometryIsRecoveredFromReplaysOfTwoDrives) {
  const sim::Scenario nominal = Nominal(), other = Turned(nominal);
  const recording::Recording own = Real(nominal, 43, HiddenGeometry()), turned = Real(other, 44, HiddenGeometry());
  TwinDiagnoseOptions options;
  options.candidates = {"diff_drive_geometry"};
  options.max_effects = 1;
  options.replayed = true;
  options.increment_window_s = 0.0;  // the absolute tracks: thirty seconds hold too few 10 s windows
  const std::vector<TwinTrainingRun> runs = {{"own", &own, ReplayRunner(own), true},
                                             {"turned", &turned, ReplayRunner(turned), true}};
  auto d = DiagnoseTwin(nominal, runs, options);
  ASSERT_TRUE(d.ok()) << d.status().message();
  ASSERT_EQ(d.value().effects.size(), 1u);
  const TwinEffect& kept = d.value().effects.front();
  ExpectGeometryWithinThreeStd(
      kept, {{"scale", kHiddenScale}, {"ratio_right_left", 1.0}, {"track_error_m", kHiddenTrackErrorM}});
  // The encoder stream that drives each replay is left out of its comparisons, with the reason.
  const std::vector<std::string>& left_out = d.value().heldout_before.left_out;
  EXPECT_TRUE(std::any_of(left_out.begin(), left_out.end(), [](const std::string& s) {
    return s.rfind("wheel_encoders: drives the replay", 0) == 0;
  })) << left_out.size();
}

// Two runs of the same drive of very different lengths (60 s and 20 s), with different hidden asymmetries (1.01 and
// 1.03), each replayed and compared by the drift's 10 s windows. The short run trains whole (its last third, 6.7 s,
// cannot hold a window): 11 windows against the long run's 31 in its first 40 s. Weighted by their windows the fit
// lands at the windows' mean of the two ratios; with each run weighing the same (TrainWeight::kRuns) the short run's
// chi-square weight is its windows' ratio above the long run's (their total unchanged), and the fitted ratio moves
// to the two's middle.
TEST(TwinTrainingRunsTest, WeighingTheRunsAlikeMakesAShortRunCountAsMuchAsALongOne) {
  sim::Scenario nominal = Nominal(), long_drive = Nominal(), short_drive = Nominal();
  long_drive.duration_s = 60.0;
  short_drive.duration_s = 20.0;
  const recording::Recording long_run =
      Real(long_drive, 45, {{"wheel_radius_asymmetry", {{"ratio_right_left", 1.01}}}});
  const recording::Recording short_run =
      Real(short_drive, 46, {{"wheel_radius_asymmetry", {{"ratio_right_left", 1.03}}}});
  TwinDiagnoseOptions options;
  options.candidates = {"wheel_radius_asymmetry"};
  options.max_effects = 1;
  options.replayed = true;
  const std::vector<TwinTrainingRun> runs = {{"long", &long_run, ReplayRunner(long_run), true},
                                             {"short", &short_run, ReplayRunner(short_run), true}};
  auto by_windows = DiagnoseTwin(nominal, runs, options);
  ASSERT_TRUE(by_windows.ok()) << by_windows.status().message();
  options.train_weight = TwinDiagnoseOptions::TrainWeight::kRuns;
  auto by_runs = DiagnoseTwin(nominal, runs, options);
  ASSERT_TRUE(by_runs.ok()) << by_runs.status().message();

  EXPECT_EQ(by_windows.value().train_weight, "windows");
  EXPECT_EQ(by_windows.value().run_weights, (std::vector<double>{1.0, 1.0}));
  EXPECT_EQ(by_runs.value().train_weight, "runs");
  const std::vector<double>& w = by_runs.value().run_weights;
  ASSERT_EQ(w.size(), 2u);
  std::printf("chi-square weights: long %.4f, short %.4f\n", w[0], w[1]);
  EXPECT_LT(w[0], 1.0);
  EXPECT_NEAR(w[1] / w[0], 31.0 / 11.0, 0.3);
  // The long run is cut at 2/3, the short one trains whole and holds nothing out.
  const TwinDiagnosis& d = by_windows.value();
  EXPECT_NEAR(d.train_end_s - long_run.streams.front().t.front().seconds(), 40.0, 0.1);
  ASSERT_EQ(d.training_runs.size(), 1u);
  EXPECT_NEAR(d.training_runs.front().train_end_s - short_run.streams.front().t.front().seconds(), 20.0, 0.1);
  EXPECT_EQ(d.training_runs.front().heldout_before.residuals, 0);

  // The first round's fit (the held-out test, on the long run's last third alone, then rejects the compromise).
  const auto fitted = [](const TwinDiagnosis& d) {
    EXPECT_EQ(d.candidates.size(), 1u);
    if (d.candidates.empty()) return 0.0;
    const EffectEstimate& e = d.candidates.front().estimate;
    std::printf("  ratio_right_left %.6f, LR %.4g: %s\n", e.parameters.at("ratio_right_left"), e.lr_raw,
                e.decision.c_str());
    return e.parameters.at("ratio_right_left");
  };
  std::printf("weighted by windows:\n");
  const double ratio_windows = fitted(by_windows.value());
  std::printf("each run weighing the same:\n");
  const double ratio_runs = fitted(by_runs.value());
  EXPECT_NEAR(ratio_windows, (31.0 * 1.01 + 11.0 * 1.03) / 42.0, 0.003);
  EXPECT_NEAR(ratio_runs, 1.02, 0.003);
}

// A training run that is missing or has nothing to compare is an error naming it.
TEST(TwinTrainingRunsTest, ARunWithoutSamplesIsAnErrorNamingIt) {
  const sim::Scenario nominal = Nominal();
  const recording::Recording own = Real(nominal, 41);
  recording::Recording empty = own;
  for (recording::Stream& s : empty.streams) {
    s.t.clear();
    s.values.resize(0, s.values.cols());
  }
  const auto d = DiagnoseTwin(
      nominal, {{"own", &own, PlainSimulationRunner(), false}, {"empty", &empty, PlainSimulationRunner(), false}});
  ASSERT_FALSE(d.ok());
  EXPECT_EQ(d.status().message(), "empty: the recording has no span of samples to compare");
  EXPECT_FALSE(DiagnoseTwin(nominal, std::vector<TwinTrainingRun>{}).ok());
}

}  // namespace
}  // namespace roamlab::gap
