// `roamlab montecarlo --calibration-consistency` end to end on a short ATV drive: consistency.json's statistics are
// those of the runs' own result files, and what it does not support is refused with one line.
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
  for (const std::string extra : {" --backend slurm", " --calibration x.json", " --calibrate-each-run"}) {
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

}  // namespace
}  // namespace roamlab
