#include "estimator/problem.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <set>

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

// The configuration's Ackermann odometer stream, or null.
StreamConfig* AckermannStream(EstimatorConfig& config) {
  for (auto& [name, sc] : config.streams)
    if (sc.model == "ackermann") return &sc;
  return nullptr;
}

TEST(ProblemBuilderTest, OnePosePerMasterSampleAndEveryMeasurementAccountedFor) {
  const auto synthetic = ShortDrive();
  auto builder = ProblemBuilder::Create(testing::AtvConfig({}), synthetic.recording);
  ASSERT_TRUE(builder.ok()) << builder.status().message();
  for (const MeasurementRef& m : builder.value()->Measurements()) builder.value()->Add(m);
  builder.value()->Finish();
  const std::size_t samples = synthetic.recording.Find("rear_wheel")->t.size();
  EXPECT_EQ(builder.value()->poses().size(), samples);
  // Attached + outside (+ rows of a frozen sensor) = samples of the source stream, for every stream: nothing silently
  // dropped.
  const std::map<std::string, std::string> source = {{"odometer", "rear_wheel"},
                                                     {"gyroscope", "imu"},
                                                     {"accelerometer", "imu"},
                                                     {"magnetometer", "magnetometer"},
                                                     {"gps", "gps"}};
  for (const auto& [stream, counts] : builder.value()->counts()) {
    EXPECT_EQ(counts.attached + counts.outside + counts.too_late + counts.rejected + counts.frozen,
              static_cast<int>(synthetic.recording.Find(source.at(stream))->t.size()))
        << stream;
  }
}

// The odometer's disturbance slot, free, as a Gauss-Markov process with its own sigma and tau per row (about the ATV
// configuration's); interval_s 0: one instance per pose.
ParameterConfig GaussMarkovDisturbance(double interval_s) {
  ParameterConfig disturbance;
  disturbance.value = Eigen::VectorXd(Eigen::Vector3d::Zero());
  disturbance.free = true;
  disturbance.process.type = ProcessConfig::Type::kGaussMarkov;
  disturbance.process.sigma = Eigen::Vector3d(0.006, 0.002, 0.025);
  disturbance.process.tau_s = Eigen::Vector3d(0.7, 1.2, 1.8);
  disturbance.process.interval_s = interval_s;
  return disturbance;
}

// The ATV configuration with `disturbance` as its odometer.disturbance, every measurement of `recording` added and
// the graph finished; null (and a failed expectation) when the configuration is refused.
std::unique_ptr<ProblemBuilder> BuildWithDisturbance(const recording::Recording& recording,
                                                     const ParameterConfig& disturbance) {
  EstimatorConfig config = testing::AtvConfig({});
  config.parameters["odometer.disturbance"] = disturbance;
  auto built = ProblemBuilder::Create(config, recording);
  EXPECT_TRUE(built.ok()) << built.status().message();
  if (!built.ok()) return nullptr;
  std::unique_ptr<ProblemBuilder> builder = std::move(built.value());
  for (const MeasurementRef& m : builder->Measurements()) builder->Add(m);
  builder->Finish();
  return builder;
}

