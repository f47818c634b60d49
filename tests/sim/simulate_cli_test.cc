// `roamlab simulate` end to end: a short drive writes a recording that reads back, --seed is honoured, and a bad
// scenario gives exit code 2 with one line naming the file, the line and the key. `roamlab replay` of that recording
// writes its twin; a recording without drive inputs or an empty window gives exit code 2 with one line.
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "recording/recording.h"
#include "recording/truth.h"
#include "tests/recording/temp_dir.h"
#include "tests/sim/sim_testing.h"

namespace roamlab {
namespace {

using roamlab::testing::CommandRun;

CommandRun Roamlab(const std::string& args, const roamlab::testing::TempDir& dir) {
  return roamlab::testing::RunCommand(std::string(ROAMLAB_BINARY) + " " + args, dir.path());
}

// atv_hills.yaml shortened to 2 s, with `from` replaced by `to`, written into dir as scenario.yaml.
std::string WriteScenario(const roamlab::testing::TempDir& dir, const std::string& from = "",
                          const std::string& to = "") {
  std::string text = sim::testing::ReadText(sim::testing::SourcePath("scenarios/atv_hills.yaml"));
  const auto replace = [&text](const std::string& a, const std::string& b) {
    const std::size_t at = text.find(a);
    EXPECT_NE(at, std::string::npos) << a;
    if (at != std::string::npos) text.replace(at, a.size(), b);
  };
  replace("model: ../models/atv.xml", "model: " + sim::testing::SourcePath("models/atv.xml"));
  replace("duration_s: 30.0", "duration_s: 2.0");
  if (!from.empty()) replace(from, to);
  const std::string path = dir.File("scenario.yaml");
  roamlab::testing::WriteFile(path, text);
  return path;
}

TEST(SimulateCliTest, WritesARecordingThatReadsBack) {
  roamlab::testing::TempDir dir;
  const std::string scenario = WriteScenario(dir);
  const CommandRun run = Roamlab("simulate " + scenario + " --out " + dir.File("rec") + " --seed 9", dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("simulate: 100%"), std::string::npos) << run.err;  // progress
  // Off a terminal (stderr is a file here): no `\r`, and a line only per 5 % of the simulation time.
  EXPECT_EQ(run.err.find('\r'), std::string::npos) << run.err;
  EXPECT_LE(std::count(run.err.begin(), run.err.end(), '\n'), 21) << run.err;
  EXPECT_NE(run.out.find("x real time"), std::string::npos) << run.out;
  auto rec = recording::ReadRecording(dir.File("rec"));
  ASSERT_TRUE(rec.ok()) << rec.status().message();
  EXPECT_EQ(rec.value().provenance.source, "simulated");
  EXPECT_EQ(rec.value().provenance.scenario, scenario);
  EXPECT_EQ(rec.value().provenance.seed, std::optional<std::uint64_t>(9));
  ASSERT_TRUE(rec.value().ground_truth.has_value());
  EXPECT_EQ(rec.value().ground_truth->size(), 201u);
  auto truth = recording::ReadTruth(dir.File("rec"));
  ASSERT_TRUE(truth.ok()) << truth.status().message();
  // The scenario's kv_over_L, and the true gain: below it by the rear tires' contact sink (sim/rolling_radius.h).
  EXPECT_EQ(truth.value().calibration.at("odometer.kv_over_L_geometric"), std::vector<double>{0.8});
  EXPECT_LT(truth.value().calibration.at("odometer.kv_over_L")[0], 0.8);
  EXPECT_GT(truth.value().calibration.at("odometer.kv_over_L")[0], 0.8 * (1.0 - 0.002));
}

TEST(SimulateCliTest, BadScenarioIsOneLineAndExitCode2) {
  roamlab::testing::TempDir dir;
  const std::string scenario = WriteScenario(dir, "sigma_m: 0.33", "sigma_m: 0.33\n    latency_s: 0.1");
  const CommandRun run = Roamlab("simulate " + scenario + " --out " + dir.File("rec") + " --quiet", dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_EQ(run.err.rfind("roamlab simulate: " + scenario + ":", 0), 0u) << run.err;
  EXPECT_NE(run.err.find("sensors.gps.latency_s: unknown key"), std::string::npos) << run.err;
  EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
  EXPECT_FALSE(std::filesystem::exists(dir.File("rec")));

  const CommandRun missing = Roamlab("simulate " + dir.File("none.yaml") + " --out " + dir.File("rec"), dir);
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.err.find("none.yaml: cannot open file"), std::string::npos) << missing.err;
}

TEST(SimulateCliTest, ReplayWritesTheTwinAndRefusesBadInput) {
  roamlab::testing::TempDir dir;
  const std::string scenario = WriteScenario(dir);
  ASSERT_EQ(Roamlab("simulate " + scenario + " --out " + dir.File("rec") + " --quiet", dir).exit_code, 0);
  const CommandRun run =
      Roamlab("replay " + dir.File("rec") + " --scenario " + scenario + " --out " + dir.File("twin"), dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("x real time"), std::string::npos) << run.out;
  auto twin = recording::ReadRecording(dir.File("twin"));
  ASSERT_TRUE(twin.ok()) << twin.status().message();
  auto rec = recording::ReadRecording(dir.File("rec"));
  ASSERT_TRUE(rec.ok());
  for (const auto& stream : rec.value().streams) {
    const recording::Stream* replayed = twin.value().Find(stream.info.name);
    ASSERT_NE(replayed, nullptr) << stream.info.name;
    EXPECT_EQ(replayed->t, stream.t) << stream.info.name;
  }
  auto truth = recording::ReadTruth(dir.File("twin"));
  ASSERT_TRUE(truth.ok()) << truth.status().message();
  EXPECT_TRUE(truth.value().replay.has_value());

  const CommandRun window = Roamlab(
      "replay " + dir.File("rec") + " --scenario " + scenario + " --out " + dir.File("w") + " --from 1.5 --to 1", dir);
  EXPECT_EQ(window.exit_code, 2);
  EXPECT_NE(window.err.find("window"), std::string::npos) << window.err;
  EXPECT_EQ(std::count(window.err.begin(), window.err.end(), '\n'), 1) << window.err;

  std::filesystem::remove(dir.File("rec/rear_wheel.csv"));
  std::string yaml = sim::testing::ReadText(dir.File("rec/recording.yaml"));
  const std::size_t at = yaml.find("  - name: rear_wheel");
  ASSERT_NE(at, std::string::npos);
  const std::size_t next = yaml.find("  - name:", at + 1);
  yaml.erase(at, next == std::string::npos ? std::string::npos : next - at);
  roamlab::testing::WriteFile(dir.File("rec/recording.yaml"), yaml);
  const CommandRun none =
      Roamlab("replay " + dir.File("rec") + " --scenario " + scenario + " --out " + dir.File("none"), dir);
  EXPECT_EQ(none.exit_code, 2) << none.err;
  EXPECT_NE(none.err.find("no drive input"), std::string::npos) << none.err;
  EXPECT_EQ(std::count(none.err.begin(), none.err.end(), '\n'), 1) << none.err;
}

}  // namespace
}  // namespace roamlab
