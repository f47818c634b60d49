// The diagnosis against the replayed twin on real OptiOdom recordings (tests/support/real_data.h, skipped when
// absent), held out across runs: the patch fitted on a Dec-2020 square, circular and Ivanjko run of the differential
// drive together (each on the replay of its own drive, compared by 10 s windowed increments) is shown on another
// circular run of the same day (the twin's 10 s motion-capture drift, nominal against patched). The claims asserted
// are the ones the data supports (docs/results.md): the drift falls by at least a fifth, not to half on every circular
// run (0.48-0.60 over the day's six, 0.52 on this one), and the motion capture's clock named among the effects is
// negative, the encoders behind the motion capture. Fitted on the square run alone, 10 s increments of its first
// two thirds (4 windows) name no effect.
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gap/twin.h"
#include "importers/optiodom.h"
#include "recording/recording.h"
#include "sim/scenario.h"
#include "tests/recording/temp_dir.h"
#include "tests/support/paths.h"
#include "tests/support/real_data.h"

namespace roamlab::gap {
namespace {

const std::string kDiff = ::roamlab::testing::RealDataDir() + "/optiodom/data/diff/";

// The run imported and read back from a recording directory, as `roamlab import optiodom` and `roamlab diagnose` do.
Result<recording::Recording> ImportRun(const std::string& set_path, const std::string& run,
                                       const ::roamlab::testing::TempDir& dir) {
  auto imported = importers::ImportOptiOdom(set_path + "_run-" + run + ".csv", set_path + "_metadata.csv");
  if (!imported.ok()) return imported.status();
  const std::string path = dir.File(std::filesystem::path(set_path).filename().string() + "_" + run);
  if (Status s = recording::WriteRecording(imported.value(), path); !s.ok()) return s;
  recording::ReadOptions read;
  read.load_ground_truth = false;
  return recording::ReadRecording(path, read);
}

TEST(TwinRealTest, AMixedSetsPatchLowersAnotherCircularRunsDrift) {
  const std::vector<std::string> training = {kDiff + "square/231220200029/231220200029",
                                             kDiff + "circular/231220200121/231220200121",
                                             kDiff + "ivanjko/231220200057/231220200057"};
  const std::string circular = kDiff + "circular/231220200134/231220200134";
  for (const std::string& set : {training[0], training[1], training[2], circular})
    if (!std::filesystem::exists(set + "_metadata.csv")) GTEST_SKIP() << "real data absent: " << set;
  ::roamlab::testing::TempDir dir;
  std::vector<recording::Recording> runs;
  for (const std::string& set : training) {
    auto run = ImportRun(set, "01", dir);
    ASSERT_TRUE(run.ok()) << run.status().message();
    runs.push_back(std::move(run).value());
  }
  auto held = ImportRun(circular, "01", dir);
  ASSERT_TRUE(held.ok()) << held.status().message();
  auto nominal = sim::LoadScenario(roamlab::testing::SourceDir() + "/scenarios/real/optiodom_diff.yaml");
  ASSERT_TRUE(nominal.ok()) << nominal.status().message();

  TwinDiagnoseOptions options;
  options.replayed = true;
  std::vector<TwinTrainingRun> set;
  for (std::size_t i = 0; i < runs.size(); ++i) set.push_back({training[i], &runs[i], ReplayRunner(runs[i]), true});
  auto d = DiagnoseTwin(nominal.value(), set, options);
  ASSERT_TRUE(d.ok()) << d.status().message();
  ASSERT_FALSE(d.value().patch.empty()) << "no effect named on the mixed set";
  const TwinEffect* clock = nullptr;
  for (const TwinEffect& e : d.value().effects) {
    std::cout << e.estimate.name;
    for (const auto& [k, v] : e.estimate.parameters)
      std::cout << " " << k << " = " << v
                << (e.estimate.std.count(k) ? " +- " + std::to_string(e.estimate.std.at(k)) : "");
    std::cout << "\n";
    if (e.estimate.name == "pose_time_offset") clock = &e;
  }
  const TwinResidualOptions held_residuals =
      ReplayedResidualOptions(nominal.value(), held.value(), options.increment_window_s);
  auto shown =
      ShowOnHeldOut(nominal.value(), d.value().patch, held.value(), ReplayRunner(held.value()), {}, 2, held_residuals);
  ASSERT_TRUE(shown.ok()) << shown.status().message();
  ASSERT_TRUE(shown.value().before.drift.count("mocap"));
  ASSERT_TRUE(shown.value().after.drift.count("mocap"));
  const double before = shown.value().before.drift.at("mocap").mean_position_m;
  const double after = shown.value().after.drift.at("mocap").mean_position_m;
  std::cout << "circular run 0134, 10 s drift: nominal twin " << before << " m, patched " << after << " m ("
            << after / before << "x); chi2 of its increments " << shown.value().before.chi2 << " -> "
            << shown.value().after.chi2 << "\n";
  EXPECT_LT(after, 0.8 * before);
  EXPECT_LT(shown.value().after.chi2, shown.value().before.chi2);

  // The motion capture's clock (pose_time_offset) is named on top of the geometry: negative, the encoders (the drive
  // the twin replays) behind the motion capture.
  ASSERT_NE(clock, nullptr) << "pose_time_offset not named";
  EXPECT_LT(clock->estimate.parameters.at("offset_s"), 0.0);
}

}  // namespace
}  // namespace roamlab::gap