// The odometer's disturbance as a Gauss-Markov process with its own sigma and tau per row: one instance per pose,
// joined by process factors whose noise is sigma_i^2 (1 - exp(-2 dt / tau_i)) per component, and a stationary prior
// N(0, sigma^2) on the first instance; the odometer's factors read the instance at their interval's start.
TEST(ProblemBuilderTest, GaussMarkovDisturbanceHasAProcessPerComponentAndAStationaryStart) {
  const auto synthetic = ShortDrive();
  const ParameterConfig disturbance = GaussMarkovDisturbance(0.0);
  const std::unique_ptr<ProblemBuilder> built = BuildWithDisturbance(synthetic.recording, disturbance);
  ASSERT_NE(built, nullptr);
  ProblemBuilder& builder = *built;
  ASSERT_TRUE(builder.IsTimeVarying("odometer.disturbance"));
  const Graph& graph = builder.graph();
  int process = 0, prior = 0, odometer = 0;
  for (const auto& [id, f] : graph.factors()) {
    if (f.stream == "odometer.disturbance" && f.variables.size() == 2) {
      ++process;
      const double dt = SecondsBetween(*graph.variable(f.variables[0]).stamp, *graph.variable(f.variables[1]).stamp);
      for (int i = 0; i < 3; ++i) {
        const double expected =
            std::pow(disturbance.process.sigma[i], 2) * (1.0 - std::exp(-2.0 * dt / disturbance.process.tau_s[i]));
        EXPECT_NEAR(f.noise->covariance(i, i), expected, 1e-12 * expected) << i;
      }
      EXPECT_DOUBLE_EQ(f.noise->covariance(0, 1), 0.0);
    } else if (f.stream == "odometer.disturbance") {
      ++prior;
      EXPECT_EQ(f.variables[0], builder.poses().front().instances.at("odometer.disturbance"));
      EXPECT_TRUE(f.noise->covariance.diagonal().isApprox(disturbance.process.sigma.array().square().matrix()));
    } else if (f.stream == "odometer") {
      ++odometer;
      // Poses k and k+1, the eight scalars, then the disturbance at pose k.
      ASSERT_EQ(f.variables.size(), 11u);
      const Variable& instance = graph.variable(f.variables[10]);
      EXPECT_EQ(instance.name, "odometer.disturbance");
      EXPECT_EQ(*instance.stamp, *graph.variable(f.variables[0]).stamp);
    }
  }
  EXPECT_EQ(process, static_cast<int>(builder.poses().size()) - 1);
  EXPECT_EQ(prior, 1);
  EXPECT_GT(odometer, 0);
}

