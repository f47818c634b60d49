// `roamlab sweep` on the local backend: a 2 x 2 grid x 2 seeds gives a table of 4 rows whose values are those of
// single `roamlab montecarlo` runs of the same points (files patched here by hand); bad sweep files give one line.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/apps/batch_fixture.h"
#include "tests/recording/temp_dir.h"
#include "tests/support/paths.h"

namespace roamlab {
namespace {

namespace fs = std::filesystem;
using testing::ReadJson;
using testing::Roamlab;
using testing::SlurpFile;

class SweepTest : public ::testing::Test {
 protected:
  // `text` with `from` replaced by `to` (which must be there once), written to DIR/name.
  std::string Patched(std::string text, const std::string& from, const std::string& to, const std::string& name) {
    EXPECT_NE(text.find(from), std::string::npos) << from;
    if (text.find(from) != std::string::npos) text.replace(text.find(from), from.size(), to);
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << text;
    return path;
  }
  std::string Sweep(const std::string& body) {
    std::ofstream(dir_ / "sweep.yaml") << "scenario: " << scenario_ << "\nconfig: " << config_ << "\n" << body;
    return "sweep sweep.yaml --out sweep --jobs 2 --quiet";
  }

  testing::TempDir temp_;
  fs::path dir_{temp_.path()};
  std::string scenario_ = testing::WriteShortAtvScenario(dir_, "4.0");
  std::string config_ = roamlab::testing::SourceDir() + "/configs/atv_tracking.yaml";
};

TEST_F(SweepTest, GridTableMatchesSingleMonteCarloRuns) {
  ASSERT_FALSE(scenario_.empty());
  const testing::CommandRun r = Roamlab(Sweep("seeds: 2\nt0_s: 1\nno_time_budget: true\ngrid:\n"
                                              "  scenario.sensors.gps.sigma_m: [0.2, 0.5]\n"
                                              "  config.tracking.window: [20, 40]\n"),
                                        dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // The table: a header and one row per point, the first key varying slowest.
  std::istringstream csv(SlurpFile(dir_ / "sweep" / "table.csv"));
  std::vector<std::string> lines;
  for (std::string line; std::getline(csv, line);) lines.push_back(line);
  ASSERT_EQ(lines.size(), 5u);
  EXPECT_EQ(lines[0],
            "point,scenario.sensors.gps.sigma_m,config.tracking.window,fraction_in_band,mean_nees,ate_m,rpe_m,"
            "track_seconds");
  EXPECT_EQ(lines[1].rfind("0,0.2,20,", 0), 0u) << lines[1];
  EXPECT_EQ(lines[2].rfind("1,0.2,40,", 0), 0u) << lines[2];
  EXPECT_EQ(lines[3].rfind("2,0.5,20,", 0), 0u) << lines[3];
  EXPECT_EQ(lines[4].rfind("3,0.5,40,", 0), 0u) << lines[4];
  const nlohmann::json sweep = ReadJson(dir_ / "sweep" / "sweep.json");
  ASSERT_EQ(sweep["points"].size(), 4u);
  EXPECT_EQ(sweep["seeds"], 2);

  // Points 1 (sigma 0.2, window 40) and 2 (sigma 0.5, window 20) as single Monte-Carlo runs of files patched here.
  const std::string config = SlurpFile(config_), scenario = SlurpFile(scenario_);
  const std::string calibrate = roamlab::testing::SourceDir() + "/configs/atv_calibration.yaml";
  for (const auto& [point, sigma, window] : {std::make_tuple(1, "0.2", "40"), std::make_tuple(2, "0.5", "20")}) {
    const std::string name = "point" + std::to_string(point);
    const std::string s = Patched(scenario, "    sigma_m: 0.33", std::string("    sigma_m: ") + sigma, name + ".yaml");
    std::string c = config;
    c.replace(c.find("calibrate: atv_calibration.yaml"), 31, "calibrate: " + calibrate);
    const std::string cfg = Patched(c, "  window: 40", std::string("  window: ") + window, name + "_config.yaml");
    const testing::CommandRun mc = Roamlab(
        "montecarlo " + s + " --config " + cfg + " --runs 2 --jobs 2 --t0 1 --no-time-budget --quiet --out " + name,
        dir_);
    ASSERT_EQ(mc.exit_code, 0) << mc.err;
    const nlohmann::json nees = ReadJson(dir_ / name / "nees.json"), runs = ReadJson(dir_ / name / "runs.json");
    const nlohmann::json& row = sweep["points"][point];
    EXPECT_EQ(row["values"]["scenario.sensors.gps.sigma_m"], sigma);
    EXPECT_EQ(row["fraction_in_band"].get<double>(), nees["fraction_in_band"].get<double>()) << name;
    for (const char* metric : {"ate_m", "mean_nees", "rpe_m"}) {
      const double mean = (runs["runs"][0][metric].get<double>() + runs["runs"][1][metric].get<double>()) / 2.0;
      EXPECT_DOUBLE_EQ(row[metric].get<double>(), mean) << name << " " << metric;
    }
  }
  // The two noise levels differ in the table (the key reached the simulation).
  EXPECT_NE(sweep["points"][0]["ate_m"], sweep["points"][2]["ate_m"]);
}

TEST_F(SweepTest, BadSweepFilesGiveOneLine) {
  ASSERT_FALSE(scenario_.empty());
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"seeds: 2\ngrid:\n  scenario.sensors.gps.sigma_mm: [0.1]\n", "has no key sensors.gps.sigma_mm"},
      {"seeds: 2\ngrid:\n  sensors.gps.sigma_m: [0.1]\n", "is not scenario.PATH or config.PATH"},
      {"seeds: 0\ngrid:\n  config.tracking.window: [10]\n", "seeds: not an integer >= 1"},
      {"seeds: 2\n", "needs either grid or list"},
      {"seeds: 2\nlist:\n  - {config.tracking.window: 10}\n  - {config.solver.max_iterations: 3}\n",
       "list[1]: names other keys than list[0]"},
      {"seeds: 2\nwindow: 3\ngrid:\n  config.tracking.window: [10]\n", "unknown key 'window'"},
      {"seeds: 2\ngrid: {config.tracking.window: [10]\n", "sweep.yaml"},
  };
  for (const auto& [body, message] : cases) {
    const testing::CommandRun r = Roamlab(Sweep(body), dir_);
    EXPECT_EQ(r.exit_code, 2) << body;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << body << " -> " << r.err;
  }
}

}  // namespace
}  // namespace roamlab
