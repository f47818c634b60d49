#include "estimator/problem.h"

#include <algorithm>

#include <gtest/gtest.h>

#include "estimator/loss.h"
#include "tests/estimator/estimation_testing.h"
#include "tests/support/synthetic.h"

namespace roamlab::estimator {
namespace {

roamlab::testing::SyntheticRecording ShortDrive() {
  roamlab::testing::SyntheticOptions options;
  options.duration_s = 2.0;
  return roamlab::testing::MakeAtvRecording(options);
}

TEST(ProblemBuilderTest, OnePosePerMasterSampleAndEveryMeasurementAccountedFor) {
  const auto synthetic = ShortDrive();
  auto builder = ProblemBuilder::Create(testing::AtvConfig({}), synthetic.recording);
  ASSERT_TRUE(builder.ok()) << builder.status().message();
  for (const MeasurementRef& m : builder.value()->Measurements()) builder.value()->Add(m);
  builder.value()->Finish();
  const std::size_t samples = synthetic.recording.Find("rear_wheel")->t.size();
  EXPECT_EQ(builder.value()->poses().size(), samples);
  // Attached + outside = samples of the source stream, for every stream: nothing silently dropped.
  const std::map<std::string, std::string> source = {{"odometer", "rear_wheel"}, {"gyroscope", "imu"},
                                                     {"accelerometer", "imu"}, {"magnetometer", "magnetometer"},
                                                     {"gps", "gps"}};
  for (const auto& [stream, counts] : builder.value()->counts()) {
    EXPECT_EQ(counts.attached + counts.outside + counts.too_late + counts.rejected,
              static_cast<int>(synthetic.recording.Find(source.at(stream))->t.size()))
        << stream;
  }
}

TEST(ProblemBuilderTest, AcceptsOutOfOrderMeasurements) {
  // All odometry first, then the GPS fixes newest first: every fix still lands on the pose nearest its time.
  const auto synthetic = ShortDrive();
  auto in_order = ProblemBuilder::Create(testing::AtvConfig({}), synthetic.recording);
  auto shuffled = ProblemBuilder::Create(testing::AtvConfig({}), synthetic.recording);
  ASSERT_TRUE(in_order.ok() && shuffled.ok());
  std::vector<MeasurementRef> ms = in_order.value()->Measurements();
  for (const MeasurementRef& m : ms) in_order.value()->Add(m);
  const auto is_gps = [&](const MeasurementRef& m) { return shuffled.value()->stream_names()[m.stream] == "gps"; };
  std::vector<MeasurementRef> gps, rest;
  for (const MeasurementRef& m : ms) (is_gps(m) ? gps : rest).push_back(m);
  std::reverse(gps.begin(), gps.end());
  for (const MeasurementRef& m : rest) shuffled.value()->Add(m);
  for (const MeasurementRef& m : gps) shuffled.value()->Add(m);
  EXPECT_EQ(shuffled.value()->counts().at("gps").attached, in_order.value()->counts().at("gps").attached);
  auto fixes_a = in_order.value()->absolute_fixes();
  auto fixes_b = shuffled.value()->absolute_fixes();
  ASSERT_EQ(fixes_a.size(), fixes_b.size());
  std::reverse(fixes_b.begin(), fixes_b.end());
  for (std::size_t i = 0; i < fixes_a.size(); ++i) {
    EXPECT_EQ(fixes_a[i].first, fixes_b[i].first);
    EXPECT_TRUE(fixes_a[i].second.isApprox(fixes_b[i].second));
  }
}

TEST(ProblemBuilderTest, RejectsConfigurationThatDoesNotFitTheRecording) {
  const auto synthetic = ShortDrive();
  EstimatorConfig config = testing::AtvConfig({});
  config.streams["gps"].sources[""] = "galileo";
  auto builder = ProblemBuilder::Create(config, synthetic.recording);
  ASSERT_FALSE(builder.ok());
  EXPECT_NE(builder.status().message().find("'galileo'"), std::string::npos) << builder.status().message();
  config = testing::AtvConfig({});
  config.streams["gps"].sources[""] = "imu";
  builder = ProblemBuilder::Create(config, synthetic.recording);
  ASSERT_FALSE(builder.ok());
  EXPECT_NE(builder.status().message().find("cannot read"), std::string::npos) << builder.status().message();
}

TEST(LossTest, HuberAndCauchyAreQuadraticNearZeroAndDownweightLargeErrors) {
  double rho = 0, d = 0;
  Loss::Huber(2.0).Evaluate(1.0, &rho, &d);
  EXPECT_DOUBLE_EQ(rho, 1.0);
  EXPECT_DOUBLE_EQ(d, 1.0);
  Loss::Huber(2.0).Evaluate(16.0, &rho, &d);  // |r| = 4: rho = 2 c |r| - c^2 = 12, rho' = c / |r| = 0.5
  EXPECT_DOUBLE_EQ(rho, 12.0);
  EXPECT_DOUBLE_EQ(d, 0.5);
  Loss::Cauchy(1.0).Evaluate(3.0, &rho, &d);  // rho = log(1 + s), rho' = 1 / (1 + s)
  EXPECT_NEAR(rho, std::log(4.0), 1e-15);
  EXPECT_NEAR(d, 0.25, 1e-15);
  // Derivative consistency by central differences.
  for (const Loss& loss : {Loss::Huber(1.5), Loss::Cauchy(0.7)}) {
    for (double s : {0.3, 5.0, 40.0}) {
      double rp = 0, rm = 0, dd = 0, unused = 0;
      loss.Evaluate(s + 1e-6, &rp, &unused);
      loss.Evaluate(s - 1e-6, &rm, &unused);
      loss.Evaluate(s, &unused, &dd);
      EXPECT_NEAR((rp - rm) / 2e-6, dd, 1e-6);
    }
  }
}

}  // namespace
}  // namespace roamlab::estimator