// process.interval_s: the poses within the interval of an instance's first pose share it, and the Gauss-Markov
// factor between two instances spans their actual time difference. The odometer (master, 100 Hz) misses the samples
// at 0.09-0.11 s, so the second instance starts at the first pose after the gap, 0.12 s after the first.
TEST(ProblemBuilderTest, ProcessIntervalSharesOneInstanceAmongItsPoses) {
  auto synthetic = ShortDrive();
  for (recording::Stream& s : synthetic.recording.streams) {
    if (s.info.name != "rear_wheel") continue;
    std::vector<Time> t;
    std::vector<int> kept;
    for (std::size_t r = 0; r < s.t.size(); ++r) {
      const double since_start = SecondsBetween(s.t.front(), s.t[r]);
      if (since_start > 0.085 && since_start < 0.115) continue;
      t.push_back(s.t[r]);
      kept.push_back(static_cast<int>(r));
    }
    s.values = Eigen::MatrixXd(s.values(kept, Eigen::all));
    s.t = t;
  }
  const ParameterConfig disturbance = GaussMarkovDisturbance(0.1);
  const std::unique_ptr<ProblemBuilder> built = BuildWithDisturbance(synthetic.recording, disturbance);
  ASSERT_NE(built, nullptr);
  ProblemBuilder& builder = *built;
  const Graph& graph = builder.graph();
  const auto& poses = builder.poses();
  const auto instance = [&](std::size_t k) { return poses[k].instances.at("odometer.disturbance"); };
  const Time t0 = poses.front().t;

  // Every pose uses the instance started by the latest pose at most 0.1 s before it; that instance is stamped with
  // that pose's time.
  std::vector<VariableId> instances;
  std::vector<Time> starts;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const bool starts_one = k == 0 || SecondsBetween(starts.back(), poses[k].t) >= 0.1 - 1e-6;
    if (starts_one) {
      instances.push_back(instance(k));
      starts.push_back(poses[k].t);
      EXPECT_EQ(*graph.variable(instance(k)).stamp, poses[k].t) << k;
    }
    EXPECT_EQ(instance(k), instances.back()) << "pose " << k;
  }
  EXPECT_EQ(instance(0), instance(1));
  EXPECT_EQ(instance(0), instance(8));  // 0.08 s, the last pose before the gap
  EXPECT_NE(instance(8), instance(9));  // 0.12 s
  EXPECT_NEAR(SecondsBetween(t0, poses[9].t), 0.12, 1e-9);
  EXPECT_EQ(std::set<VariableId>(instances.begin(), instances.end()).size(), instances.size());
  ASSERT_GE(instances.size(), 15u);  // 2 s of poses

  // One process factor per pair of consecutive instances, over their stamps' difference (0.12 s first, 0.1 s after):
  // noise sigma_i^2 (1 - exp(-2 dt / tau_i)), and x_1 - exp(-dt / tau_i) x_0 (evaluated at x_0 = 1, x_1 = 0).
  int process = 0;
  for (const auto& [id, f] : graph.factors()) {
    if (f.stream != "odometer.disturbance" || f.variables.size() != 2) continue;
    const auto it = std::find(instances.begin(), instances.end(), f.variables[0]);
    ASSERT_NE(it, instances.end());
    ASSERT_NE(it + 1, instances.end());
    EXPECT_EQ(f.variables[1], *(it + 1));
    const double dt = SecondsBetween(starts[it - instances.begin()], starts[it - instances.begin() + 1]);
    EXPECT_NEAR(dt, it == instances.begin() ? 0.12 : 0.1, 1e-6);
    const double x0[3] = {1.0, 1.0, 1.0}, x1[3] = {0.0, 0.0, 0.0};
    const double* values[2] = {x0, x1};
    double error[3], noise_jacobian[9];
    ASSERT_TRUE(f.factor->Evaluate(values, error, nullptr, noise_jacobian));
    for (int i = 0; i < 3; ++i) {
      const double tau = disturbance.process.tau_s[i];
      EXPECT_NEAR(error[i], -std::exp(-dt / tau), 1e-12) << i;
      const double expected = std::pow(disturbance.process.sigma[i], 2) * -std::expm1(-2.0 * dt / tau);
      EXPECT_NEAR(f.noise->covariance(i, i), expected, 1e-12 * expected) << i;
    }
    ++process;
  }
  EXPECT_EQ(process, static_cast<int>(instances.size()) - 1);

  // The odometer's factor of the interval [k, k+1] reads the instance of pose k.
  int odometer = 0;
  for (const auto& [id, f] : graph.factors()) {
    if (f.stream != "odometer") continue;
    const VariableId first = f.variables[0];  // a structured binding cannot be captured in C++17
    const auto k = std::find_if(poses.begin(), poses.end(), [first](const PoseNode& p) { return p.id == first; });
    ASSERT_NE(k, poses.end());
    EXPECT_EQ(f.variables[10], k->instances.at("odometer.disturbance"));
    ++odometer;
  }
  EXPECT_GT(odometer, 0);
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

// "accepted" when the builder takes the configuration, else its error message.
std::string BuildOutcome(const EstimatorConfig& config, const recording::Recording& recording) {
  auto builder = ProblemBuilder::Create(config, recording);
  return builder.ok() ? std::string("accepted") : builder.status().message();
}

// The magnetometer's specific-force input must be an IMU or accelerometer stream of the recording, with the torque
// factor c; c alone is refused too.
TEST(ProblemBuilderTest, MagnetometerSpecificForceInputIsChecked) {
  const auto synthetic = ShortDrive();
  const auto message = [&](const EstimatorConfig& config) { return BuildOutcome(config, synthetic.recording); };
  EstimatorConfig config = testing::AtvConfig({});
  StreamConfig& mag = config.streams["magnetometer"];
  mag.inputs["specific_force"] = "imu";
  mag.options["drive_nm_per_mps2"] = {49.6};
  EXPECT_EQ(message(config), "accepted");
  mag.inputs["specific_force"] = "gps";
  EXPECT_NE(message(config).find("not an imu or accelerometer stream"), std::string::npos) << message(config);
  mag.inputs["specific_force"] = "imu";
  mag.options.erase("drive_nm_per_mps2");
  EXPECT_NE(message(config).find("needs options.drive_nm_per_mps2"), std::string::npos) << message(config);
  mag.inputs.clear();
  mag.options["drive_nm_per_mps2"] = {49.6};
  EXPECT_NE(message(config).find("without inputs.specific_force"), std::string::npos) << message(config);
}

