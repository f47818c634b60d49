// A designed drive's predicted std against a Monte-Carlo of it: `roamlab design`'s Cramer-Rao std of a component must
// be the spread of the calibrations over independent noise realizations of the designed drive, within the sampling
// spread of a sample standard deviation of N runs. That holds where the configured noise is the simulation's (white,
// the scenario's sigmas): the motion capture's and the IMU's, which carry the IMU misalignment designed for here (rx
// and ry rest mostly on the motion capture's orientation noise: configured at twice the simulated, their spread falls
// to 0.65 and 0.32 of the prediction and this test fails). Not the wheels': the encoders' tick truncation, which the
// configured white rate noise over-states (docs/results.md, the indoor calibration consistency), so their spread may
// only be smaller than predicted. 10 s of the differential drive with motion capture, a budget of 4 drives, 12 runs.
#include <cmath>
#include <map>
#include <string>

#include <gtest/gtest.h>

#include "common/chi_square.h"
#include "experiment/consistency.h"
#include "experiment/design.h"
#include "tests/recording/temp_dir.h"
#include "tests/support/paths.h"

namespace roamlab::experiment {
namespace {

// configs/indoor_diffdrive_mocap_calibration.yaml with the IMU's noise the scenario's (gyroscope 0.01 rad/s,
// accelerometer 0.05 m/s^2; the motion capture's is already), and its target on the IMU's misalignment.
std::string ImuExactConfig() {
  return "master: odometer\n"
         "solver: {method: levenberg_marquardt, max_iterations: 100, function_tolerance: 1.0e-10}\n"
         "parameters:\n"
         "  odometer.radius_left: {value: 0.075, free: true}\n"
         "  odometer.radius_right: {value: 0.075, free: true}\n"
         "  odometer.baseline: {value: 0.4, free: true}\n"
         "  imu.misalignment: {value: [1, 0, 0, 0], free: true, target_std: 0.002}\n"
         "streams:\n"
         "  odometer:\n    model: differential_drive\n    source: wheel_encoders\n"
         "    noise: {wheel_radps: 0.15, lateral_mps: 0.02, vertical_mps: 0.02, tilt_radps: 0.1}\n"
         "  gyroscope:\n    model: gyroscope\n    source: imu\n    noise: {sigma_radps: 0.01}\n"
         "    parameters: {misalignment: imu.misalignment}\n"
         "  accelerometer:\n    model: accelerometer\n    source: imu\n    noise: {sigma_mps2: 0.05}\n"
         "    parameters: {misalignment: imu.misalignment}\n"
         "  mocap:\n    model: absolute_pose\n    source: mocap\n    noise: {position_m: 0.001, orientation_rad: "
         "0.005}\n";
}

TEST(DesignMonteCarloTest, PredictedStdIsTheSpreadOfTheDesignedDrivesCalibrations) {
  testing::TempDir dir;
  testing::WriteFile(dir.File("config.yaml"), ImuExactConfig());
  DesignRequest request;
  request.scenario = roamlab::testing::SourceDir() + "/scenarios/indoor_diffdrive_mocap.yaml";
  request.duration_s = 10.0;
  request.config = dir.File("config.yaml");
  request.out = dir.File("designed.yaml");
  request.budget = 4;
  DesignResult design;
  const Outcome designed = DesignToFile(request, &design);
  ASSERT_TRUE(designed.ok()) << designed.status.message();
  const DesignCandidate& best = design.candidates[static_cast<std::size_t>(design.best)];
  EXPECT_LE(best.objective, design.candidates.front().objective);
  std::map<std::string, double> predicted(best.crb_std.begin(), best.crb_std.end());

  constexpr int kRuns = 12;
  MonteCarloOptions options;
  options.scenario = request.out;
  options.config = request.config;
  options.out = dir.File("mc");
  options.runs = kRuns;
  options.jobs = 1;
  options.calibration_consistency = true;
  ConsistencySummary summary;
  const Outcome ran = RunCalibrationConsistency(options, &summary);
  ASSERT_TRUE(ran.ok()) << ran.status.message();

  // (N - 1) s^2 / sigma^2 ~ chi-square(N - 1) for a sample std s of N runs: s / sigma within its 99 % interval
  // ([0.49, 1.56] for 12 runs).
  const double lo = std::sqrt(ChiSquareQuantile(0.005, kRuns - 1) / (kRuns - 1));
  const double hi = std::sqrt(ChiSquareQuantile(0.995, kRuns - 1) / (kRuns - 1));
  const char* axes[] = {"rx", "ry", "rz"};
  int imu_components = 0;
  for (const eval::BlockConsistency& block : summary.blocks) {
    ASSERT_EQ(block.runs, kRuns) << block.name;
    for (std::size_t i = 0; i < block.components.size(); ++i) {
      const eval::ComponentConsistency& c = block.components[i];
      const std::string label = block.components.size() == 1 ? block.name : block.name + "[" + axes[i] + "]";
      ASSERT_EQ(predicted.count(label), 1u) << label;
      const double sigma = predicted.at(label);
      // The same bound, the design's at the truth and montecarlo's at the noise-free calibration: their points differ
      // by the physics' bias, a small fraction of the parameter (measured: equal to 3 digits).
      EXPECT_NEAR(c.cramer_rao_std / sigma, 1.0, 0.02) << label;
      const double ratio = c.spread / sigma;
      if (block.name == "imu.misalignment") {  // white noise, configured as simulated
        ++imu_components;
        EXPECT_GE(ratio, lo) << label << ": spread " << c.spread << " against the predicted " << sigma;
        EXPECT_LE(ratio, hi) << label << ": spread " << c.spread << " against the predicted " << sigma;
      } else {  // the wheels: conservative (measured 0.17-0.25), never over-confident
        EXPECT_LE(ratio, hi) << label << ": spread " << c.spread << " against the predicted " << sigma;
      }
    }
  }
  EXPECT_EQ(imu_components, 3);
}

}  // namespace
}  // namespace roamlab::experiment
