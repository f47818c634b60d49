#include "estimator/information.h"

#include <cmath>
#include <numeric>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "estimator/calibration.h"
#include "tests/estimator/estimation_testing.h"
#include "tests/support/synthetic.h"

namespace roamlab::estimator {
namespace {

roamlab::testing::SyntheticRecording NoiseFreeDrive(bool hilly) {
  roamlab::testing::SyntheticOptions options;
  options.duration_s = 12.0;
  options.noise = false;
  options.hilly = hilly;
  return roamlab::testing::MakeAtvRecording(options);
}

const InformationComponent& Component(const InformationResult& r, const std::string& label) {
  for (const InformationComponent& c : r.components)
    if (c.label == label) return c;
  ADD_FAILURE() << "no component " << label;
  static InformationComponent none;
  return none;
}

const std::vector<std::string> kFree = {"gps.lever_arm", "magnetometer.b", "odometer.kv_over_L", "odometer.k_theta",
                                        "odometer.k_gamma"};

// On a noise-free recording whose models are exact (the synthetic generator), calibrate converges to the truth, so
// the white std it reports comes from the same information at (almost) the same point: the two agree to well under
// 1 % (they differ by the estimate's distance from the truth, ~1e-6 of a std here, and the two Schur paths' rounding).
TEST(InformationTest, CramerRaoBoundIsTheStdCalibrateReportsOnANoiseFreeRecording) {
  const auto drive = NoiseFreeDrive(true);
  const EstimatorConfig config = testing::AtvConfig(kFree);
  auto info = AnalyzeInformation(config, drive.recording, drive.truth.calibration, *drive.recording.ground_truth);
  ASSERT_TRUE(info.ok()) << info.status().message();
  CalibrationOptions calibrate_options;
  calibrate_options.std_method = CalibrationOptions::StdMethod::kWhite;
  auto calibrated = Calibrate(config, drive.recording, calibrate_options);
  ASSERT_TRUE(calibrated.ok()) << calibrated.status().message();
  int compared = 0;
  for (const ParameterEstimate& p : calibrated.value().parameters) {
    for (int k = 0; k < p.std.size(); ++k) {
      const InformationComponent* c = nullptr;
      for (const InformationComponent& candidate : info.value().components)
        if (candidate.parameter == p.name && c == nullptr) c = &candidate + k;
      ASSERT_NE(c, nullptr) << p.name;
      ASSERT_TRUE(std::isfinite(c->crb_std)) << c->label;
      EXPECT_NEAR(c->crb_std / p.std_white[k], 1.0, 0.01) << c->label << ": CRB " << c->crb_std << ", calibrate "
                                                            << p.std_white[k];
      ++compared;
    }
  }
  EXPECT_EQ(compared, 9);
}

// Both shares split each component's information exactly (they sum to 1 over the streams, the variance shares also over
// the windows, and are never negative), and only the factors that measure a parameter (or one correlated with it) get
// a measured share: the magnetometer's b is measured by the magnetometer alone and does not correlate with the other
// streams' parameters.
TEST(InformationTest, SharesAddUpAndAMagnetometerParameterComesFromTheMagnetometerAlone) {
  const auto drive = NoiseFreeDrive(true);
  auto info = AnalyzeInformation(testing::AtvConfig(kFree), drive.recording, drive.truth.calibration,
                                 *drive.recording.ground_truth);
  ASSERT_TRUE(info.ok()) << info.status().message();
  EXPECT_EQ(info.value().windows, 12);
  for (const InformationComponent& c : info.value().components) {
    double by_stream = 0.0, measured = 0.0;
    for (const auto& [stream, share] : c.by_stream) {
      by_stream += share;
      EXPECT_GE(share, 0.0) << c.label << " " << stream;
    }
    for (const auto& [stream, share] : c.measured_by) measured += share;
    EXPECT_NEAR(by_stream, 1.0, 1e-9) << c.label;
    EXPECT_NEAR(measured, 1.0, 1e-9) << c.label;
    EXPECT_NEAR(std::accumulate(c.by_window.begin(), c.by_window.end(), 0.0), 1.0, 1e-9) << c.label;
  }
  for (const std::string axis : {"x", "y", "z"}) {
    const InformationComponent& b = Component(info.value(), "magnetometer.b[" + axis + "]");
    EXPECT_NEAR(b.measured_by.at("magnetometer"), 1.0, 1e-9);
    EXPECT_NEAR(b.measured_by.at("gps"), 0.0, 1e-9);
    EXPECT_NEAR(b.measured_by.at("gyroscope"), 0.0, 1e-9);
  }
  // The lever arm is measured by the GPS alone, the gains by the odometer alone.
  EXPECT_NEAR(Component(info.value(), "gps.lever_arm[x]").measured_by.at("gps"), 1.0, 1e-9);
  EXPECT_NEAR(Component(info.value(), "odometer.kv_over_L").measured_by.at("odometer"), 1.0, 1e-9);
}

// On a flat drive the GPS antenna's height cannot be told from the vehicle's: the component has no CRB, and the
// weakest direction is that component alone, reported unobservable.
TEST(InformationTest, LeverArmHeightOnAFlatDriveIsAnUnobservableDirection) {
  const auto drive = NoiseFreeDrive(false);
  auto info = AnalyzeInformation(testing::AtvConfig({"gps.lever_arm", "odometer.kv_over_L"}), drive.recording,
                                 drive.truth.calibration, *drive.recording.ground_truth);
  ASSERT_TRUE(info.ok()) << info.status().message();
  const InformationComponent& z = Component(info.value(), "gps.lever_arm[z]");
  EXPECT_EQ(z.observability, Observability::kUnobservable);
  EXPECT_TRUE(std::isnan(z.crb_std));
  EXPECT_TRUE(std::isfinite(Component(info.value(), "gps.lever_arm[x]").crb_std));
  ASSERT_FALSE(info.value().directions.empty());
  const InformationDirection& weakest = info.value().directions.front();
  EXPECT_EQ(weakest.observability, Observability::kUnobservable);
  EXPECT_EQ(weakest.name, "1.00 gps.lever_arm[z]");
  // On the hills it is observable, and no direction is unobservable.
  const auto hills = NoiseFreeDrive(true);
  auto hilly = AnalyzeInformation(testing::AtvConfig({"gps.lever_arm", "odometer.kv_over_L"}), hills.recording,
                                  hills.truth.calibration, *hills.recording.ground_truth);
  ASSERT_TRUE(hilly.ok()) << hilly.status().message();
  EXPECT_TRUE(std::isfinite(Component(hilly.value(), "gps.lever_arm[z]").crb_std));
  for (const InformationDirection& d : hilly.value().directions)
    EXPECT_NE(d.observability, Observability::kUnobservable) << d.name;
}

TEST(InformationTest, BadInputsAreErrors) {
  const auto drive = NoiseFreeDrive(true);
  InformationOptions options;
  options.window_s = 0.0;
  EXPECT_FALSE(AnalyzeInformation(testing::AtvConfig(kFree), drive.recording, drive.truth.calibration,
                                  *drive.recording.ground_truth, options)
                   .ok());
  EXPECT_FALSE(
      AnalyzeInformation(testing::AtvConfig(kFree), drive.recording, drive.truth.calibration, Trajectory{}).ok());
  auto wrong = drive.truth.calibration;
  wrong["gps.lever_arm"] = {1.0, 2.0};
  auto result = AnalyzeInformation(testing::AtvConfig(kFree), drive.recording, wrong, *drive.recording.ground_truth);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.status().message().find("gps.lever_arm"), std::string::npos);
  EXPECT_FALSE(AnalyzeInformation(testing::AtvConfig({}), drive.recording, drive.truth.calibration,
                                  *drive.recording.ground_truth)
                   .ok());
}

}  // namespace
}  // namespace roamlab::estimator
