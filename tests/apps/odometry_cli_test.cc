// `roamlab import optiodom` and `roamlab odometry learn|evaluate` end to end on synthetic OptiOdom files (a
// differential drive whose real wheel radii and track differ from its metadata), and one clear line with exit code 2
// on a malformed file. The real OptiOdom data, when present, are imported once.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/recording/temp_dir.h"
#include "tests/support/real_data.h"

namespace roamlab {
namespace {

namespace fs = std::filesystem;

using testing::CommandRun;

CommandRun Roamlab(const std::string& args, const fs::path& dir) {
  return testing::RunCommand(std::string(ROAMLAB_BINARY) + " " + args, dir.string());
}

constexpr double kPi = 3.14159265358979323846;
constexpr double kTicksPerWheelRev = 43.7 * 64.0;

void WriteMetadata(const fs::path& path) {
  std::ofstream(path) << "type,diff,,\nngear,43.7,,\nencRes,64,,\nLi,0.2,,\nDi,0.084,0.084,\nN,2,,\n";
}

// A run of an OptiOdom-like differential drive: true radii 0.0415 m (right) and 0.0425 m (left), track 0.205 m,
// 20 Hz; `pattern` 0 mixes straight lines, turns in place and arcs of both signs, 1 drives circles. Ticks are
// quantized with the fraction carried over, the pose integrated exactly per cycle.
void WriteRun(const fs::path& path, int pattern, double duration_s) {
  const double r_right = 0.0415, r_left = 0.0425, track = 0.205, dt = 0.05;
  double x = 0.0, y = 0.0, th = 0.0, carry_r = 0.0, carry_l = 0.0;
  std::ofstream out(path);
  out.precision(17);
  const int steps = static_cast<int>(duration_s / dt);
  for (int k = 0; k <= steps; ++k) {
    const double t = k * dt;
    // Wheel speeds [rad/s] for this cycle.
    double wr = 0.0, wl = 0.0;
    if (pattern == 0) {
      const int phase = static_cast<int>(t / 2.0) % 4;
      if (phase == 0) wr = wl = 5.0;
      if (phase == 1) wr = 3.0, wl = -3.0;
      if (phase == 2) wr = 6.0, wl = 3.0;
      if (phase == 3) wr = 2.0, wl = 5.0;
    } else {
      wr = 6.0;
      wl = 4.0;
    }
    if (k == 0) wr = wl = 0.0;
    // Ticks in this cycle, then the exact motion over it.
    const double exact_r = wr * dt * kTicksPerWheelRev / (2.0 * kPi) + carry_r;
    const double exact_l = wl * dt * kTicksPerWheelRev / (2.0 * kPi) + carry_l;
    const double ticks_r = std::round(exact_r), ticks_l = std::round(exact_l);
    carry_r = exact_r - ticks_r;
    carry_l = exact_l - ticks_l;
    const double v = 0.5 * (r_right * wr + r_left * wl);
    const double w = (r_right * wr - r_left * wl) / track;
    const double dth = w * dt;
    const double forward = std::abs(dth) < 1e-12 ? v * dt : v / w * std::sin(dth);
    const double lateral = std::abs(dth) < 1e-12 ? 0.0 : v / w * (1.0 - std::cos(dth));
    x += forward * std::cos(th) - lateral * std::sin(th);
    y += forward * std::sin(th) + lateral * std::cos(th);
    th += dth;
    out << t << "," << x << "," << y << "," << th << "," << ticks_r << "," << ticks_l << "\n";
  }
}

class OdometryCliTest : public ::testing::Test {
 protected:
  testing::TempDir temp_;
  fs::path dir_{temp_.path()};
};

TEST_F(OdometryCliTest, LearnedModelsBeatTheNominalModelOnAnotherShape) {
  WriteMetadata(dir_ / "syn_metadata.csv");
  WriteRun(dir_ / "syn_run-01.csv", 0, 120.0);
  WriteRun(dir_ / "syn_run-02.csv", 1, 40.0);
  for (const char* run : {"01", "02"}) {
    const CommandRun r = Roamlab("import optiodom " + (dir_ / ("syn_run-" + std::string(run) + ".csv")).string() +
                                     " --out " + (dir_ / ("rec" + std::string(run))).string() + " --quiet",
                                 dir_);
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  const std::string train = (dir_ / "rec01").string();
  for (const std::string model : {"linear", "parametric", "gp --mean linear --kernel rbf --max-pairs 300"}) {
    const std::string file = (dir_ / (model.substr(0, model.find(' ')) + ".json")).string();
    const CommandRun r = Roamlab(
        "odometry learn --recording " + train + " --model " + model + " --interval 0.25 --out " + file + " --quiet",
        dir_);
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  const CommandRun r =
      Roamlab("odometry evaluate --model " + (dir_ / "linear.json").string() + " " +
                  (dir_ / "parametric.json").string() + " " + (dir_ / "gp.json").string() + " --recording " +
                  (dir_ / "rec02").string() + " --out " + (dir_ / "eval").string() + " --no-plots --quiet",
              dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(dir_ / "eval" / "table.json");
  const nlohmann::json table = nlohmann::json::parse(in);
  ASSERT_EQ(table["rows"].size(), 4u);
  EXPECT_EQ(table["rows"][0]["model"], "nominal");
  EXPECT_EQ(table["rows"][3]["model"], "gp");
  EXPECT_EQ(table["rows"][3]["mean"], "linear");
  EXPECT_EQ(table["rows"][3]["kernel"], "rbf");
  // The nominal model (D = 0.084 m both, L = 0.2 m) misses a 2.4 % radius difference and a 2.5 % wider track.
  const double nominal = table["rows"][0]["ate_m"].get<double>();
  EXPECT_GT(nominal, 0.1);
  for (int i = 1; i < 4; ++i) {
    EXPECT_LT(table["rows"][i]["ate_m"].get<double>(), 0.2 * nominal) << table["rows"][i]["model"];
  }
}

TEST_F(OdometryCliTest, MalformedOptiOdomFileGivesOneLineAndExitCode2) {
  WriteMetadata(dir_ / "bad_metadata.csv");
  std::ofstream(dir_ / "bad_run-01.csv") << "0,0,0,0,0,0\n0.05,0.001,0,0,3\n";
  const CommandRun r =
      Roamlab("import optiodom " + (dir_ / "bad_run-01.csv").string() + " --out " + (dir_ / "rec").string(), dir_);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("bad_run-01.csv:2:"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "rec" / "recording.yaml"));
  // A metadata file of an unsupported robot type, and an omni4 one with a single distance (it needs l1 and l2).
  std::ofstream(dir_ / "bad_metadata.csv") << "type,omni5,\nngear,12,\nencRes,1024,\nLi,0.2,\nDi,0.1,0.1,0.1,0.1,\n";
  const CommandRun m =
      Roamlab("import optiodom " + (dir_ / "bad_run-01.csv").string() + " --out " + (dir_ / "rec").string(), dir_);
  EXPECT_EQ(m.exit_code, 2);
  EXPECT_NE(m.err.find("bad_metadata.csv: type 'omni5' is not supported"), std::string::npos) << m.err;
  std::ofstream(dir_ / "bad_metadata.csv") << "type,omni4,\nngear,12,\nencRes,1024,\nLi,0.2,\nDi,0.1,0.1,0.1,0.1,\n";
  const CommandRun l =
      Roamlab("import optiodom " + (dir_ / "bad_run-01.csv").string() + " --out " + (dir_ / "rec").string(), dir_);
  EXPECT_EQ(l.exit_code, 2);
  EXPECT_NE(l.err.find("bad_metadata.csv: Li has 1 distances, type omni4 needs 2"), std::string::npos) << l.err;
}

// The real data: one differential-drive run imports with its metadata and ground truth.
TEST_F(OdometryCliTest, ImportsARealOptiOdomRun) {
  const fs::path set = fs::path(::roamlab::testing::RealData("optiodom/data/diff/circular/231220200121"));
  if (!fs::exists(set)) GTEST_SKIP() << "OptiOdom data not found at " << set << " (../shared/data absent)";
  const CommandRun r = Roamlab("import optiodom " + (set / "231220200121_run-01.csv").string() + " --out " +
                                   (dir_ / "rec").string() + " --quiet",
                               dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream yaml(dir_ / "rec" / "recording.yaml");
  std::stringstream text;
  text << yaml.rdbuf();
  EXPECT_NE(text.str().find("kind: differential_drive"), std::string::npos);
  EXPECT_NE(text.str().find("track_m: 0.2"), std::string::npos);
  EXPECT_TRUE(fs::exists(dir_ / "rec" / "ground_truth.tum"));
}

}  // namespace
}  // namespace roamlab
