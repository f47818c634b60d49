// `roamlab montecarlo --calibration-consistency` end to end on a short ATV drive: consistency.json's statistics are
// those of the runs' own result files, --redraw-terrain gives each run its own terrain and names the runs that fail on
// theirs, and what it does not support is refused with one line.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <Eigen/Cholesky>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/recording/temp_dir.h"
#include "tests/support/paths.h"

namespace roamlab {
namespace {

namespace fs = std::filesystem;

using testing::CommandRun;

CommandRun Roamlab(const std::string& args, const fs::path& dir) {
  return testing::RunCommand(std::string(ROAMLAB_BINARY) + " " + args, dir.string());
}

nlohmann::json ReadJson(const fs::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// A JSON number, null read as NaN.
double Value(const nlohmann::json& j) { return j.is_null() ? NAN : j.get<double>(); }

// Equal up to rounding, or both NaN (null).
void ExpectSame(double expected, const nlohmann::json& actual, const std::string& what) {
  if (std::isnan(expected)) {
    EXPECT_TRUE(actual.is_null()) << what << ": " << actual;
    return;
  }
  ASSERT_TRUE(actual.is_number()) << what;
  EXPECT_NEAR(actual.get<double>(), expected, 1e-9 * (1.0 + std::abs(expected))) << what;
}

class ConsistencyCliTest : public ::testing::Test {
 protected:
  // atv_hills.yaml cut to 6 s (the model's path made absolute for the copy).
  void SetUp() override {
    std::ifstream in(testing::SourceDir() + "/scenarios/atv_hills.yaml");
    std::string scenario((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string from = "duration_s: 30.0", model = "../models/atv.xml";
    ASSERT_NE(scenario.find(from), std::string::npos);
    scenario.replace(scenario.find(from), from.size(), "duration_s: 6.0");
    ASSERT_NE(scenario.find(model), std::string::npos);
    scenario.replace(scenario.find(model), model.size(), testing::SourceDir() + "/models/atv.xml");
    std::ofstream(scenario_) << scenario;
  }

  std::string Command(int jobs, const std::string& out) const {
    return "montecarlo " + scenario_ + " --config " + config_ + " --calibration-consistency --runs 3 --seed-base 500" +
           " --jobs " + std::to_string(jobs) + " --out " + (dir_ / out).string();
  }

  // A copy of the short scenario with `from` replaced by `to`, written to NAME.yaml.
  std::string Variant(const std::string& name, const std::string& from, const std::string& to) const {
    std::ifstream in(scenario_);
    std::string scenario((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(scenario.find(from), std::string::npos) << from;
    if (scenario.find(from) != std::string::npos) scenario.replace(scenario.find(from), from.size(), to);
    const std::string path = (dir_ / (name + ".yaml")).string();
    std::ofstream(path) << scenario;
    return path;
  }

  testing::TempDir temp_;
  fs::path dir_{temp_.path()};
  std::string scenario_ = (dir_ / "atv_short.yaml").string();
  std::string config_ = testing::SourceDir() + "/configs/atv_calibration.yaml";
};

// Recomputes every component's bias, spread, mean std and coverage, and every run's block NEES, from the runs' files.
void ExpectStatisticsOfTheRuns(const nlohmann::json& block, const std::vector<nlohmann::json>& runs) {
  const std::string name = block["name"];
  const int d = block["dimension"];
  const int n = static_cast<int>(runs.size());
  for (int k = 0; k < d; ++k) {
    double sum = 0.0, squares = 0.0, std_sum = 0.0;
    int std_count = 0, inside[3] = {0, 0, 0};
    for (const nlohmann::json& run : runs) sum += Value(run["parameters"][name]["error"][k]);
    const double bias = sum / n;
    for (const nlohmann::json& run : runs) {
      const double e = Value(run["parameters"][name]["error"][k]), s = Value(run["parameters"][name]["std"][k]);
      squares += (e - bias) * (e - bias);
      if (!std::isfinite(s)) continue;
      std_sum += s;
      ++std_count;
      for (int sigmas = 1; sigmas <= 3; ++sigmas) inside[sigmas - 1] += std::abs(e) <= sigmas * s ? 1 : 0;
    }
    const nlohmann::json& c = block["components"][k];
    const std::string what = name + "[" + std::to_string(k) + "]";
    ExpectSame(bias, c["bias"], what + " bias");
    ExpectSame(std::sqrt(squares / (n - 1)), c["spread"], what + " spread");
    ExpectSame(std_count ? std_sum / std_count : NAN, c["mean_std"], what + " mean std");
    for (int sigmas = 0; sigmas < 3; ++sigmas)
      ExpectSame(std_count ? static_cast<double>(inside[sigmas]) / std_count : NAN, c["coverage"][sigmas]["fraction"],
                 what + " coverage");
    ExpectSame(Value(c["mean_std"]) / Value(c["cramer_rao_std"]), c["efficiency"], what + " efficiency");
  }
  for (int j = 0; j < n; ++j) {
    const nlohmann::json& p = runs[j]["parameters"][name];
    Eigen::VectorXd e(d);
    Eigen::MatrixXd covariance(d, d);
    for (int r = 0; r < d; ++r) {
      e[r] = Value(p["error"][r]);
      for (int c = 0; c < d; ++c) covariance(r, c) = Value(p["covariance"][r][c]);
    }
    const Eigen::LLT<Eigen::MatrixXd> llt(covariance);
    const double nees = covariance.allFinite() && llt.info() == Eigen::Success ? e.dot(llt.solve(e)) : NAN;
    ExpectSame(nees, block["nees"]["per_run"][j], name + " NEES of run " + std::to_string(j));
  }
}

TEST_F(ConsistencyCliTest, StatisticsAreThoseOfTheRuns) {
  const CommandRun r = Roamlab(Command(2, "c"), dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("gps.lever_arm[2]"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("mean NEES"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("wrote " + (dir_ / "c" / "consistency.json").string()), std::string::npos) << r.out;
  const nlohmann::json j = ReadJson(dir_ / "c" / "consistency.json");
  EXPECT_EQ(j["runs"], 3);
  EXPECT_EQ(j["seed_base"], 500);
  EXPECT_EQ(j["scenario"], scenario_);
  EXPECT_TRUE(j["cramer_rao"].is_string());

  // Every run's file: its seed, the truth of the scenario, the error of a vector parameter as estimate - truth.
  std::vector<nlohmann::json> runs;
  for (int i = 0; i < 3; ++i) {
    runs.push_back(ReadJson(dir_ / "c" / "calibrations" / ("00000" + std::to_string(i) + ".json")));
    EXPECT_EQ(runs.back()["seed"], 500 + i);
    const nlohmann::json& lever = runs.back()["parameters"]["gps.lever_arm"];
    EXPECT_EQ(lever["truth"], nlohmann::json({0.57, -0.46, 0.32}));
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(Value(lever["error"][k]), Value(lever["estimate"][k]) - Value(lever["truth"][k]), 1e-12);
  }
  EXPECT_NE(runs[0]["parameters"]["gps.lever_arm"]["estimate"], runs[1]["parameters"]["gps.lever_arm"]["estimate"])
      << "each run draws its own noise";

  std::vector<std::string> names;
  for (const nlohmann::json& block : j["parameters"]) {
    names.push_back(block["name"]);
    EXPECT_EQ(block["runs"], 3);
    ExpectStatisticsOfTheRuns(block, runs);
  }
  EXPECT_EQ(names, (std::vector<std::string>{"gps.lever_arm", "imu.misalignment", "magnetometer.A", "magnetometer.b",
                                             "odometer.k_gamma", "odometer.k_theta", "odometer.kv_over_L"}));
  // The Cramer-Rao std of the lever arm is known and the runs report one of the same size (a 6 s drive).
  const nlohmann::json& lever = j["parameters"][0]["components"][0];
  ASSERT_TRUE(lever["cramer_rao_std"].is_number());
  ASSERT_TRUE(lever["noise_free_error"].is_number());
  EXPECT_LT(std::abs(lever["noise_free_error"].get<double>()), 3.0 * lever["cramer_rao_std"].get<double>());
  EXPECT_NEAR(lever["efficiency"].get<double>(), 1.0, 0.5);
  if (r.out.find("gnuplot not found") == std::string::npos) {
    EXPECT_TRUE(fs::exists(dir_ / "c" / "consistency.png"));
  }

  // One job gives the same file.
  const CommandRun one = Roamlab(Command(1, "c1") + " --quiet", dir_);
  ASSERT_EQ(one.exit_code, 0) << one.err;
  EXPECT_TRUE(one.out.empty()) << one.out;
  EXPECT_EQ(ReadJson(dir_ / "c1" / "consistency.json"), j);
}

TEST_F(ConsistencyCliTest, RefusesWhatItDoesNotSupportWithOneLine) {
  for (const std::string extra :
       {" --backend slurm", " --calibration x.json", " --calibrate-each-run", " --terrain-base 5"}) {
    const CommandRun r = Roamlab(Command(1, "bad") + extra, dir_);
    EXPECT_EQ(r.exit_code, 2) << extra << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
  const CommandRun missing = Roamlab(
      "montecarlo " + (dir_ / "none.yaml").string() + " --config " + config_ +
          " --calibration-consistency --runs 2 --out " + (dir_ / "m").string(),
      dir_);
  EXPECT_EQ(missing.exit_code, 2) << missing.err;
  EXPECT_NE(missing.err.find("none.yaml"), std::string::npos) << missing.err;
}

// The drive of run i as the simulation measured it (its terrain shows in the height range, the roll and the slip).
std::vector<double> Drive(const nlohmann::json& run) {
  std::vector<double> out;
  for (const char* key : {"distance_m", "path_height_range_m", "max_abs_roll_rad", "max_wheel_slip_mps"})
    out.push_back(Value(run["drive"][key]));
  return out;
}

TEST_F(ConsistencyCliTest, RedrawnTerrainsDifferAndTheNoiseAloneDoesNotChangeTheDrive) {
  const std::string base = "montecarlo " + scenario_ + " --config " + config_ +
                           " --calibration-consistency --runs 2 --seed-base 500 --jobs 2 --quiet --out ";
  const CommandRun same = Roamlab(base + (dir_ / "same").string(), dir_);
  ASSERT_EQ(same.exit_code, 0) << same.err;
  const CommandRun redrawn = Roamlab(base + (dir_ / "redrawn").string() + " --redraw-terrain --terrain-base 40", dir_);
  ASSERT_EQ(redrawn.exit_code, 0) << redrawn.err;

  std::vector<nlohmann::json> same_runs, redrawn_runs;
  for (int i = 0; i < 2; ++i) {
    const std::string file = "00000" + std::to_string(i) + ".json";
    same_runs.push_back(ReadJson(dir_ / "same" / "calibrations" / file));
    redrawn_runs.push_back(ReadJson(dir_ / "redrawn" / "calibrations" / file));
    EXPECT_FALSE(same_runs.back().contains("terrain_seed"));
    EXPECT_EQ(redrawn_runs.back()["terrain_seed"], 40 + i);
    EXPECT_EQ(redrawn_runs.back()["seed"], 500 + i);
    ASSERT_TRUE(redrawn_runs.back().contains("parameters")) << redrawn_runs.back();
  }
  // The noise seeds alone leave the physics as it was; the terrains change it.
  EXPECT_EQ(Drive(same_runs[0]), Drive(same_runs[1]));
  EXPECT_NE(Drive(redrawn_runs[0]), Drive(redrawn_runs[1]));
  EXPECT_NE(Drive(redrawn_runs[0])[1], Drive(redrawn_runs[1])[1]) << "the path's height range";
  EXPECT_NE(Drive(redrawn_runs[1]), Drive(same_runs[1]));

  const nlohmann::json j = ReadJson(dir_ / "redrawn" / "consistency.json");
  EXPECT_EQ(j["terrain_seed_base"], 40);
  EXPECT_EQ(j["calibrated_runs"], nlohmann::json({0, 1}));
  EXPECT_EQ(j["failed_runs"], nlohmann::json::array());
  EXPECT_TRUE(ReadJson(dir_ / "same" / "consistency.json")["terrain_seed_base"].is_null());
  for (const nlohmann::json& block : j["parameters"]) ExpectStatisticsOfTheRuns(block, redrawn_runs);

  // A resumed call with other terrains does not take these files for its own.
  const CommandRun other =
      Roamlab(base + (dir_ / "redrawn").string() + " --redraw-terrain --terrain-base 41 --resume", dir_);
  EXPECT_EQ(other.exit_code, 1) << other.err;
  EXPECT_NE(other.err.find("000000.json: not the result of run 0"), std::string::npos) << other.err;
}

// Hills steep enough that the short drive rolls over on terrain seed 1 and not on seeds 2 and 3 (found by simulating
// them: `roamlab simulate` of the short scenario with this relief and each seed).
constexpr char kSteepReliefM[] = "40.0";
constexpr char kSteepTerrainBase[] = "1";

TEST_F(ConsistencyCliTest, ARunThatFailsOnItsTerrainIsCountedAndNamed) {
  // Steep hills: the drive rolls over or leaves the ground on some of these terrains and not on others.
  const std::string steep = Variant("steep", "relief_m: 4.0", "relief_m: " + std::string(kSteepReliefM));
  const CommandRun r = Roamlab("montecarlo " + steep + " --config " + config_ +
                                   " --calibration-consistency --runs 3 --jobs 2 --redraw-terrain --terrain-base " +
                                   std::string(kSteepTerrainBase) + " --out " + (dir_ / "steep").string(),
                               dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = ReadJson(dir_ / "steep" / "consistency.json");
  ASSERT_TRUE(j["failed_runs"].is_array());
  ASSERT_GE(j["failed_runs"].size(), 1u) << j["failed_runs"];
  const std::size_t calibrated = j["calibrated_runs"].size();
  EXPECT_GE(calibrated, 1u);
  EXPECT_EQ(calibrated + j["failed_runs"].size(), 3u) << "every run is either calibrated or named as failed";
  for (const nlohmann::json& block : j["parameters"]) EXPECT_EQ(block["runs"], calibrated);
  for (const nlohmann::json& f : j["failed_runs"]) {
    const int i = f["run"];
    EXPECT_EQ(f["terrain_seed"], std::stoull(kSteepTerrainBase) + i);
    EXPECT_EQ(f["seed"], 1000 + i);
    const std::string reason = f["reason"];
    EXPECT_EQ(reason.rfind("simulation: ", 0), 0u) << reason;
    // Its result file says the same, and the table names it.
    EXPECT_EQ(ReadJson(dir_ / "steep" / "calibrations" / ("00000" + std::to_string(i) + ".json"))["failed"], reason);
    EXPECT_NE(r.out.find("  run " + std::to_string(i) + " (noise seed " + std::to_string(1000 + i) + ", terrain seed " +
                         std::to_string(f["terrain_seed"].get<int>()) + "): " + reason),
              std::string::npos)
        << r.out;
  }
  EXPECT_NE(r.out.find("3 runs (" + std::to_string(calibrated) + " calibrated, " +
                       std::to_string(j["failed_runs"].size()) + " failed)"),
            std::string::npos)
      << r.out;
}

TEST_F(ConsistencyCliTest, RefusesToRedrawWhatItCannot) {
  const std::string hills =
      "type: hills\n    seed: 7\n    size_m: [300.0, 300.0]\n    resolution_m: 1.0\n    relief_m: 4.0\n"
      "    wavelength_m: [20.0, 60.0]\n    waves: 16\n";
  const std::string flat = Variant("flat", hills, "type: flat\n");
  const std::vector<std::string> bad = {
      // The terrain of tracking runs is not redrawn.
      "montecarlo " + scenario_ + " --config " + config_ + " --runs 2 --redraw-terrain --out " + (dir_ / "t").string(),
      // A flat floor has no seed.
      "montecarlo " + flat + " --config " + config_ + " --calibration-consistency --runs 2 --redraw-terrain --out " +
          (dir_ / "f").string()};
  for (const std::string& command : bad) {
    const CommandRun r = Roamlab(command, dir_);
    EXPECT_EQ(r.exit_code, 2) << command << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find("terrain"), std::string::npos) << r.err;
  }
}

}  // namespace
}  // namespace roamlab
