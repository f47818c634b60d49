// The IMU master on real recordings (skipped when the shared data are absent):
//  - the Husky bag without its wheel odometry (configs/real/husky_imu_gps.yaml, and with the vehicle's non-holonomic
//    rows: husky_imu_gps_nonholonomic.yaml), tracked with its calibration and compared with the wheel-odometry-aided
//    run (configs/real/husky_wheel_aided.yaml), and that run with the odometry's stamps moved by its lag; the GPS's
//    slow error (the configurations' gps.bias process) split from the wheel-aided run's residuals;
//  - the x-io handheld IMU + magnetometer log (configs/real/xio_imu_mag.yaml): the magnetometer's A and b against the
//    ellipsoid fit of the raw field (eval/ellipsoid_fit.h).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <limits>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "estimator/calibration.h"
#include "estimator/config.h"
#include "estimator/covariance.h"
#include "estimator/geometry.h"
#include "estimator/models/enu.h"
#include "estimator/tracking.h"
#include "eval/ellipsoid_fit.h"
#include "importers/csv.h"
#include "importers/rosbag.h"
#include "tests/support/husky_bag.h"
#include "tests/support/paths.h"
#include "tests/support/real_data.h"

namespace roamlab::estimator {
namespace {

const std::string kData = ::roamlab::testing::RealDataDir();
const std::string kConfigs = roamlab::testing::SourceDir() + "/configs/real/";

std::map<std::string, Eigen::VectorXd> Values(const CalibrationResult& r) {
  std::map<std::string, Eigen::VectorXd> out;
  for (const ParameterEstimate& p : r.parameters) out[p.name] = p.estimate;
  return out;
}

// Each stream's active residuals' autocorrelation, in time order.
std::map<std::string, ResidualAutocorrelation> Autocorrelations(const CalibrationResult& r) {
  std::map<std::string, std::vector<const MeasurementResidual*>> streams;
  for (const MeasurementResidual& m : r.residuals)
    if (m.active) streams[m.stream].push_back(&m);
  std::map<std::string, ResidualAutocorrelation> out;
  for (auto& [stream, rows] : streams) {
    std::stable_sort(rows.begin(), rows.end(), [](const auto* x, const auto* y) { return x->t < y->t; });
    std::vector<Eigen::VectorXd> series;
    for (const MeasurementResidual* m : rows) series.push_back(m->whitened);
    out[stream] = AnalyzeAutocorrelation(series);
  }
  return out;
}

// Each parameter with its white and HAC standard deviations (`std` is the HAC one on an imported recording).
void Print(const CalibrationResult& r) {
  for (const ParameterEstimate& p : r.parameters) {
    std::cout << "  " << p.name << " = [" << p.estimate.transpose() << "] +- white [" << p.std_white.transpose()
              << "], hac [" << p.std_hac.transpose() << "]\n";
  }
  std::cout << "  (std: " << r.std_method << "; HAC lags:";
  for (const auto& [stream, lag] : r.hac_lags) std::cout << " " << stream << " " << lag;
  std::cout << ")\n";
  // Each stream's integrated residual autocorrelation time: how many times a white variance understates the spread
  // of a mean over that stream (what the tracked positions' std, white, would need for the GPS stream).
  for (const auto& [stream, a] : Autocorrelations(r)) {
    std::cout << "  " << stream << ": integrated residual autocorrelation time " << a.integrated_time << " (lag "
              << a.lag << "), std inflation sqrt = " << std::sqrt(a.integrated_time) << "\n";
  }
}

// The spread (std per component) of the ellipsoid fit's centre over `replicates` moving-block bootstrap resamples of
// `samples` (blocks of `block` consecutive samples drawn with replacement; fixed seed). Resamples whose fit fails are
// left out and counted on the output.
Eigen::Vector3d BlockBootstrapCentreStd(const std::vector<Eigen::Vector3d>& samples, std::size_t block,
                                        int replicates) {
  std::mt19937 rng(39);
  std::uniform_int_distribution<std::size_t> start(0, samples.size() - block);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero(), sum_squared = Eigen::Vector3d::Zero();
  int fitted = 0;
  for (int r = 0; r < replicates; ++r) {
    std::vector<Eigen::Vector3d> resample;
    while (resample.size() < samples.size()) {
      const std::size_t first = start(rng);
      resample.insert(resample.end(), samples.begin() + static_cast<std::ptrdiff_t>(first),
                      samples.begin() + static_cast<std::ptrdiff_t>(first + block));
    }
    const auto fit = eval::FitEllipsoid(resample);
    if (!fit.ok()) continue;
    sum += fit.value().centre;
    sum_squared += fit.value().centre.cwiseProduct(fit.value().centre);
    ++fitted;
  }
  std::cout << "block bootstrap: " << fitted << " of " << replicates << " resamples fitted\n";
  if (fitted < 2) return Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  return ((sum_squared - sum.cwiseProduct(sum) / fitted) / (fitted - 1)).cwiseMax(0.0).cwiseSqrt();
}

// A run's track of the GPS antenna (the pose moved by the calibrated lever arm) with its position covariance.
struct AntennaTrack {
  std::vector<Time> t;
  std::vector<Eigen::Vector3d> p;
  std::vector<Eigen::Matrix3d> covariance;
};

AntennaTrack Antenna(const TrackingResult& track, const Eigen::Vector3d& lever_arm) {
  AntennaTrack out;
  for (std::size_t i = 0; i < track.trajectory.size(); ++i) {
    const StampedPose& p = track.trajectory[i];
    out.t.push_back(p.t);
    out.p.push_back(p.p_world_body + p.q_world_body * lever_arm);
    out.covariance.push_back(track.position_covariance[i]);
  }
  return out;
}

// The smoothed trajectory of a calibration at the poses whose covariance it computed (the antenna at the body
// origin), with the chosen (white or HAC) covariance, or the white one.
AntennaTrack Smoothed(const CalibrationResult& calibration, bool white) {
  AntennaTrack out;
  for (const PoseCovariance& c : calibration.pose_covariances) {
    out.t.push_back(calibration.trajectory[c.pose].t);
    out.p.push_back(calibration.trajectory[c.pose].p_world_body);
    out.covariance.push_back(white ? c.white : c.covariance);
  }
  return out;
}

// The 3-sigma region of a 2-D Gaussian: the chi-square(2) quantile of 0.9973, -2 ln(0.0027) = 11.83.
constexpr double kThreeSigma2d = 11.83;

// The fraction of the reference's poses at which `track` (interpolated linearly in time; its nearest pose's
// covariance) lies inside the combined horizontal 3-sigma region; printed with the mean of the normalized squared
// differences d^T (C_track + C_reference)^-1 d, 2 (the dimension) for consistent and independent errors, below it
// when the covariances are generous or the errors positively correlated. Both runs read the same GPS, so their errors
// are positively correlated and the sum of the covariances overstates the difference's: the test is conservative in
// that.
double WithinThreeSigma(const AntennaTrack& track, const AntennaTrack& reference, const char* name) {
  int compared = 0, within = 0;
  double sum_difference = 0.0, max_difference = 0.0, sum_std_track = 0.0, sum_std_reference = 0.0, sum_nees = 0.0;
  for (std::size_t i = 0; i < reference.t.size(); ++i) {
    const auto after = std::lower_bound(track.t.begin(), track.t.end(), reference.t[i]);
    if (after == track.t.begin() || after == track.t.end()) continue;
    const std::size_t j = static_cast<std::size_t>(after - track.t.begin());
    const double w = SecondsBetween(track.t[j - 1], reference.t[i]) / SecondsBetween(track.t[j - 1], track.t[j]);
    const Eigen::Vector2d d = (reference.p[i] - ((1.0 - w) * track.p[j - 1] + w * track.p[j])).head<2>();
    const Eigen::Matrix2d c_track = track.covariance[w < 0.5 ? j - 1 : j].topLeftCorner<2, 2>();
    const Eigen::Matrix2d c_reference = reference.covariance[i].topLeftCorner<2, 2>();
    const double nees = d.dot((c_track + c_reference).ldlt().solve(d));
    within += nees <= kThreeSigma2d ? 1 : 0;
    sum_nees += nees;
    ++compared;
    sum_difference += d.norm();
    max_difference = std::max(max_difference, d.norm());
    sum_std_track += std::sqrt(c_track.trace());
    sum_std_reference += std::sqrt(c_reference.trace());
  }
  const double fraction = static_cast<double>(within) / std::max(compared, 1);
  std::cout << name << ": " << compared << " poses compared; horizontal difference mean " << sum_difference / compared
            << " m, max " << max_difference << " m; reported horizontal std mean: IMU+GPS " << sum_std_track / compared
            << " m, wheel-aided " << sum_std_reference / compared << " m; within the 3-sigma region "
            << 100.0 * fraction << "%; mean normalized squared difference " << sum_nees / compared
            << " (2 for independent errors)\n";
  return fraction;
}

// The variance of a fix's error per ENU axis [m^2] as a configuration models it: the white sigma_m squared, plus the
// stationary variance of the bias's Gauss-Markov process when the bias is one.
Eigen::Vector3d FixErrorVariance(const EstimatorConfig& config) {
  const double sigma_m = config.streams.at("gps").noise.at("sigma_m");
  Eigen::Vector3d variance = Eigen::Vector3d::Constant(sigma_m * sigma_m);
  const auto bias = config.parameters.find("gps.bias");
  if (bias != config.parameters.end() && bias->second.process.type == ProcessConfig::Type::kGaussMarkov)
    variance += bias->second.process.sigma.cwiseAbs2();
  return variance;
}

// The fraction of the GPS fixes inside a track's horizontal 3-sigma region: its distance from each fix, normalized by
// its own reported covariance (nearest pose at or after the fix) plus the fix's error variance as its configuration
// models it (FixErrorVariance).
double AgainstFixes(const recording::Recording& rec, const AntennaTrack& track, const Eigen::Vector3d& fix_variance,
                    const char* name) {
  const recording::Stream& gps = *rec.Find("gps");
  const EnuConverter enu(*rec.origin);
  const Eigen::Matrix2d fix_covariance = fix_variance.head<2>().asDiagonal();
  double sum = 0.0;
  int n = 0, inside = 0;
  for (std::size_t r = 0; r < gps.t.size(); ++r) {
    const auto it = std::lower_bound(track.t.begin(), track.t.end(), gps.t[r]);
    if (it == track.t.end()) continue;
    const std::size_t k = static_cast<std::size_t>(it - track.t.begin());
    const auto row = static_cast<Eigen::Index>(r);
    const Eigen::Vector3d z = enu.ToEnu(gps.values(row, 0), gps.values(row, 1), gps.values(row, 2));
    const Eigen::Vector2d d = (track.p[k] - z).head<2>();
    const Eigen::Matrix2d c = track.covariance[k].topLeftCorner<2, 2>() + fix_covariance;
    inside += d.dot(c.ldlt().solve(d)) <= kThreeSigma2d ? 1 : 0;
    sum += d.squaredNorm();
    ++n;
  }
  std::cout << name << " against the GPS fixes: rms horizontal distance " << std::sqrt(sum / n)
            << " m, within the 3-sigma region " << 100.0 * inside / n << "% of " << n << " fixes\n";
  return static_cast<double>(inside) / n;
}

// FixErrorVariance of a configuration in configs/real/.
Eigen::Vector3d ConfiguredFixErrorVariance(const std::string& file) {
  auto config = LoadEstimatorConfig(kConfigs + file);
  EXPECT_TRUE(config.ok()) << config.status().message();
  return config.ok() ? FixErrorVariance(config.value()) : Eigen::Vector3d::Constant(NAN);
}

Result<CalibrationResult> CalibrateWith(const std::string& config_file, const recording::Recording& rec,
                                        int pose_covariance_every) {
  auto config = LoadEstimatorConfig(config_file);
  if (!config.ok()) return config.status();
  CalibrationOptions options;
  options.keep_residuals = true;
  options.pose_covariance_every = pose_covariance_every;
  return Calibrate(config.value(), rec, options);
}

// Where the IMU's horizontal axes point, independently of the estimator: the accelerometer's horizontal specific
// force (turned by the configured mounting) against the odometry's acceleration in the body frame, forward dv/dt
// and centripetal v omega_z (omega_z the gyroscope's, v the odometry's read `lag_s` later: it lags), both as 1 s
// means, their means removed; the least-squares turn theta [rad] about the body's z with f = R(theta) a (2-D
// Procrustes), and the correlation of the two. The mounted IMU's x axis points at -theta in the body frame.
struct HorizontalTurn {
  double theta = 0.0;
  double correlation = 0.0;
  int blocks = 0;
};

HorizontalTurn AccelerometerAgainstOdometry(const recording::Recording& rec, double lag_s) {
  const recording::Stream& imu = *rec.Find("imu");
  const recording::Stream& odometry = *rec.Find("odometry");
  const Eigen::Quaterniond mounting(std::sqrt(0.5), std::sqrt(0.5), 0.0, 0.0);
  const auto speed = [&](Time t) {
    auto it = std::lower_bound(odometry.t.begin(), odometry.t.end(),
                               Time::FromNanoseconds(t.nanoseconds() + std::llround(lag_s * 1e9)));
    if (it == odometry.t.end()) --it;
    return odometry.values(it - odometry.t.begin(), 0);  // column vx [m/s]
  };
  std::vector<Eigen::Vector2d> f, a;
  constexpr std::int64_t kBlockNs = 1'000'000'000;
  std::size_t k = 0;
  for (Time start = imu.t.front(); Time::FromNanoseconds(start.nanoseconds() + kBlockNs) <= imu.t.back();
       start = Time::FromNanoseconds(start.nanoseconds() + kBlockNs)) {
    const Time end = Time::FromNanoseconds(start.nanoseconds() + kBlockNs);
    Eigen::Vector2d f_sum = Eigen::Vector2d::Zero();
    double centripetal_sum = 0.0;
    int n = 0;
    for (; k < imu.t.size() && imu.t[k] < end; ++k, ++n) {
      const auto row = static_cast<Eigen::Index>(k);
      f_sum += (mounting * Eigen::Vector3d(imu.values.row(row).segment<3>(3).transpose())).head<2>();
      centripetal_sum += speed(imu.t[k]) * (mounting * Eigen::Vector3d(imu.values.row(row).head<3>().transpose())).z();
    }
    if (n == 0) continue;
    f.push_back(f_sum / n);
    a.emplace_back(speed(end) - speed(start), centripetal_sum / n);
  }
  Eigen::Vector2d f_mean = Eigen::Vector2d::Zero(), a_mean = Eigen::Vector2d::Zero();
  for (std::size_t i = 0; i < f.size(); ++i) {
    f_mean += f[i] / static_cast<double>(f.size());
    a_mean += a[i] / static_cast<double>(a.size());
  }
  double cos_sum = 0.0, sin_sum = 0.0, ff = 0.0, aa = 0.0;
  for (std::size_t i = 0; i < f.size(); ++i) {
    const Eigen::Vector2d fi = f[i] - f_mean, ai = a[i] - a_mean;
    cos_sum += ai.dot(fi);
    sin_sum += ai.x() * fi.y() - ai.y() * fi.x();
    ff += fi.squaredNorm();
    aa += ai.squaredNorm();
  }
  return {std::atan2(sin_sum, cos_sum), std::hypot(cos_sum, sin_sum) / std::sqrt(ff * aa), static_cast<int>(f.size())};
}

// The direction of travel in a trajectory's body frame [rad]: the circular mean, over the poses that moved at least
// 0.5 m over the 10 poses around them, of the displacement's angle about the body's z.
double TravelInBody(const Trajectory& trajectory) {
  double sin_sum = 0.0, cos_sum = 0.0;
  for (std::size_t i = 5; i + 5 < trajectory.size(); ++i) {
    const Eigen::Vector3d d = trajectory[i + 5].p_world_body - trajectory[i - 5].p_world_body;
    if (d.head<2>().norm() < 0.5) continue;
    const Eigen::Vector3d d_body = trajectory[i].q_world_body.conjugate() * d;
    sin_sum += std::sin(std::atan2(d_body.y(), d_body.x()));
    cos_sum += std::cos(std::atan2(d_body.y(), d_body.x()));
  }
  return std::atan2(sin_sum, cos_sum);
}

// An IMU + GPS run: its calibration, and its track of the GPS antenna with that calibration.
struct ImuGpsRun {
  CalibrationResult calibration;
  AntennaTrack track;
};

Result<ImuGpsRun> RunImuGps(const std::string& config_file, const recording::Recording& imu_gps) {
  auto calibration = CalibrateWith(config_file, imu_gps, 0);
  if (!calibration.ok()) return calibration.status();
  auto config = LoadEstimatorConfig(config_file);
  if (!config.ok()) return config.status();
  auto track = Track(config.value(), imu_gps, Values(calibration.value()));
  if (!track.ok()) return track.status();
  const Eigen::Vector3d lever_arm = Values(calibration.value()).at("gps.lever_arm");
  return ImuGpsRun{calibration.value(), Antenna(track.value(), lever_arm)};
}

// The calibrated IMU misalignment's turn from the configured mounting R_x(+90 deg), about the body's axes (the slot's
// tangent is in the IMU's frame: IMU x = body x, IMU y = body z, IMU z = body -y) [rad], printed in degrees with its
// std; the yaw's ParameterEstimate component is the second (about the IMU's y).
Eigen::Vector3d MisalignmentFromMounting(const ParameterEstimate& p) {
  const Eigen::Quaterniond mounting(std::sqrt(0.5), std::sqrt(0.5), 0.0, 0.0);
  const Eigen::Quaterniond q(p.estimate[0], p.estimate[1], p.estimate[2], p.estimate[3]);
  const Eigen::Vector3d delta = QuaternionLog<double>(mounting.conjugate() * q.normalized());
  const Eigen::Vector3d roll_pitch_yaw(delta[0], -delta[2], delta[1]);
  const Eigen::Vector3d deg = roll_pitch_yaw * 180.0 / M_PI, std = p.std * 180.0 / M_PI;
  std::cout << "  IMU misalignment from the mounting: roll " << deg[0] << " +- " << std[0] << " deg, pitch " << deg[1]
            << " +- " << std[2] << " deg, yaw " << deg[2] << " +- " << std[1]
            << " deg (roll, pitch, yaw: " << ObservabilityName(p.components[0]) << ", "
            << ObservabilityName(p.components[2]) << ", " << ObservabilityName(p.components[1]) << ")\n";
  return roll_pitch_yaw;
}

// The fixes' slow error read from a run that does not follow it: per ENU axis, the GPS residuals [m] (whitened times
// the run's white sigma_m) in time order, demeaned, their autocovariance C(l) at lag l fixes. A white part plus a
// first-order Gauss-Markov part of variance s^2 and correlation time tau gives C(0) = w^2 + s^2 and C(l) = s^2
// exp(-l dt / tau) for l >= 1, so: s = sqrt(C(1)), w = sqrt(C(0) - C(1)), and tau = (l_e - 1) dt, l_e the first lag
// at which C(l) falls to C(1) / e (dt the fixes' median spacing).
struct GpsErrorSplit {
  Eigen::Vector3d slow_sigma_m;
  Eigen::Vector3d white_sigma_m;
  Eigen::Vector3d tau_s;
};

GpsErrorSplit SplitGpsResiduals(const CalibrationResult& r, double sigma_m) {
  std::vector<const MeasurementResidual*> rows;
  for (const MeasurementResidual& m : r.residuals)
    if (m.active && m.stream == "gps") rows.push_back(&m);
  std::stable_sort(rows.begin(), rows.end(), [](const auto* x, const auto* y) { return x->t < y->t; });
  const int n = static_cast<int>(rows.size());
  GpsErrorSplit out;
  out.slow_sigma_m = out.white_sigma_m = out.tau_s = Eigen::Vector3d::Constant(NAN);
  if (n < 8) return out;  // too few fixes for a lag window
  Eigen::MatrixXd e(3, n);
  std::vector<double> spacing_s;
  for (int t = 0; t < n; ++t) {
    e.col(t) = sigma_m * rows[static_cast<std::size_t>(t)]->whitened;
    if (t > 0)
      spacing_s.push_back(
          SecondsBetween(rows[static_cast<std::size_t>(t) - 1]->t, rows[static_cast<std::size_t>(t)]->t));
  }
  e.colwise() -= e.rowwise().mean();
  std::nth_element(spacing_s.begin(), spacing_s.begin() + static_cast<std::ptrdiff_t>(spacing_s.size() / 2),
                   spacing_s.end());
  const double dt_s = spacing_s[spacing_s.size() / 2];
  const auto autocovariance = [&](int axis, int lag) {
    return e.row(axis).head(n - lag).dot(e.row(axis).tail(n - lag)) / n;
  };
  for (int axis = 0; axis < 3; ++axis) {
    const double c0 = autocovariance(axis, 0), c1 = autocovariance(axis, 1);
    out.slow_sigma_m[axis] = std::sqrt(std::max(c1, 0.0));
    out.white_sigma_m[axis] = std::sqrt(std::max(c0 - c1, 0.0));
    int lag = 1;
    while (lag < n / 4 && autocovariance(axis, lag) > c1 / M_E) ++lag;
    out.tau_s[axis] = (lag - 1) * dt_s;
  }
  std::cout << "GPS residuals (" << n << " fixes, " << dt_s << " s apart) split per ENU axis: slow std ["
            << out.slow_sigma_m.transpose() << "] m, tau [" << out.tau_s.transpose() << "] s, white std ["
            << out.white_sigma_m.transpose() << "] m\n";
  return out;
}

// The rule's inputs: the wheel-aided run (configs/real/husky_wheel_aided.yaml) with the fixes taken as white (the bias
// left out, sigma_m 1.2 m: the fixes' whole spread taken as one white error).
TEST(ImuMasterRealTest, HuskyGpsSlowErrorFromTheWheelAidedResiduals) {
  const std::string bag = kData + "/husky_test1/test1.bag";
  if (!std::filesystem::exists(bag)) GTEST_SKIP() << "real data absent: " << bag;
  auto rec = importers::ImportRosbag(bag, ::roamlab::testing::HuskyImportOptions());
  ASSERT_TRUE(rec.ok()) << rec.status().message();
  auto config = LoadEstimatorConfig(kConfigs + "husky_wheel_aided.yaml");
  ASSERT_TRUE(config.ok()) << config.status().message();
  EstimatorConfig white = config.value();
  white.parameters.erase("gps.bias");
  white.streams.at("gps").noise["sigma_m"] = 1.2;
  CalibrationOptions options;
  options.keep_residuals = true;
  auto run = Calibrate(white, rec.value(), options);
  ASSERT_TRUE(run.ok()) << run.status().message();
  const GpsErrorSplit split = SplitGpsResiduals(run.value(), 1.2);
  const double white_rms = std::sqrt(split.white_sigma_m.squaredNorm() / 3.0);
  // The Husky configurations carry the rule's values, rounded to three digits (within 1 %).
  for (const char* file : {"husky_wheel_aided.yaml", "husky_imu_gps.yaml", "husky_imu_gps_nonholonomic.yaml"}) {
    auto c = LoadEstimatorConfig(kConfigs + file);
    ASSERT_TRUE(c.ok()) << c.status().message();
    const ProcessConfig& process = c.value().parameters.at("gps.bias").process;
    EXPECT_EQ(process.type, ProcessConfig::Type::kGaussMarkov) << file;
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_NEAR(process.sigma[axis], split.slow_sigma_m[axis], 0.01 * split.slow_sigma_m[axis]) << file << axis;
      EXPECT_NEAR(process.tau_s[axis], split.tau_s[axis], 0.01 * split.tau_s[axis]) << file << axis;
    }
    EXPECT_NEAR(c.value().streams.at("gps").noise.at("sigma_m"), white_rms, 0.01 * white_rms) << file;
  }
}

// The IMU + GPS runs (configs/real/husky_imu_gps.yaml, and husky_imu_gps_nonholonomic.yaml with the vehicle's
// non-holonomic rows), tracked with their calibrations, against the GPS fixes and against the wheel-odometry-aided
// calibration's smoothed track (configs/real/husky_wheel_aided.yaml: the skid steer's effective track and the
// gyroscope's time offset free). The reference's covariance is the HAC one: its residuals are autocorrelated over tens
// of seconds (the fixes' slow errors, which the stiff wheel-aided track does not follow), and its white covariance
// understates how far the track strays from the fixes several times.
TEST(ImuMasterRealTest, HuskyImuGpsTrackAgainstTheFixesAndTheWheelOdometryAidedTrack) {
  const std::string bag = kData + "/husky_test1/test1.bag";
  if (!std::filesystem::exists(bag)) GTEST_SKIP() << "real data absent: " << bag;
  auto rec = importers::ImportRosbag(bag, ::roamlab::testing::HuskyImportOptions());
  ASSERT_TRUE(rec.ok()) << rec.status().message();
  // The IMU + GPS recording: the wheel odometry (its twist, its pose and the wheels derived from it) dropped.
  recording::Recording imu_gps = rec.value();
  imu_gps.streams.erase(
      std::remove_if(imu_gps.streams.begin(), imu_gps.streams.end(),
                     [](const recording::Stream& s) { return s.info.name != "imu" && s.info.name != "gps"; }),
      imu_gps.streams.end());
  ASSERT_EQ(imu_gps.streams.size(), 2u);

  // Every 10th pose of the wheel-aided run (one a second) gets its covariance.
  auto wheel = CalibrateWith(kConfigs + "husky_wheel_aided.yaml", rec.value(), 10);
  ASSERT_TRUE(wheel.ok()) << wheel.status().message();
  std::cout << "wheel-odometry-aided calibration:\n";
  Print(wheel.value());
  const AntennaTrack reference = Smoothed(wheel.value(), false);
  const AntennaTrack reference_white = Smoothed(wheel.value(), true);
  ASSERT_GT(reference.t.size(), 300u);
  const Eigen::Vector3d wheel_fix_variance = ConfiguredFixErrorVariance("husky_wheel_aided.yaml");
  AgainstFixes(rec.value(), reference_white, wheel_fix_variance, "wheel-aided smoothed track, white covariance");
  AgainstFixes(rec.value(), reference, wheel_fix_variance, "wheel-aided smoothed track, HAC covariance");

  auto plain = RunImuGps(kConfigs + "husky_imu_gps.yaml", imu_gps);
  ASSERT_TRUE(plain.ok()) << plain.status().message();
  std::cout << "IMU + GPS calibration:\n";
  Print(plain.value().calibration);
  for (const ParameterEstimate& p : plain.value().calibration.parameters)
    for (int i = 0; i < p.std.size(); ++i) EXPECT_TRUE(std::isfinite(p.std[i])) << p.name << "[" << i << "]";
  const double imu_consistent =
      AgainstFixes(rec.value(), plain.value().track, ConfiguredFixErrorVariance("husky_imu_gps.yaml"), "IMU+GPS track");
  WithinThreeSigma(plain.value().track, reference_white,
                   "IMU+GPS track against the wheel-aided track, white covariance");
  const double imu_within =
      WithinThreeSigma(plain.value().track, reference, "IMU+GPS track against the wheel-aided track, HAC");

  auto vehicle = RunImuGps(kConfigs + "husky_imu_gps_nonholonomic.yaml", imu_gps);
  ASSERT_TRUE(vehicle.ok()) << vehicle.status().message();
  std::cout << "IMU + GPS + non-holonomic calibration:\n";
  Print(vehicle.value().calibration);
  const ParameterEstimate* misalignment = nullptr;
  for (const ParameterEstimate& p : vehicle.value().calibration.parameters)
    if (p.name == "imu.misalignment") misalignment = &p;
  ASSERT_NE(misalignment, nullptr);
  const Eigen::Vector3d roll_pitch_yaw = MisalignmentFromMounting(*misalignment);
  const double vehicle_consistent =
      AgainstFixes(rec.value(), vehicle.value().track, ConfiguredFixErrorVariance("husky_imu_gps_nonholonomic.yaml"),
                   "IMU+GPS+non-holonomic track");
  std::cout << "direction of travel in the body frame: IMU+GPS "
            << TravelInBody(plain.value().calibration.trajectory) * 180.0 / M_PI << " deg, IMU+GPS+non-holonomic "
            << TravelInBody(vehicle.value().calibration.trajectory) * 180.0 / M_PI << " deg\n";
  WithinThreeSigma(vehicle.value().track, reference_white,
                   "IMU+GPS+non-holonomic track against the wheel-aided track, white covariance");
  WithinThreeSigma(vehicle.value().track, reference, "IMU+GPS+non-holonomic track against the wheel-aided track, HAC");
  // With the fixes' slow error modelled (the bias), the wheel-aided run's GPS residuals are white: no lag window of
  // their autocorrelation reaches 2 / sqrt(n) (AnalyzeAutocorrelation's lag 0 to 2; with the fixes taken as white
  // they are correlated over 30 fixes, 12 s). The HAC covariance of the smoothed positions still widens the white one
  // (printed): the wheels' residuals and the bias's process rows stay correlated.
  double sum_white = 0.0, sum_hac = 0.0;
  for (const PoseCovariance& c : wheel.value().pose_covariances) {
    sum_white += std::sqrt(c.white.topLeftCorner<2, 2>().trace());
    sum_hac += std::sqrt(c.hac.topLeftCorner<2, 2>().trace());
  }
  std::cout << "wheel-aided smoothed positions: horizontal std HAC / white " << sum_hac / sum_white << "\n";
  EXPECT_LE(Autocorrelations(wheel.value()).at("gps").lag, 2);
  // Both IMU+GPS tracks are consistent with the fixes: at most the 0.27% a 3-sigma region leaves out, with a margin
  // for the fixes' correlated errors.
  EXPECT_GE(imu_consistent, 0.99);
  EXPECT_GE(vehicle_consistent, 0.99);
  // The IMU+GPS track lies within the combined 3-sigma region of the wheel-aided track's (HAC) at 97 % of the poses or
  // more: a consistent pair leaves out 0.27 % of independent poses, and below 97 % (with the spread that 395
  // correlated poses give a fraction) the pair is not consistent. With the fixes taken as white it read 61.8 %: each
  // track followed the fixes' slow error in its own way, and neither covariance held that error (docs/results.md).
  EXPECT_GE(imu_within, 0.97);
  // The skid steer turns with an effective track well below the nominal 0.555 m through which its wheel speeds were
  // recovered from the controller's odometry: more than 3 of its (HAC) std below.
  for (const ParameterEstimate& p : wheel.value().parameters) {
    if (p.name == "wheels.baseline") {
      EXPECT_LT(p.estimate[0] + 3.0 * p.std[0], 0.555);
    }
  }
  // The IMU misalignment's yaw with the non-holonomic rows: observable, with a finite std, and on the side that the
  // accelerometer's regression on the odometry's acceleration shows (the mounted IMU's x axis at -theta in the body
  // frame): within 45 deg of it, the same quarter turn, where the configured mounting (yaw 0) is a quarter turn off.
  // Not asserted: their agreement within the regression's std, which its 1 s blocks, correlated in time, leave unknown.
  const HorizontalTurn turn = AccelerometerAgainstOdometry(rec.value(), 0.4);
  std::cout << "accelerometer against the odometry's acceleration (" << turn.blocks << " blocks of 1 s, odometry read "
            << "0.4 s later): turned by " << turn.theta * 180.0 / M_PI << " deg, correlation " << turn.correlation
            << "; the mounted IMU's x at " << -turn.theta * 180.0 / M_PI << " deg in the body frame\n";
  EXPECT_EQ(misalignment->components[1], Observability::kObservable);
  EXPECT_TRUE(std::isfinite(misalignment->std[1]));
  EXPECT_LT(std::abs(std::remainder(roll_pitch_yaw[2] + turn.theta, 2.0 * M_PI)), M_PI / 4.0);
}

// The odometry's lag against the wheel-aided model (configs/real/husky_wheel_aided.yaml, the gyroscope's first-order
// time offset fixed at 0): the odometry and wheel streams' stamps moved 0.4 s earlier (the lag the yaw rates show,
// docs/results.md) and the calibration run again. The wheels' rows fit better (their chi-square drops by a fifth: the
// lag is real), but the smoothed track stays as far from the fixes (its rms distance moves by under 1 %): the lag is
// not what keeps the wheel-aided track from the fixes.
TEST(ImuMasterRealTest, HuskyOdometryLagSeenByTheWheelsNotByTheTrack) {
  const std::string bag = kData + "/husky_test1/test1.bag";
  if (!std::filesystem::exists(bag)) GTEST_SKIP() << "real data absent: " << bag;
  auto rec = importers::ImportRosbag(bag, ::roamlab::testing::HuskyImportOptions());
  ASSERT_TRUE(rec.ok()) << rec.status().message();
  auto config = LoadEstimatorConfig(kConfigs + "husky_wheel_aided.yaml");
  ASSERT_TRUE(config.ok()) << config.status().message();
  config.value().parameters.at("imu.time_offset_s").free = false;
  std::map<double, double> wheels_chi2, rms;
  for (const double shift_s : {0.0, 0.4}) {
    recording::Recording shifted = rec.value();
    for (recording::Stream& s : shifted.streams) {
      if (s.info.name == "imu" || s.info.name == "gps") continue;
      for (Time& t : s.t) t = Time::FromNanoseconds(t.nanoseconds() - std::llround(shift_s * 1e9));
    }
    CalibrationOptions options;
    options.keep_residuals = true;
    auto calibration = Calibrate(config.value(), shifted, options);
    ASSERT_TRUE(calibration.ok()) << calibration.status().message();
    for (const MeasurementResidual& m : calibration.value().residuals)
      if (m.active && m.stream == "wheels") wheels_chi2[shift_s] += m.whitened.squaredNorm();
    AntennaTrack track;
    for (const StampedPose& p : calibration.value().trajectory) {
      track.t.push_back(p.t);
      track.p.push_back(p.p_world_body);
      track.covariance.push_back(Eigen::Matrix3d::Zero());
    }
    std::cout << "odometry " << shift_s << " s earlier: wheels chi-square " << wheels_chi2[shift_s] << "\n";
    Print(calibration.value());
    // The fraction inside is meaningless here (no covariance); the rms distance is what is compared.
    const recording::Stream& gps = *rec.value().Find("gps");
    const EnuConverter enu(*rec.value().origin);
    double sum = 0.0;
    int n = 0;
    for (std::size_t r = 0; r < gps.t.size(); ++r) {
      const auto it = std::lower_bound(track.t.begin(), track.t.end(), gps.t[r]);
      if (it == track.t.end()) continue;
      const auto row = static_cast<Eigen::Index>(r);
      const Eigen::Vector3d z = enu.ToEnu(gps.values(row, 0), gps.values(row, 1), gps.values(row, 2));
      sum += (track.p[static_cast<std::size_t>(it - track.t.begin())] - z).head<2>().squaredNorm();
      ++n;
    }
    rms[shift_s] = std::sqrt(sum / n);
    std::cout << "  smoothed track against the fixes: rms horizontal distance " << rms[shift_s] << " m\n";
  }
  EXPECT_LT(wheels_chi2[0.4], 0.9 * wheels_chi2[0.0]);
  EXPECT_LT(std::abs(rms[0.4] - rms[0.0]), 0.01 * rms[0.0]);
}

TEST(ImuMasterRealTest, XioMagnetometerCalibrationAgainstTheEllipsoidFit) {
  const std::string csv = kData + "/xio_imu_mag/sensor_data.csv";
  if (!std::filesystem::exists(csv)) GTEST_SKIP() << "real data absent: " << csv;
  // The recording as `roamlab import csv` makes it (configs/import/xio_imu_mag.yaml): streams imu and magnetometer,
  // the magnetometer's repeated values between its own updates collapsed.
  importers::CsvImportReport report;
  auto imported =
      importers::ImportCsv({csv}, roamlab::testing::SourceDir() + "/configs/import/xio_imu_mag.yaml", &report);
  ASSERT_TRUE(imported.ok()) << imported.status().message();
  const recording::Recording& rec = imported.value();
  const recording::Stream* imu = rec.Find("imu");
  const recording::Stream* magnetometer = rec.Find("magnetometer");
  ASSERT_NE(imu, nullptr);
  ASSERT_NE(magnetometer, nullptr);
  std::cout << "x-io: " << imu->t.size() << " IMU samples, " << magnetometer->t.size() << " magnetometer samples\n";
  ASSERT_GT(magnetometer->t.size(), 1000u);

  // The ellipsoid fit of the raw field, and the field's dip from the fitted field against the accelerometer's up.
  std::vector<Eigen::Vector3d> raw;
  std::vector<Eigen::Vector3d> up;  // the accelerometer's direction at each magnetometer sample (nearest row)
  for (Eigen::Index i = 0; i < magnetometer->values.rows(); ++i) {
    raw.push_back(magnetometer->values.row(i));
    const Time t = magnetometer->t[static_cast<std::size_t>(i)];
    const auto it = std::min(std::lower_bound(imu->t.begin(), imu->t.end(), t), std::prev(imu->t.end()));
    up.push_back(imu->values.row(it - imu->t.begin()).segment<3>(3).transpose().normalized());
  }
  auto fit = eval::FitEllipsoid(raw);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  std::cout << (fit.value().constrained ? "ellipsoid-specific fit (the general quadric is no ellipsoid)\n"
                                        : "general quadric fit\n");
  // How well the log determines the fit: the two halves of the log fitted apart (a device held z up covers a cap of
  // the ellipsoid, and a cap fits many ellipsoids).
  const auto half = static_cast<std::ptrdiff_t>(raw.size() / 2);
  for (const auto& [name, part] : {std::pair{"first", std::vector<Eigen::Vector3d>(raw.begin(), raw.begin() + half)},
                                   std::pair{"second", std::vector<Eigen::Vector3d>(raw.begin() + half, raw.end())}}) {
    const auto half_fit = eval::FitEllipsoid(part, eval::EllipsoidFitMethod::kEllipsoidSpecific);
    if (half_fit.ok()) {
      std::cout << "ellipsoid-specific fit of the " << name << " half: centre [" << half_fit.value().centre.transpose()
                << "] uT, radius " << half_fit.value().radius << " uT\n";
    }
  }
  // How well the log's samples determine any ellipsoid's centre: the Cramer-Rao bound at the fit (white noise of the
  // fit's rms residual along the normal), and a moving-block bootstrap (blocks of 1 s of samples, which keeps the
  // samples' correlation in time within each block; 200 replicates, fixed seed).
  const Eigen::Vector3d bound =
      eval::EllipsoidCentreCovariance(fit.value(), raw, fit.value().rms_residual).diagonal().cwiseSqrt();
  const double seconds = SecondsBetween(magnetometer->t.front(), magnetometer->t.back());
  const auto block = static_cast<std::size_t>(std::ceil(static_cast<double>(raw.size()) / seconds));
  const Eigen::Vector3d bootstrap = BlockBootstrapCentreStd(raw, block, 200);
  std::cout << "ellipsoid fit's centre std: Cramer-Rao [" << bound.transpose() << "] uT; block bootstrap (" << block
            << " samples a block) [" << bootstrap.transpose() << "] uT\n";
  double sum_sin_dip = 0.0;
  for (std::size_t i = 0; i < raw.size(); ++i) {
    const Eigen::Vector3d h = fit.value().correction * (raw[i] - fit.value().centre);
    sum_sin_dip += -up[i].dot(h.normalized());
  }
  const double dip = std::asin(sum_sin_dip / static_cast<double>(raw.size()));
  std::cout << "ellipsoid fit: centre [" << fit.value().centre.transpose() << "] uT, radius " << fit.value().radius
            << " uT, rms residual " << fit.value().rms_residual << " uT, dip " << dip * 180.0 / M_PI << " deg; W =\n"
            << fit.value().correction << "\n";

  auto config = LoadEstimatorConfig(kConfigs + "xio_imu_mag.yaml");
  ASSERT_TRUE(config.ok()) << config.status().message();
  const std::vector<double>& field = config.value().streams.at("mag").options.at("field_world");
  const Eigen::Vector3d h_world(field[0], field[1], field[2]);
  std::cout << "configured field: |h| " << h_world.norm() << " uT, dip "
            << std::asin(-h_world.z() / h_world.norm()) * 180.0 / M_PI << " deg\n";
  auto result = Calibrate(config.value(), rec);
  ASSERT_TRUE(result.ok()) << result.status().message();
  Print(result.value());
  const auto values = Values(result.value());
  const Eigen::Vector3d b = values.at("mag.b");
  const Eigen::Matrix3d A = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(values.at("mag.A").data());
  // z = A h^(S) + b with |h^(S)| = |h_world| and z = W^-1 h' + c with |h'| = r: A A^T = (r / |h_world|)^2 W^-2, so
  // the symmetric factor of A scaled by |h_world| / r is compared with W^-1 (eval/ellipsoid_fit.h).
  const Eigen::Matrix3d P = eval::SymmetricFactor(A) * (h_world.norm() / fit.value().radius);
  const Eigen::Matrix3d W_inv = fit.value().correction.inverse();
  const double b_error = (b - fit.value().centre).norm();
  const double A_error = (P - W_inv).cwiseAbs().maxCoeff();
  std::cout << "x-io: |b - centre| = " << b_error << " uT; max |P - W^-1| = " << A_error << "; P =\n"
            << P << "\nW^-1 =\n"
            << W_inv << "\n";
  // How well each maps the raw samples onto its sphere: the rms of |A^-1 (z - b)| - |h_world| for the estimator's,
  // the fit's rms residual for the fit's.
  const Eigen::FullPivLU<Eigen::Matrix3d> A_lu(A);
  double sum_squared = 0.0;
  for (const Eigen::Vector3d& z : raw) {
    const double e = A_lu.solve(z - b).norm() - h_world.norm();
    sum_squared += e * e;
  }
  const double estimator_rms = std::sqrt(sum_squared / static_cast<double>(raw.size()));
  double sum_squared_raw = 0.0;
  for (const Eigen::Vector3d& z : raw) sum_squared_raw += std::pow(z.norm() - h_world.norm(), 2);
  std::cout << "uncalibrated (A = I, b = 0) sphere residual rms "
            << std::sqrt(sum_squared_raw / static_cast<double>(raw.size())) << " uT\n";
  std::cout << "sphere residual rms: estimator " << estimator_rms << " uT, ellipsoid fit " << fit.value().rms_residual
            << " uT\n";
  // The log keeps the device's z axis up (the accelerometer's z stays above 0.2 g): the raw field covers a cap of its
  // ellipsoid, which does not pin the ellipsoid down. The general quadric through it is no ellipsoid, and the
  // ellipsoid-specific fit is one of a family that fits the cap about equally well; the estimator, which also knows
  // the orientations (gyroscope, accelerometer) and the field's direction, finds another member. So the comparison
  // above (b within 0.5 uT of the fit's centre, P within 0.02 of W^-1) is reported, not asserted (it holds on a
  // synthetic handheld turned through every orientation: ImuMasterTest.HandheldMagnetometerCalibration...); what is
  // asserted: the cap is what the fit saw, and the estimator's A and b map the raw field onto the sphere of the
  // configured magnitude to within twice the configured noise (the radial part of an isotropic noise sigma has rms
  // sigma; uncalibrated, A = I and b = 0, the rms printed above is several times that).
  EXPECT_TRUE(fit.value().constrained);
  // How far the log is from deciding the comparison: with white noise the samples would pin the centre down to about
  // the 0.5 uT asked (the Cramer-Rao bound printed above), but the resamples that keep 1 s of the samples' time
  // correlation spread the fit's centre 4 times that tolerance or more in some component, and the estimator's own
  // reported (HAC) std of b exceeds the tolerance in every component: the difference of the two is not measurable to
  // 0.5 uT on this log.
  constexpr double kTolerance = 0.5;  // uT: the hard-iron agreement asked of the two
  EXPECT_GT(bootstrap.maxCoeff(), 4.0 * kTolerance);
  for (const ParameterEstimate& p : result.value().parameters) {
    if (p.name == "mag.b") {
      EXPECT_GT(p.std.minCoeff(), kTolerance);
    }
  }
  EXPECT_LT(estimator_rms, 2.0 * config.value().streams.at("mag").noise.at("sigma"));
  EXPECT_TRUE(b.allFinite() && A.allFinite());
}

}  // namespace
}  // namespace roamlab::estimator
