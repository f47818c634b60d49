#include "estimator/tracking.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>

#include "common/chi_square.h"
#include "estimator/calibration.h"
#include "estimator/problem.h"
#include "estimator/solver.h"
#include "tests/estimator/estimation_testing.h"
#include "tests/estimator/factor_testing.h"
#include "tests/support/paths.h"
#include "tests/support/synthetic.h"

namespace roamlab::estimator {
namespace {

// Position error of each tracked pose against the ground truth at the same time stamp.
std::vector<Eigen::Vector3d> PositionErrors(const TrackingResult& r, const Trajectory& truth) {
  std::vector<Eigen::Vector3d> errors;
  std::size_t j = 0;
  for (const StampedPose& p : r.trajectory) {
    while (j < truth.size() && truth[j].t < p.t) ++j;
    EXPECT_LT(j, truth.size());
    EXPECT_EQ(truth[j].t, p.t);
    errors.push_back(p.p_world_body - truth[j].p_world_body);
  }
  return errors;
}

// A sliding window's last pose against the whole track's (no marginalization): within 0.2 of the whole track's
// position std (Mahalanobis), and its position std within 10 % of the whole track's.
void ExpectEndsLikeTheWholeTrack(const TrackingResult& sliding, const TrackingResult& whole) {
  const StampedPose& a = sliding.trajectory.back();
  const StampedPose& b = whole.trajectory.back();
  ASSERT_EQ(a.t, b.t);
  const Eigen::Matrix3d& cov = whole.position_covariance.back();
  const Eigen::Vector3d d = a.p_world_body - b.p_world_body;
  EXPECT_LT(std::sqrt(d.dot(cov.ldlt().solve(d))), 0.2);
  EXPECT_NEAR(std::sqrt(sliding.position_covariance.back().trace()), std::sqrt(cov.trace()),
              0.1 * std::sqrt(cov.trace()));
}

TEST(TrackingTest, NoiseFreeTrackingFollowsTheTruth) {
  roamlab::testing::SyntheticOptions options;
  options.duration_s = 4.0;
  options.noise = false;
  const auto synthetic = roamlab::testing::MakeAtvRecording(options);
  auto result = Track(testing::AtvConfig({}, 20), synthetic.recording, {});
  ASSERT_TRUE(result.ok()) << result.status().message();
  // One pose per master sample.
  EXPECT_EQ(result.value().trajectory.size(), synthetic.recording.Find("rear_wheel")->t.size());
  double worst = 0.0;
  for (const Eigen::Vector3d& e : PositionErrors(result.value(), *synthetic.recording.ground_truth))
    worst = std::max(worst, e.norm());
  EXPECT_LT(worst, 0.02);
  EXPECT_GT(result.value().updates, 0);
}

TEST(TrackingTest, NoisyPositionErrorsAreConsistentWithReportedCovariance) {
  roamlab::testing::SyntheticOptions options;
  options.duration_s = 10.0;
  options.seed = 3;
  const auto synthetic = roamlab::testing::MakeAtvRecording(options);
  auto result = Track(testing::AtvConfig({}, 30), synthetic.recording, {});
  ASSERT_TRUE(result.ok()) << result.status().message();
  const auto errors = PositionErrors(result.value(), *synthetic.recording.ground_truth);
  // Errors are strongly correlated in time, so this is a gross check, not the Monte-Carlo NEES test: at least 90% of
  // the poses within the 99.7% chi-square(3) ellipsoid of their own covariance.
  const double gate = ChiSquareQuantile(0.997, 3);
  int inside = 0;
  for (std::size_t i = 0; i < errors.size(); ++i) {
    const double nees = errors[i].dot(result.value().position_covariance[i].ldlt().solve(errors[i]));
    inside += nees <= gate;
  }
  EXPECT_GE(inside, static_cast<int>(0.9 * errors.size()));
}

TEST(TrackingTest, MarginalizationKeepsTheInformationOfTheWindow) {
  // A short window with marginalization must end where a window holding everything ends: the prior carries what
  // the removed poses knew (exact for a linear problem, to within a small fraction of a standard deviation here).
  roamlab::testing::SyntheticOptions options;
  options.duration_s = 3.0;
  options.seed = 5;
  const auto synthetic = roamlab::testing::MakeAtvRecording(options);
  auto sliding = Track(testing::AtvConfig({}, 10), synthetic.recording, {});
  auto whole = Track(testing::AtvConfig({}, 100000), synthetic.recording, {});
  ASSERT_TRUE(sliding.ok() && whole.ok());
  ExpectEndsLikeTheWholeTrack(sliding.value(), whole.value());
}

// The ATV configuration with the gyroscope's bias slot mapped to imu.gyro_bias, declared free and time-varying: a
// random walk of density 1e-3 rad/s/sqrt(s), starting from zero (as in the configuration comment of config.h).
EstimatorConfig WithRandomWalkGyroBias(EstimatorConfig config) {
  config.streams["gyroscope"].parameters["bias"] = "imu.gyro_bias";
  ParameterConfig bias;
  bias.value = Eigen::VectorXd(Eigen::Vector3d::Zero());
  bias.free = true;
  bias.process.type = ProcessConfig::Type::kRandomWalk;
  bias.process.sigma = Eigen::Vector3d::Constant(1.0e-3);
  config.parameters["imu.gyro_bias"] = bias;
  return config;
}

// A 10 s drive with a constant gyro bias of (0.02, -0.01, 0.015) rad/s in the IMU frame, 0.3 to 0.6 of the gyro's
// per-sample noise.
roamlab::testing::SyntheticRecording GyroBiasDrive() {
  roamlab::testing::SyntheticOptions options;
  options.duration_s = 10.0;
  options.seed = 7;
  options.gyro_bias_radps = Eigen::Vector3d(0.02, -0.01, 0.015);
  return roamlab::testing::MakeAtvRecording(options);
}

TEST(TrackingTest, RandomWalkGyroBiasIsRecoveredWithinFourSigma) {
  // Track() does not report the tracked bias instances, and Calibrate() reports constant parameters only, so this
  // builds the offline graph as Calibrate() does (every measurement, one bias instance per pose joined by random-walk
  // factors, alignment to the GPS, one solve) and checks the instance at the last pose against the truth with its
  // marginal covariance. Calibrate() on the same configuration must reach the same optimum.
  const auto synthetic = GyroBiasDrive();
  const Eigen::Vector3d truth(synthetic.truth.calibration.at("imu.gyro_bias").data());
  const EstimatorConfig config = WithRandomWalkGyroBias(testing::AtvConfig({}, 20));
  auto built = ProblemBuilder::Create(config, synthetic.recording);
  ASSERT_TRUE(built.ok()) << built.status().message();
  ProblemBuilder& builder = *built.value();
  for (const MeasurementRef& m : builder.Measurements()) builder.Add(m);
  builder.Finish();
  builder.AlignToAbsoluteFixes();
  const SolverSummary summary = Solve(config.solver, &builder.graph());
  testing::ExpectEndedOnTolerance(summary);

  const VariableId last = builder.poses().back().instances.at("imu.gyro_bias");
  const Eigen::VectorXd sigma = testing::ExpectWithinSigmas(builder.graph(), {last}, {truth});
  // The drive resolves the bias: every component is more than 3 sigma away from the zero the solve started at.
  ASSERT_EQ(sigma.size(), 3);
  for (int i = 0; i < 3; ++i) EXPECT_LT(3.0 * sigma[i], std::abs(truth[i])) << "sigma " << sigma.transpose();

  auto calibrated = Calibrate(config, synthetic.recording);
  ASSERT_TRUE(calibrated.ok()) << calibrated.status().message();
  EXPECT_NEAR(calibrated.value().final_cost, summary.final_cost, 1e-6 * summary.final_cost);
}

TEST(TrackingTest, MarginalizationKeepsTheInformationWithSharedInstances) {
  // As MarginalizationKeepsTheInformationOfTheWindow, with a random-walk gyro bias whose instances are 0.1 s apart,
  // each shared by 10 poses: an instance leaves the 15-pose window with the last pose that uses it, and the end of the
  // track matches the window holding everything.
  roamlab::testing::SyntheticOptions options;
  options.duration_s = 3.0;
  options.seed = 5;
  options.gyro_bias_radps = Eigen::Vector3d(0.02, -0.01, 0.015);
  const auto synthetic = roamlab::testing::MakeAtvRecording(options);
  EstimatorConfig sliding_config = WithRandomWalkGyroBias(testing::AtvConfig({}, 15));
  sliding_config.parameters["imu.gyro_bias"].process.interval_s = 0.1;
  EstimatorConfig whole_config = sliding_config;
  whole_config.tracking.window = 100000;
  auto sliding = Track(sliding_config, synthetic.recording, {});
  auto whole = Track(whole_config, synthetic.recording, {});
  ASSERT_TRUE(sliding.ok()) << sliding.status().message();
  ASSERT_TRUE(whole.ok()) << whole.status().message();
  ASSERT_EQ(sliding.value().trajectory.size(), whole.value().trajectory.size());
  ExpectEndsLikeTheWholeTrack(sliding.value(), whole.value());
}

TEST(TrackingTest, TrackingTheGyroBiasComesCloseToKnowingIt) {
  // Tracking with the bias free as a random walk, against tracking with the bias fixed at its true value (the oracle)
  // and with it fixed at zero (ignored). The position error against the truth cannot show the difference: it is
  // dominated by the GPS noise, about 0.15 m RMS in all three runs. The three runs share that noise, so their
  // difference isolates what the bias does: measured in the oracle's own position standard deviations, tracking the
  // bias must stay less than half as far from the oracle as ignoring it does, everywhere along the drive.
  const auto synthetic = GyroBiasDrive();
  const EstimatorConfig tracked = WithRandomWalkGyroBias(testing::AtvConfig({}, 20));
  EstimatorConfig oracle = tracked;
  oracle.parameters["imu.gyro_bias"] = ParameterConfig{
      Eigen::VectorXd(Eigen::Vector3d(synthetic.truth.calibration.at("imu.gyro_bias").data())), false, {}, {}, {}};
  const EstimatorConfig ignored = testing::AtvConfig({}, 20);

  auto with_oracle = Track(oracle, synthetic.recording, {});
  auto with_tracked = Track(tracked, synthetic.recording, {});
  auto with_ignored = Track(ignored, synthetic.recording, {});
  ASSERT_TRUE(with_oracle.ok() && with_tracked.ok() && with_ignored.ok());
  const TrackingResult& reference = with_oracle.value();
  const auto worst_distance = [&reference](const TrackingResult& r) {
    EXPECT_EQ(r.trajectory.size(), reference.trajectory.size());
    double worst = 0.0;
    for (std::size_t k = 0; k < std::min(r.trajectory.size(), reference.trajectory.size()); ++k) {
      const Eigen::Vector3d d = r.trajectory[k].p_world_body - reference.trajectory[k].p_world_body;
      worst = std::max(worst, std::sqrt(d.dot(reference.position_covariance[k].ldlt().solve(d))));
    }
    return worst;
  };
  const double tracked_distance = worst_distance(with_tracked.value());
  const double ignored_distance = worst_distance(with_ignored.value());
  EXPECT_LT(tracked_distance, 0.5 * ignored_distance) << tracked_distance << " vs " << ignored_distance;
}

}  // namespace
}  // namespace roamlab::estimator

