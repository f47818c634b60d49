// Honest uncertainty with coloured noise: on seeded simulated drives of the indoor differential drive whose gyroscope
// noise is a first-order Gauss-Markov process (sensors.imu.noise_correlation_s), with a hidden gyroscope scale error
// (a scale effect) and IMU clock offset (a time-shift effect), the fraction of 2-sigma intervals that contain the
// truth, with the white standard deviation (inverse information) and with the HAC one (estimator/covariance.h).
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "estimator/calibration.h"
#include "gap/nominal_config.h"
#include "sim/simulator.h"

namespace roamlab::gap {
namespace {

constexpr int kCases = 20;
constexpr double kCorrelationS = 0.5;  // the gyroscope noise's correlation time
constexpr double kDurationS = 30.0;

struct Coverage {
  int white = 0;
  int hac = 0;
  int cases = 0;
};

const estimator::ParameterEstimate* Find(const estimator::CalibrationResult& r, const std::string& name) {
  for (const auto& p : r.parameters)
    if (p.name == name) return &p;
  return nullptr;
}

void Count(double error, double std_white, double std_hac, Coverage* c) {
  c->white += std::abs(error) <= 2.0 * std_white;
  c->hac += std::abs(error) <= 2.0 * std_hac;
  ++c->cases;
}

// The nominal model with the gyroscope's z scale and the IMU clock offset free; the wheel radius fixed at its nominal
// value (free, it trades one for one against the gyroscope's scale: both set the yaw rate the other reads). The scale's
// x and y, which a planar drive leaves unobservable, are held by a tight prior.
estimator::EstimatorConfig ConfigWithScaleAndOffset(const sim::Scenario& scenario) {
  auto config = NominalConfig(scenario);
  EXPECT_TRUE(config.ok()) << config.status().message();
  estimator::EstimatorConfig c = config.value();
  for (auto& [name, p] : c.parameters)
    if (name.find("radius") != std::string::npos) p.free = false;
  c.stages.clear();  // one stage: every free parameter at once
  c.streams["gyroscope"].parameters["scale"] = "gyroscope.scale";
  estimator::ParameterConfig& scale = c.parameters["gyroscope.scale"];
  scale.value = Eigen::Vector3d::Ones();
  scale.free = true;
  scale.prior_sigma = Eigen::Vector3d(1e-4, 1e-4, std::numeric_limits<double>::infinity());
  estimator::ParameterConfig& offset = c.parameters["imu.time_offset_s"];
  offset.value = Eigen::VectorXd::Zero(1);
  offset.free = true;
  return c;
}

TEST(HonestUncertaintySlowTest, HacIntervalsCoverHiddenScaleAndClockOffsetUnderColouredNoise) {
  auto loaded = sim::LoadScenario(std::string(ROAMLAB_SOURCE_DIR) + "/scenarios/indoor_diffdrive_gap.yaml");
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  sim::Scenario scenario = loaded.value();
  scenario.duration_s = kDurationS;
  scenario.sensors.imu->noise_correlation_s = kCorrelationS;
  const estimator::EstimatorConfig config = ConfigWithScaleAndOffset(scenario);
  Coverage scale, offset;
  std::mt19937_64 draws(2024);
  std::uniform_real_distribution<double> scale_error(-0.03, 0.03);
  std::uniform_int_distribution<int> offset_steps(-20, 20);  // physics steps of 2 ms
  for (int k = 0; k < kCases; ++k) {
    const double true_scale = 1.0 + scale_error(draws);
    const double true_offset_s = 0.002 * offset_steps(draws);
    sim::Scenario hidden = scenario;
    hidden.effects = {{"gyro_scale_error", {{"scale_z", true_scale}}},
                      {"imu_time_offset", {{"offset_s", true_offset_s}}}};
    sim::SimulateOptions options;
    options.seed = 100 + static_cast<std::uint64_t>(k);
    auto simulation = sim::Simulate(hidden, options);
    ASSERT_TRUE(simulation.ok()) << simulation.status().message();
    estimator::CalibrationOptions calibration;
    calibration.std_method = estimator::CalibrationOptions::StdMethod::kHac;
    auto result = estimator::Calibrate(config, simulation.value().recording, calibration);
    ASSERT_TRUE(result.ok()) << result.status().message();
    const estimator::ParameterEstimate* s = Find(result.value(), "gyroscope.scale");
    const estimator::ParameterEstimate* o = Find(result.value(), "imu.time_offset_s");
    ASSERT_TRUE(s != nullptr && o != nullptr);
    Count(s->estimate[2] - true_scale, s->std_white[2], s->std_hac[2], &scale);
    Count(o->estimate[0] - true_offset_s, o->std_white[0], o->std_hac[0], &offset);
    std::printf(
        "case %2d  scale %.4f: %+.5f  std white %.5f hac %.5f   offset %+.3f s: %+.4f  std white %.4f hac %.4f\n", k,
        true_scale, s->estimate[2] - true_scale, s->std_white[2], s->std_hac[2], true_offset_s,
        o->estimate[0] - true_offset_s, o->std_white[0], o->std_hac[0]);
  }
  std::printf("2-sigma coverage over %d cases (gyroscope noise correlated over %.1f s):\n", kCases, kCorrelationS);
  std::printf("  gyroscope scale z:  white %d/%d  hac %d/%d\n", scale.white, kCases, scale.hac, kCases);
  std::printf("  IMU clock offset:   white %d/%d  hac %d/%d\n", offset.white, kCases, offset.hac, kCases);
  // Target: at least 90% of the HAC intervals cover the truth, per effect.
  EXPECT_GE(scale.hac, 18);
  EXPECT_GE(offset.hac, 18);
}

}  // namespace
}  // namespace roamlab::gap
