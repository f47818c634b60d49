// The twin's clock on the real Husky bag (tests/support/real_data.h, skipped when absent): over 120 s of its turns,
// replayed from the wheel speeds the controller's odometry gives, the IMU's stamps against the twin
// (imu_time_offset) and the recorded drive against the IMU and the GPS (drive_time_offset) are two names of one
// clock, the odometry's lag, fitted with opposite signs. The flat twin's specific force misfits the recorded one by
// several times its stated noise and its chi-square in the shift is not smooth at the physics step, so the step-wide
// curvature (and the HAC sandwich around it) pins each shift far tighter than the two fits agree. The batch-means
// std, the spread of the shift along the run, is what the twin reports, and the two fits agree within it.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gap/twin.h"
#include "importers/rosbag.h"
#include "recording/recording.h"
#include "sim/scenario.h"
#include "tests/recording/temp_dir.h"
#include "tests/support/husky_bag.h"
#include "tests/support/paths.h"
#include "tests/support/real_data.h"

namespace roamlab::gap {
namespace {

// The recording with each stream's rows kept from `from_s` to `to_s` after the first IMU stamp (the bag has no
// camera stream, whose file names would need cutting too).
recording::Recording Cut(const recording::Recording& in, double from_s, double to_s) {
  recording::Recording out = in;
  const double t0 = in.Find("imu")->t.front().seconds();
  for (recording::Stream& s : out.streams) {
    EXPECT_TRUE(s.text.empty()) << s.info.name;
    std::vector<Time> t;
    std::vector<Eigen::Index> keep;
    for (std::size_t i = 0; i < s.t.size(); ++i) {
      const double since_s = s.t[i].seconds() - t0;
      if (since_s < from_s || since_s > to_s) continue;
      t.push_back(s.t[i]);
      keep.push_back(static_cast<Eigen::Index>(i));
    }
    Eigen::MatrixXd values(static_cast<Eigen::Index>(keep.size()), s.values.cols());
    for (std::size_t j = 0; j < keep.size(); ++j) values.row(static_cast<Eigen::Index>(j)) = s.values.row(keep[j]);
    s.t = std::move(t);
    s.values = std::move(values);
  }
  return out;
}

const TwinEffect* Fitted(const TwinDiagnosis& d, const std::string& name) {
  for (const TwinEffect& e : d.candidates)
    if (e.estimate.name == name && e.estimate.parameters.count("offset_s") && e.estimate.std.count("offset_s"))
      return &e;
  return nullptr;
}

TEST(TwinHuskyTest, TheTwoNamesOfTheOdometrysLagAgreeWithinTheirStds) {
  const std::string bag = ::roamlab::testing::RealData("husky_test1/test1.bag");
  if (!std::ifstream(bag)) GTEST_SKIP() << "real data absent: " << bag;
  importers::RosbagImportOptions import = ::roamlab::testing::HuskyImportOptions();
  import.odometry_wheel_separation_m = 0.5708 * 1.875;
  auto imported = importers::ImportRosbag(bag, import);
  ASSERT_TRUE(imported.ok()) << imported.status().message();
  ::roamlab::testing::TempDir dir;
  const std::string path = dir.File("husky");
  ASSERT_TRUE(recording::WriteRecording(imported.value(), path).ok());
  recording::ReadOptions read;
  read.load_ground_truth = false;
  auto whole = recording::ReadRecording(path, read);
  ASSERT_TRUE(whole.ok()) << whole.status().message();
  const recording::Recording real = Cut(whole.value(), 180.0, 300.0);
  auto nominal = sim::LoadScenario(roamlab::testing::SourceDir() + "/scenarios/real/husky.yaml");
  ASSERT_TRUE(nominal.ok()) << nominal.status().message();

  TwinDiagnoseOptions options;
  options.replayed = true;
  options.candidates = {"imu_time_offset", "drive_time_offset"};
  options.max_effects = 1;
  options.std_method = estimator::CalibrationOptions::StdMethod::kHac;
  auto d = DiagnoseTwin(nominal.value(), {{"husky", &real, ReplayRunner(real), true}}, options);
  ASSERT_TRUE(d.ok()) << d.status().message();
  const TwinEffect* imu = Fitted(d.value(), "imu_time_offset");
  const TwinEffect* drive = Fitted(d.value(), "drive_time_offset");
  ASSERT_TRUE(imu && drive) << "both clocks fitted";
  for (const TwinEffect* e : {imu, drive})
    std::printf("%s %+.4f s +- %.4f (white %.2g, HAC %.2g, batch means %.2g)\n", e->estimate.name.c_str(),
                e->estimate.parameters.at("offset_s"), e->estimate.std.at("offset_s"), e->std_white.at("offset_s"),
                e->std_hac.at("offset_s"), e->std_batch.at("offset_s"));
  const double a = imu->estimate.parameters.at("offset_s"), b = drive->estimate.parameters.at("offset_s");
  // The odometry lags the gyroscope: the IMU reads ahead of the twin, the drive behind the IMU.
  EXPECT_LT(a, 0.0);
  EXPECT_GT(b, 0.0);
  const double sa = imu->estimate.std.at("offset_s"), sb = drive->estimate.std.at("offset_s");
  EXPECT_LE(std::abs(a + b), 2.0 * std::hypot(sa, sb));
  // Without the batch means the same two fits are far apart.
  EXPECT_GT(std::abs(a + b), 2.0 * std::hypot(imu->std_hac.at("offset_s"), drive->std_hac.at("offset_s")));
}

}  // namespace
}  // namespace roamlab::gap