// The Ackermann odometer's specific-force input (the longitudinal slip's proxy) needs O's forward axis in the
// accelerometer's frame, and that axis needs the input.
TEST(ProblemBuilderTest, AckermannSpecificForceInputIsChecked) {
  const auto synthetic = ShortDrive();
  const auto message = [&](const EstimatorConfig& config) { return BuildOutcome(config, synthetic.recording); };
  EstimatorConfig config = testing::AtvConfig({});
  StreamConfig* odo = AckermannStream(config);
  ASSERT_NE(odo, nullptr);
  odo->inputs["specific_force"] = "imu";
  odo->options["forward_in_sensor"] = {1.0, 0.0, 0.0};
  EXPECT_EQ(message(config), "accepted");
  odo->inputs["specific_force"] = "gps";
  EXPECT_NE(message(config).find("not an imu or accelerometer stream"), std::string::npos) << message(config);
  odo->inputs["specific_force"] = "imu";
  odo->options["forward_in_sensor"] = {0.0, 0.0, 0.0};
  EXPECT_NE(message(config).find("needs options.forward_in_sensor"), std::string::npos) << message(config);
  odo->inputs.clear();
  odo->options["forward_in_sensor"] = {1.0, 0.0, 0.0};
  EXPECT_NE(message(config).find("forward_in_sensor without inputs.specific_force"), std::string::npos)
      << message(config);
}

// The Ackermann odometer's understeer form: option front_slip_velocity is 0 or 1.
TEST(ProblemBuilderTest, AckermannFrontSlipVelocityIsChecked) {
  const auto synthetic = ShortDrive();
  const auto message = [&](const EstimatorConfig& config) { return BuildOutcome(config, synthetic.recording); };
  EstimatorConfig config = testing::AtvConfig({});
  StreamConfig* odo = AckermannStream(config);
  ASSERT_NE(odo, nullptr);
  odo->options["front_slip_velocity"] = {1.0};
  EXPECT_EQ(message(config), "accepted");
  odo->options["front_slip_velocity"] = {0.5};
  EXPECT_NE(message(config).find("front_slip_velocity must be 0 or 1"), std::string::npos) << message(config);
}

// A differential drive seen by motion capture over a short stretch (the fixes span well under 1 m, too little for a
// position-only yaw fit) that starts facing backwards: the measured orientations still turn the dead-reckoned
// trajectory (which starts at yaw 0) onto the fixes.
TEST(ProblemBuilderTest, AbsolutePoseOrientationsAlignAShortDeadReckonedStretch) {
  constexpr double kYaw0 = 2.9;
  const Eigen::Vector2d start(1.0, -2.0);
  const recording::Recording rec = testing::DiffDriveArcWithMotionCapture(60, kYaw0, start);  // 0.3 m in all
  auto config = ParseEstimatorConfig(testing::ArcConfigYaml({0.02, 0.001, 0.003}), "test config");
  ASSERT_TRUE(config.ok()) << config.status().message();
  auto builder = ProblemBuilder::Create(config.value(), rec);
  ASSERT_TRUE(builder.ok()) << builder.status().message();
  for (const MeasurementRef& m : builder.value()->Measurements()) builder.value()->Add(m);
  builder.value()->Finish();
  builder.value()->AlignToAbsoluteFixes();
  const ProblemBuilder& b = *builder.value();
  ASSERT_GT(b.poses().size(), 10u);
  const Pose<double> first = PoseFromArray(b.graph().variable(b.poses().front().id).value.data());
  const Eigen::Vector3d x_axis = first.q_world_body * Eigen::Vector3d::UnitX();
  // Exact kinematics on both sides: what is left is the dead reckoning's integration error (sub-millimetre).
  EXPECT_NEAR(std::atan2(x_axis.y(), x_axis.x()), kYaw0, 1e-3);
  EXPECT_NEAR((first.p_world_body.head<2>() - start).norm(), 0.0, 0.005);
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
