// `roamlab simulate` end to end: a short drive writes a recording that reads back, --seed is honoured, and a bad
// scenario gives exit code 2 with one line naming the file, the line and the key.
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
  EXPECT_EQ(truth.value().calibration.at("odometer.kv_over_L"), std::vector<double>{0.8});
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

}  // namespace
}  // namespace roamlab
