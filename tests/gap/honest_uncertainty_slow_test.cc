// Honest uncertainty with coloured noise: on seeded simulated drives of the indoor differential drive whose gyroscope
// noise is a first-order Gauss-Markov process (sensors.imu.noise_correlation_s), with a hidden gyroscope scale error
// (a scale effect) and IMU clock offset (a time-shift effect), the fraction of 2-sigma intervals that contain the
// truth, with the white standard deviation (inverse information) and with the HAC one (estimator/covariance.h).
// As in the diagnosis (gap/diagnose.h), each effect is the departure from the fit of a nominal simulation (another
// noise seed, no hidden effect), which carries the nominal model's own bias on MuJoCo's physics (the tires' slip
// shifts the clock offset by several ms); the departure's std combines both fits' (in quadrature).
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "estimator/calibration.h"
#include "gap/nominal_config.h"
#include "sim/simulator.h"
#include "tests/support/paths.h"

namespace roamlab::gap {
namespace {

constexpr int kCases = 20;
constexpr double kCorrelationS = 0.5;  // the gyroscope noise's correlation time
constexpr double kDurationS = 60.0;

// One fit's estimate and white and HAC std of a scalar component.
struct Component {
  double estimate = 0.0;
  double white = 0.0;
  double hac = 0.0;
};

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

// The departure of `fit` from `baseline` against the true departure; prints the case's line.
void Count(const Component& fit, const Component& baseline, double truth, const char* name, Coverage* c) {
  const double error = fit.estimate - baseline.estimate - truth;
  const double white = std::hypot(fit.white, baseline.white);
  const double hac = std::hypot(fit.hac, baseline.hac);
  c->white += std::abs(error) <= 2.0 * white;
  c->hac += std::abs(error) <= 2.0 * hac;
  ++c->cases;
  std::printf("  %s %+.5f: error %+.5f, std white %.5f, hac %.5f\n", name, truth, error, white, hac);
}

// The gyroscope's z scale and the clock offset fitted on `recording` with both standard deviations.
std::pair<Component, Component> Fit(const estimator::EstimatorConfig& config, const recording::Recording& recording,
                                    bool print_lags) {
  estimator::CalibrationOptions options;
  options.std_method = estimator::CalibrationOptions::StdMethod::kHac;
  auto result = estimator::Calibrate(config, recording, options);
  EXPECT_TRUE(result.ok()) << result.status().message();
  if (!result.ok()) return {};
  const estimator::ParameterEstimate* s = Find(result.value(), "gyroscope.scale");
  const estimator::ParameterEstimate* o = Find(result.value(), "imu.time_offset_s");
  EXPECT_TRUE(s != nullptr && o != nullptr);
  if (s == nullptr || o == nullptr) return {};
  if (print_lags)
    for (const auto& [stream, lag] : result.value().hac_lags)
      std::printf("  HAC lag of %s: %d rows\n", stream.c_str(), lag);
  // (std with the HAC method: the larger of std_white and std_hac.)
  return {{s->estimate[2], s->std_white[2], s->std[2]}, {o->estimate[0], o->std_white[0], o->std[0]}};
}

sim::Simulation Simulate(const sim::Scenario& scenario, std::uint64_t seed) {
  sim::SimulateOptions options;
  options.seed = seed;
  auto simulation = sim::Simulate(scenario, options);
  EXPECT_TRUE(simulation.ok()) << simulation.status().message();
  return std::move(simulation).value();
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
  auto loaded = sim::LoadScenario(roamlab::testing::SourceDir() + "/scenarios/indoor_diffdrive_gap.yaml");
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  sim::Scenario scenario = loaded.value();
  scenario.duration_s = kDurationS;
  scenario.sensors.imu->noise_correlation_s = kCorrelationS;
  const estimator::EstimatorConfig config = ConfigWithScaleAndOffset(scenario);
  const auto [scale0, offset0] = Fit(config, Simulate(scenario, 900001).recording, true);
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
    const auto [s, o] = Fit(config, Simulate(hidden, 100 + static_cast<std::uint64_t>(k)).recording, false);
    std::printf("case %d\n", k);
    Count(s, scale0, true_scale - 1.0, "gyroscope scale z - 1", &scale);
    Count(o, offset0, true_offset_s, "IMU clock offset [s]  ", &offset);
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