namespace roamlab::estimator {
namespace {

// A calibration of the GPS lever arm and the IMU misalignment on one 8 s drive, as tracking of another drive uses it.
struct CalibratedAtv {
  std::map<std::string, Eigen::VectorXd> values;
  CalibrationPrior prior;
};

CalibratedAtv CalibrateOnOtherDrive() {
  roamlab::testing::SyntheticOptions options;
  options.duration_s = 8.0;
  options.seed = 21;
  const auto synthetic = roamlab::testing::MakeAtvRecording(options);
  auto result = Calibrate(testing::AtvConfig({"gps.lever_arm", "imu.misalignment"}), synthetic.recording);
  EXPECT_TRUE(result.ok()) << result.status().message();
  CalibratedAtv out;
  for (const ParameterEstimate& p : result.value().parameters) {
    out.values[p.name] = p.estimate;
    out.prior.names.push_back(p.name);
  }
  out.prior.information = result.value().information;
  return out;
}

// A noisy 6 s synthetic ATV drive.
roamlab::testing::SyntheticRecording SixSecondDrive(std::uint32_t seed) {
  roamlab::testing::SyntheticOptions options;
  options.duration_s = 6.0;
  options.seed = seed;
  return roamlab::testing::MakeAtvRecording(options);
}

// The ATV configuration with a 20-pose window and no time budget (every update solved as far as it goes).
EstimatorConfig UnbudgetedConfig() {
  EstimatorConfig config = testing::AtvConfig({}, 20);
  config.tracking.time_budget_s = 1e9;
  return config;
}

TEST(TrackingTest, CalibrationPriorWidensThePositionCovarianceByTheCalibrationUncertainty) {
  // Fixing a parameter conditions on it; leaving it free under its calibration prior marginalizes it instead, and a
  // marginal covariance is never smaller than a conditional one: every tracked pose's position covariance must grow
  // (in the PSD order, checked on the trace and the smallest eigenvalue of the difference).
  const CalibratedAtv calibrated = CalibrateOnOtherDrive();
  const auto synthetic = SixSecondDrive(22);
  EstimatorConfig config = UnbudgetedConfig();
  auto fixed = Track(config, synthetic.recording, calibrated.values);
  config.tracking.calibration_prior = true;
  TrackingOptions with_prior;
  with_prior.calibration_prior = calibrated.prior;
  auto marginal = Track(config, synthetic.recording, calibrated.values, with_prior);
  ASSERT_TRUE(fixed.ok()) << fixed.status().message();
  ASSERT_TRUE(marginal.ok()) << marginal.status().message();
  ASSERT_EQ(fixed.value().trajectory.size(), marginal.value().trajectory.size());
  double growth = 0.0;
  for (std::size_t i = 0; i < fixed.value().trajectory.size(); ++i) {
    const Eigen::Matrix3d difference = marginal.value().position_covariance[i] - fixed.value().position_covariance[i];
    const double scale = fixed.value().position_covariance[i].trace();
    EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(difference).eigenvalues().minCoeff(), -1e-6 * scale)
        << "pose " << i;
    growth = std::max(growth, difference.trace() / scale);
  }
  // The lever arm's uncertainty (about 0.05 m horizontally after 8 s) is not negligible against the GPS-held position.
  EXPECT_GT(growth, 0.05);
}

// With a relinearization threshold of 0.01 (iSAM2's) most factors of an update keep their Jacobians and carry their
// error to first order. Under the calibration prior on a noisy drive, the tracked poses must stay within a small part
// of their own position std of the fully relinearized ones (0.25 sigma, Mahalanobis), their covariances within 10 %,
// and most linearizations must be carries.
TEST(TrackingTest, RelinearizationThresholdStaysCloseToRelinearizingEveryFactor) {
  const CalibratedAtv calibrated = CalibrateOnOtherDrive();
  const auto synthetic = SixSecondDrive(23);
  EstimatorConfig config = UnbudgetedConfig();
  config.tracking.calibration_prior = true;
  TrackingOptions with_prior;
  with_prior.calibration_prior = calibrated.prior;
  auto every = Track(config, synthetic.recording, calibrated.values, with_prior);
  config.tracking.relinearize_threshold = 0.01;
  auto carried = Track(config, synthetic.recording, calibrated.values, with_prior);
  ASSERT_TRUE(every.ok()) << every.status().message();
  ASSERT_TRUE(carried.ok()) << carried.status().message();
  EXPECT_EQ(every.value().factor_carries, 0);
  EXPECT_GT(carried.value().factor_carries, 2 * carried.value().factor_evaluations);
  ASSERT_EQ(every.value().trajectory.size(), carried.value().trajectory.size());
  for (std::size_t i = 0; i < every.value().trajectory.size(); ++i) {
    const Eigen::Matrix3d& cov = every.value().position_covariance[i];
    const Eigen::Vector3d d = carried.value().trajectory[i].p_world_body - every.value().trajectory[i].p_world_body;
    EXPECT_LT(std::sqrt(d.dot(cov.ldlt().solve(d))), 0.25) << "pose " << i;
    EXPECT_NEAR(carried.value().position_covariance[i].trace(), cov.trace(), 0.1 * cov.trace()) << "pose " << i;
  }
}

// The recording without the rows of `stream` stamped in [start_s, start_s + duration_s) after its first stamp: an
// outage (a dropout, or a frozen sensor's repeated rows left out).
void RemoveRows(const std::string& stream, double start_s, double duration_s, recording::Recording* rec) {
  const auto found = std::find_if(rec->streams.begin(), rec->streams.end(),
                                  [&](const recording::Stream& s) { return s.info.name == stream; });
  ASSERT_NE(found, rec->streams.end()) << stream;
  recording::Stream& s = *found;
  const Time first = s.t.front();
  std::vector<Time> t;
  std::vector<Eigen::Index> kept;
  for (std::size_t i = 0; i < s.t.size(); ++i) {
    const double since = SecondsBetween(first, s.t[i]);
    if (since >= start_s && since < start_s + duration_s) continue;
    t.push_back(s.t[i]);
    kept.push_back(static_cast<Eigen::Index>(i));
  }
  Eigen::MatrixXd values(static_cast<Eigen::Index>(kept.size()), s.values.cols());
  for (std::size_t r = 0; r < kept.size(); ++r) values.row(static_cast<Eigen::Index>(r)) = s.values.row(kept[r]);
  s.t = std::move(t);
  s.values = std::move(values);
}

// Tracking through a 2 s IMU dropout with the gate on: no gyroscope or accelerometer sample joins the poses of the
// gap, whose relative rotation only the other sensors constrain, and the gate tests the odometer's factor of each new
// pose. Every pose must come out with a finite, positive-definite position covariance, and its error must be
// consistent with it as on a drive without the gap.
TEST(TrackingTest, TracksThroughAnImuDropoutWithFiniteConsistentCovariances) {
  roamlab::testing::SyntheticOptions options;
  options.duration_s = 8.0;
  options.seed = 3;
  auto synthetic = roamlab::testing::MakeAtvRecording(options);
  RemoveRows("imu", 3.0, 2.0, &synthetic.recording);
  EstimatorConfig config = UnbudgetedConfig();
  config.gate_probability = 0.99999;
  auto result = Track(config, synthetic.recording, {});
  ASSERT_TRUE(result.ok()) << result.status().message();
  const auto errors = PositionErrors(result.value(), *synthetic.recording.ground_truth);
  const double gate = ChiSquareQuantile(0.997, 3);
  int inside = 0;
  for (std::size_t i = 0; i < errors.size(); ++i) {
    const Eigen::Matrix3d& cov = result.value().position_covariance[i];
    ASSERT_TRUE(cov.allFinite()) << "pose " << i;
    ASSERT_GT(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvalues().minCoeff(), 0.0) << "pose " << i;
    inside += errors[i].dot(cov.ldlt().solve(errors[i])) <= gate;
  }
  EXPECT_GE(inside, static_cast<int>(0.9 * errors.size()));
}

// Tracking with gross outliers on every 10th steering row (0.5 rad, 35 times the simulated noise): each bends the
// update's estimate of its pose until the gyroscope's row of the same interval may fail the gate too. The gate must
// reject the outlier's odometer factor and keep the gyroscope's, so that no pose loses its information.
TEST(TrackingTest, GatesMasterOutliersWithoutRejectingTheGoodRowsOfTheirPoses) {
  roamlab::testing::SyntheticOptions options;
  options.duration_s = 8.0;
  options.seed = 3;
  auto synthetic = roamlab::testing::MakeAtvRecording(options);
  const auto steering = std::find_if(synthetic.recording.streams.begin(), synthetic.recording.streams.end(),
                                     [](const recording::Stream& s) { return s.info.name == "steering"; });
  ASSERT_NE(steering, synthetic.recording.streams.end());
  int outliers = 0;
  for (Eigen::Index row = 5; row < steering->values.rows(); row += 10, ++outliers)
    steering->values(row, 0) += row % 20 == 5 ? 0.5 : -0.5;
  EstimatorConfig config = UnbudgetedConfig();
  config.gate_probability = 0.99999;
  auto result = Track(config, synthetic.recording, {});
  ASSERT_TRUE(result.ok()) << result.status().message();
  EXPECT_EQ(result.value().counts.at("gyroscope").rejected, 0);
  EXPECT_LE(result.value().counts.at("odometer").rejected, 2 * outliers);
  for (std::size_t i = 0; i < result.value().position_covariance.size(); ++i)
    ASSERT_TRUE(result.value().position_covariance[i].allFinite()) << "pose " << i;
}

// Tracking with gross outliers on a tenth of the speed rows (1 m/s, 30 times the simulated noise) and of the steering
// rows (0.5 rad), drawn at random. Such a row predicts its new pose, and at the update that attaches it only the IMU's
// rows of the pose before tie the new pose's motion to the past: the two conflict alone, the solve splits the error
// between them, and either may fail worst. The gate must reject exactly the outlying rows, none of the IMU's and none
// of the good rows after them.
TEST(TrackingTest, GatesMasterOutliersOnlyOnceTheNextSampleSidesWithTheGoodRows) {
  roamlab::testing::SyntheticOptions options;
  options.duration_s = 8.0;
  options.seed = 3;
  auto synthetic = roamlab::testing::MakeAtvRecording(options);
  recording::Stream* speed = nullptr;
  recording::Stream* steering = nullptr;
  for (recording::Stream& s : synthetic.recording.streams) {
    if (s.info.name == "rear_wheel") speed = &s;
    if (s.info.name == "steering") steering = &s;
  }
  ASSERT_TRUE(speed != nullptr && steering != nullptr);
  ASSERT_EQ(speed->t, steering->t);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  int outlying_rows = 0;
  // From row 1: the first row's factor joins the first two poses, before any update.
  for (Eigen::Index row = 1; row < speed->values.rows(); ++row) {
    const bool on_speed = uniform(rng) < 0.1, on_steering = uniform(rng) < 0.1;
    if (on_speed) speed->values(row, 0) += uniform(rng) < 0.5 ? 1.0 : -1.0;
    if (on_steering) steering->values(row, 0) += uniform(rng) < 0.5 ? 0.5 : -0.5;
    outlying_rows += on_speed || on_steering;
  }
  // The ATV's tracking configuration (its odometer's disturbance states, its IMU rows' noise), the mountings at the
  // synthetic drive's.
  auto loaded = LoadEstimatorConfig(roamlab::testing::SourceDir() + "/configs/atv_tracking.yaml");
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  EstimatorConfig config = loaded.value();
  const EstimatorConfig synthetic_config = UnbudgetedConfig();
  for (const char* name : {"gps.lever_arm", "imu.misalignment", "magnetometer.A", "magnetometer.b"})
    config.parameters[name].value = synthetic_config.parameters.at(name).value;
  config.tracking.time_budget_s = 1e9;
  auto result = Track(config, synthetic.recording, {});
  ASSERT_TRUE(result.ok()) << result.status().message();
  EXPECT_EQ(result.value().counts.at("accelerometer").rejected, 0);
  EXPECT_EQ(result.value().counts.at("gyroscope").rejected, 0);
  EXPECT_EQ(result.value().counts.at("odometer").rejected, outlying_rows);
  for (std::size_t i = 0; i < result.value().position_covariance.size(); ++i)
    ASSERT_TRUE(result.value().position_covariance[i].allFinite()) << "pose " << i;
}

// Tracking a differential drive (cumulative wheel angles) under motion capture, with three readings in a row off by
// 0.5 rad (10 rad/s, 20 sigma, on the spans they end and start), the first and the third on the left wheel backwards
// and the middle one forwards (all three on the right wheel forwards). Every span from the one before them to the one
// after them fails; a bridge over the middle reading alone passes (its ends are off by the same angles), one over
// all three is right. The gate must leave out exactly the three readings, no motion-capture pose, and every pose
// keep a finite covariance.
TEST(TrackingTest, LeavesOutExactlyTheOutlyingCumulativeWheelReadings) {
  recording::Recording rec = testing::DiffDriveArcWithMotionCapture(120, 0.3, Eigen::Vector2d(1.0, -2.0));
  constexpr int kFirst = 60;
  rec.streams[0].values.row(kFirst) += Eigen::RowVector2d(-0.5, 0.5);
  rec.streams[0].values.row(kFirst + 1) += Eigen::RowVector2d(0.5, 0.5);
  rec.streams[0].values.row(kFirst + 2) += Eigen::RowVector2d(-0.5, 0.5);
  // Each motion-capture pose 1 us before its wheel reading, so that it has joined the newest pose at the update.
  for (Time& t : rec.streams[1].t) t = Time::FromNanoseconds(t.nanoseconds() - 1000);
  const auto config = ParseEstimatorConfig(
      testing::ArcConfigYaml({},
                             "tracking: {window: 20, max_iterations: 5, improvement_threshold: 1.0e-3, "
                             "time_budget_s: 1.0e9, initialization_s: 0.5}\n"
                             "gating: {probability: 0.99999}\n"),
      "test config");
  ASSERT_TRUE(config.ok()) << config.status().message();
  auto result = Track(config.value(), rec, {});
  ASSERT_TRUE(result.ok()) << result.status().message();
  EXPECT_EQ(result.value().counts.at("wheels").rejected, 3);
  EXPECT_EQ(result.value().counts.at("mocap").rejected, 0);
  for (std::size_t i = 0; i < result.value().position_covariance.size(); ++i)
    ASSERT_TRUE(result.value().position_covariance[i].allFinite()) << "pose " << i;
}

// Tracking a differential drive under motion capture whose clock steps 0.5 s ahead halfway (its later poses stamped
// late: 50 mm and 0.25 rad off the truth at their stamps, 500 and 250 times its noise). The wheels' noise leaves the
// dead-reckoned pose millimetres uncertain within a second; a late pose solved with the window pulls it onto itself and
// then fits there (without the innovation test none is rejected). The jump shows as a gap of the stream; tested on
// its innovation at the estimate without it, every late pose must be rejected, and every tracked position lie within
// the 99.7 % quantile of its reported covariance.
TEST(TrackingTest, RejectsEveryMotionCapturePoseStampedLateAfterItsClockJumps) {
  recording::Recording rec = testing::DiffDriveArcWithMotionCapture(120, 0.3, Eigen::Vector2d(1.0, -2.0));
  const Time truth_end = rec.streams[0].t.back();
  recording::Stream& mocap = rec.streams[1];
  mocap.info.rate_hz = 1.0 / testing::kArcDt_s;  // (the jump then shows as a gap of the stream)
  constexpr int kJumpRow = 60;
  const std::int64_t jump_ns = Time::FromSeconds(0.5).nanoseconds();
  int late_in_span = 0;
  for (std::size_t k = 0; k < mocap.t.size(); ++k) {
    // Each motion-capture pose 1 us before its wheel reading, so that it has joined the newest pose at the update.
    mocap.t[k] = Time::FromNanoseconds(mocap.t[k].nanoseconds() - 1000 + (k >= kJumpRow ? jump_ns : 0));
    late_in_span += k >= kJumpRow && mocap.t[k] <= truth_end;
  }
  const Eigen::Index kept = static_cast<Eigen::Index>(kJumpRow + late_in_span);
  mocap.t.resize(static_cast<std::size_t>(kept));
  mocap.values.conservativeResize(kept, Eigen::NoChange);
  const auto config = ParseEstimatorConfig(R"(
master: wheels
tracking: {window: 20, max_iterations: 5, improvement_threshold: 1.0e-3, time_budget_s: 1.0e9, initialization_s: 0.5}
gating: {probability: 0.99999}
parameters:
  wheels.radius: {value: [0.04]}
  wheels.baseline: {value: [0.2]}
streams:
  wheels:
    model: differential_drive
    source: wheels
    noise: {wheel_radps: 0.5, lateral_mps: 0.002, vertical_mps: 0.002, tilt_radps: 0.02}
    parameters: {radius_left: wheels.radius, radius_right: wheels.radius, baseline: wheels.baseline}
  mocap:
    model: absolute_pose
    source: mocap
    noise: {position_m: 0.0001, orientation_rad: 0.001}
)",
                                           "test config");
  ASSERT_TRUE(config.ok()) << config.status().message();
  const recording::Recording truth = testing::DiffDriveArcWithMotionCapture(120, 0.3, Eigen::Vector2d(1.0, -2.0));
  auto result = Track(config.value(), rec, {});
  ASSERT_TRUE(result.ok()) << result.status().message();
  EXPECT_EQ(result.value().counts.at("mocap").rejected, late_in_span);
  EXPECT_EQ(result.value().counts.at("wheels").rejected, 0);
  const double gate = ChiSquareQuantile(0.997, 3);
  const TrackingResult& r = result.value();
  for (std::size_t i = 0; i < r.trajectory.size(); ++i) {
    const Eigen::Matrix3d& cov = r.position_covariance[i];
    ASSERT_TRUE(cov.allFinite()) << "pose " << i;
    const Eigen::Index row = static_cast<Eigen::Index>(std::llround(r.trajectory[i].t.seconds() / testing::kArcDt_s));
    const Eigen::Vector3d error = r.trajectory[i].p_world_body - truth.streams[1].values.row(row).head<3>().transpose();
    EXPECT_LE(error.dot(cov.ldlt().solve(error)), gate) << "pose " << i << " at " << r.trajectory[i].t.seconds() << " s";
  }
}

TEST(TrackingTest, CalibrationPriorOfTheWrongSizeIsAnError) {
  CalibratedAtv calibrated = CalibrateOnOtherDrive();
  calibrated.prior.information = Eigen::MatrixXd::Identity(2, 2);
  roamlab::testing::SyntheticOptions options;
  options.duration_s = 3.0;
  const auto synthetic = roamlab::testing::MakeAtvRecording(options);
  EstimatorConfig config = testing::AtvConfig({}, 20);
  config.tracking.calibration_prior = true;
  TrackingOptions with_prior;
  with_prior.calibration_prior = calibrated.prior;
  auto result = Track(config, synthetic.recording, calibrated.values, with_prior);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.status().message().find("tangent dimensions"), std::string::npos) << result.status().message();
}

}  // namespace
}  // namespace roamlab::estimator
