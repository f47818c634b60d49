// The IMU's time offset as a calibration parameter (models/imu_time_offset.h) on the synthetic ATV.
#include <cmath>

#include <gtest/gtest.h>

#include "estimator/calibration.h"
#include "tests/estimator/estimation_testing.h"
#include "tests/support/synthetic.h"

namespace roamlab::estimator {
namespace {

const ParameterEstimate* Find(const CalibrationResult& r, const std::string& name) {
  for (const auto& p : r.parameters)
    if (p.name == name) return &p;
  return nullptr;
}

roamlab::testing::SyntheticRecording Drive(double imu_time_offset_s) {
  roamlab::testing::SyntheticOptions options;
  options.duration_s = 6.0;
  options.seed = 7;
  options.imu_time_offset_s = imu_time_offset_s;
  return roamlab::testing::MakeAtvRecording(options);
}

// Freed at 0, the offset's models cost what the plain ones do and take every sample the plain ones take.
TEST(TimeOffsetTest, FreeAtZeroItCostsAndAttachesAsWithoutIt) {
  const auto synthetic = Drive(0.0);
  auto fixed = Calibrate(testing::AtvConfig({"odometer.k_theta"}), synthetic.recording);
  auto free = Calibrate(testing::AtvConfig({"odometer.k_theta", "imu.time_offset_s"}), synthetic.recording);
  ASSERT_TRUE(fixed.ok()) << fixed.status().message();
  ASSERT_TRUE(free.ok()) << free.status().message();
  EXPECT_NEAR(free.value().initial_cost, fixed.value().initial_cost, 1e-9 * fixed.value().initial_cost);
  for (const auto& [stream, counts] : fixed.value().counts) {
    EXPECT_EQ(free.value().counts.at(stream).attached, counts.attached) << stream;
    EXPECT_EQ(free.value().counts.at(stream).outside, counts.outside) << stream;
  }
}

// An offset off the 10 ms grid, either sign, is recovered within 3 reported standard deviations on a 6 s drive. The
// reference is the estimate on the same drive and noise without an offset (this noise draw alone moves the estimate
// by about 2 std), so that the comparison is of the offset's effect alone.
TEST(TimeOffsetTest, RecoversAnOffsetOffTheGridWithinItsReportedUncertainty) {
  const std::vector<std::string> free = {"odometer.k_theta", "imu.time_offset_s"};
  auto reference = Calibrate(testing::AtvConfig(free), Drive(0.0).recording);
  ASSERT_TRUE(reference.ok()) << reference.status().message();
  const ParameterEstimate* zero = Find(reference.value(), "imu.time_offset_s");
  ASSERT_NE(zero, nullptr);
  for (double offset : {-0.023, 0.031}) {
    auto result = Calibrate(testing::AtvConfig(free), Drive(offset).recording);
    ASSERT_TRUE(result.ok()) << result.status().message();
    const ParameterEstimate* p = Find(result.value(), "imu.time_offset_s");
    ASSERT_NE(p, nullptr);
    ASSERT_TRUE(std::isfinite(p->std[0]) && p->std[0] < 0.005) << p->std[0];
    EXPECT_LT(std::abs(p->estimate[0] - zero->estimate[0] - offset), 3.0 * p->std[0])
        << "offset " << offset << ": " << p->estimate[0] << " +- " << p->std[0] << ", without " << zero->estimate[0];
  }
}

}  // namespace
}  // namespace roamlab::estimator
