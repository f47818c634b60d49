#include "tests/support/synthetic.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <GeographicLib/LocalCartesian.hpp>

#include "common/check.h"
#include "estimator/geometry.h"

namespace roamlab::testing {
namespace {

constexpr double kPi = 3.14159265358979323846;
// The truth grid: 1 kHz, and the half-width of the finite differences for the body rate and the acceleration.
constexpr std::int64_t kGridStepNs = 1000000;
constexpr double kGridStepS = 1e-3;

constexpr recording::GeodeticOrigin kOrigin{45.4642, 9.19, 120.0};

// Noise sources; the index is mixed into the seed of each one's generator.
enum NoiseSource { kGyroNoise = 0, kAccelNoise, kMagNoise, kGpsNoise, kSpeedNoise, kSteeringNoise, kGpsBias };

// One plane sinusoid of the terrain: amplitude * sin(kx x + ky y + phase), amplitude [m], wave numbers [rad/m].
struct TerrainWave {
  double amplitude;
  double kx;
  double ky;
  double phase;
};

constexpr TerrainWave kHills[] = {
    {0.45, 2.0 * kPi / 60.0, 2.0 * kPi / 50.0, 0.0},
    {0.45, 2.0 * kPi / 60.0, -2.0 * kPi / 50.0, 0.0},
    {0.60, 2.0 * kPi / 45.0, 2.0 * kPi / 45.0, 0.7},
    {0.30, 2.0 * kPi / 30.0, -kPi / 30.0, 0.5 * kPi},
};

// Height [m] and its gradient at (x, y).
struct TerrainSample {
  double h = 0.0;
  double h_x = 0.0;
  double h_y = 0.0;
};

// Speed along the surface [m/s] and steering angle [rad] at t [s].
double Speed(double t) {
  return 4.5 + 1.0 * std::sin(2.0 * kPi * t / 13.0) + 0.4 * std::sin(2.0 * kPi * t / 4.7 + 0.6);
}
double Steering(double t) {
  return 0.18 * std::sin(2.0 * kPi * t / 11.0 + 0.3) + 0.1 * std::sin(2.0 * kPi * t / 3.7 + 1.1);
}

// The vehicle's truth at any time in [-1 ms, end + 1 ms]: planar state on a 1 kHz RK4 grid, refined to the requested
// time with one partial RK4 step; pose, rates and acceleration derived from it.
class AtvTruth {
 public:
  struct Kinematics {
    Eigen::Vector3d p_world_body;
    Eigen::Quaterniond q_world_body;
    Eigen::Vector3d omega_body;  // [rad/s]
    Eigen::Vector3d a_world;     // [m/s^2], without gravity
    double speed_mps;            // |v_body|
  };

  // Queried for t in [start_ns, end_ns] (start_ns <= 0).
  AtvTruth(bool hilly, double wheelbase_m, std::int64_t start_ns, std::int64_t end_ns)
      : hilly_(hilly), wheelbase_m_(wheelbase_m), first_node_(start_ns / kGridStepNs - 2) {
    if (hilly_) height_offset_ = SumWaves(0.0, 0.0).h;
    // Grid nodes from first to last (inclusive), so that every t +- 1 ms with t in [start, end] has a node at or before
    // it.
    const std::int64_t last = end_ns / kGridStepNs + 2;
    nodes_.resize(static_cast<std::size_t>(last - first_node_ + 1));
    Node(0) = Eigen::Vector3d::Zero();
    for (std::int64_t j = 0; j > first_node_; --j) Node(j - 1) = Rk4(j * kGridStepS, Node(j), -kGridStepS);
    for (std::int64_t j = 0; j < last; ++j) Node(j + 1) = Rk4(j * kGridStepS, Node(j), kGridStepS);
  }

  Kinematics At(std::int64_t t_ns) const {
    const Eigen::Vector3d before = StateAt(t_ns - kGridStepNs);
    const Eigen::Vector3d now = StateAt(t_ns);
    const Eigen::Vector3d after = StateAt(t_ns + kGridStepNs);
    Kinematics k;
    Eigen::Quaterniond q_before, q_after;
    Eigen::Vector3d p_before, p_after;
    PoseOf(before, &p_before, &q_before);
    PoseOf(now, &k.p_world_body, &k.q_world_body);
    PoseOf(after, &p_after, &q_after);
    k.omega_body = estimator::QuaternionLog<double>(q_before.conjugate() * q_after) / (2.0 * kGridStepS);
    k.a_world = (p_after - 2.0 * k.p_world_body + p_before) / (kGridStepS * kGridStepS);
    k.speed_mps = Speed(static_cast<double>(t_ns) * 1e-9);
    return k;
  }

 private:
  Eigen::Vector3d& Node(std::int64_t j) { return nodes_[static_cast<std::size_t>(j - first_node_)]; }
  const Eigen::Vector3d& Node(std::int64_t j) const { return nodes_[static_cast<std::size_t>(j - first_node_)]; }

  static TerrainSample SumWaves(double x, double y) {
    TerrainSample sample;
    for (const TerrainWave& wave : kHills) {
      const double phase = wave.kx * x + wave.ky * y + wave.phase;
      sample.h += wave.amplitude * std::sin(phase);
      sample.h_x += wave.amplitude * wave.kx * std::cos(phase);
      sample.h_y += wave.amplitude * wave.ky * std::cos(phase);
    }
    return sample;
  }

  TerrainSample Terrain(double x, double y) const {
    if (!hilly_) return TerrainSample{};
    TerrainSample sample = SumWaves(x, y);
    sample.h -= height_offset_;
    return sample;
  }

  // d(x, y, yaw)/dt at time t [s].
  Eigen::Vector3d Derivative(double t, const Eigen::Vector3d& state) const {
    const double c = std::cos(state.z());
    const double s = std::sin(state.z());
    const TerrainSample terrain = Terrain(state.x(), state.y());
    const double slope = terrain.h_x * c + terrain.h_y * s;
    const double v = Speed(t);
    const double horizontal = v / std::sqrt(1.0 + slope * slope);
    return Eigen::Vector3d(horizontal * c, horizontal * s, v * std::tan(Steering(t)) / wheelbase_m_);
  }

  Eigen::Vector3d Rk4(double t, const Eigen::Vector3d& state, double h) const {
    const Eigen::Vector3d k1 = Derivative(t, state);
    const Eigen::Vector3d k2 = Derivative(t + 0.5 * h, state + 0.5 * h * k1);
    const Eigen::Vector3d k3 = Derivative(t + 0.5 * h, state + 0.5 * h * k2);
    const Eigen::Vector3d k4 = Derivative(t + h, state + h * k3);
    return state + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  }

  // Planar state at t_ns: the grid node at or before it plus one partial step.
  Eigen::Vector3d StateAt(std::int64_t t_ns) const {
    std::int64_t j = t_ns / kGridStepNs;
    if (j * kGridStepNs > t_ns) --j;  // floor for negative times
    ROAMLAB_CHECK(j >= first_node_ && j - first_node_ < static_cast<std::int64_t>(nodes_.size()),
                  "synthetic truth queried outside its grid at " << t_ns << " ns");
    const std::int64_t rest_ns = t_ns - j * kGridStepNs;
    if (rest_ns == 0) return Node(j);
    return Rk4(j * kGridStepS, Node(j), static_cast<double>(rest_ns) * 1e-9);
  }

  // Pose of O for a planar state: on the surface, x along the path, z along the terrain normal.
  void PoseOf(const Eigen::Vector3d& state, Eigen::Vector3d* p_world_body, Eigen::Quaterniond* q_world_body) const {
    const TerrainSample terrain = Terrain(state.x(), state.y());
    const double c = std::cos(state.z());
    const double s = std::sin(state.z());
    const Eigen::Vector3d x_axis = Eigen::Vector3d(c, s, terrain.h_x * c + terrain.h_y * s).normalized();
    const Eigen::Vector3d normal(-terrain.h_x, -terrain.h_y, 1.0);
    const Eigen::Vector3d z_axis = (normal - normal.dot(x_axis) * x_axis).normalized();
    Eigen::Matrix3d R_world_body;
    R_world_body << x_axis, z_axis.cross(x_axis), z_axis;
    *p_world_body = Eigen::Vector3d(state.x(), state.y(), terrain.h);
    *q_world_body = Eigen::Quaterniond(R_world_body).normalized();
  }

  bool hilly_;
  double wheelbase_m_;
  double height_offset_ = 0.0;
  std::int64_t first_node_;
  std::vector<Eigen::Vector3d> nodes_;  // planar state at node j * 1 ms, j from first_node_
};

// Zero-mean Gaussian noise of one source; all zeros when disabled.
class NoiseStream {
 public:
  NoiseStream(bool enabled, std::uint32_t seed, NoiseSource source) : enabled_(enabled) {
    std::seed_seq sequence{seed, static_cast<std::uint32_t>(source)};
    generator_.seed(sequence);
  }
  double Draw(double sigma) { return enabled_ ? sigma * normal_(generator_) : 0.0; }
  Eigen::Vector3d Draw3(double sigma) {
    const double x = Draw(sigma);
    const double y = Draw(sigma);
    const double z = Draw(sigma);
    return Eigen::Vector3d(x, y, z);
  }

 private:
  bool enabled_;
  std::mt19937_64 generator_;
  std::normal_distribution<double> normal_{0.0, 1.0};
};

std::int64_t PeriodNs(double rate_hz) { return std::llround(1e9 / rate_hz); }

// t_k = k * period for t_k <= end.
std::vector<Time> SampleTimes(double rate_hz, std::int64_t end_ns) {
  const std::int64_t period_ns = PeriodNs(rate_hz);
  std::vector<Time> times;
  for (std::int64_t t = 0; t <= end_ns; t += period_ns) times.push_back(Time::FromNanoseconds(t));
  return times;
}

recording::Stream MakeStream(const std::string& name, recording::StreamType type, double rate_hz,
                             std::vector<std::string> columns, const std::string& units, std::int64_t end_ns) {
  recording::Stream stream;
  stream.info.name = name;
  stream.info.type = type;
  stream.info.rate_hz = rate_hz;
  stream.info.columns = std::move(columns);
  stream.info.units = units;
  stream.t = SampleTimes(rate_hz, end_ns);
  stream.values.resize(static_cast<Eigen::Index>(stream.t.size()),
                       static_cast<Eigen::Index>(stream.info.columns.size()));
  return stream;
}

bool IsFinite(double x) { return std::isfinite(x); }

}  // namespace

std::string SyntheticOptions::Validate() const {
  std::ostringstream problems;
  const auto require = [&problems](bool ok, const char* what) {
    if (!ok) problems << (problems.tellp() > 0 ? "; " : "") << what;
  };
  require(IsFinite(duration_s) && duration_s > 0.0, "duration_s must be > 0");
  for (double rate : {imu_rate_hz, odometer_rate_hz, gps_rate_hz}) {
    require(IsFinite(rate) && rate > 0.0 && rate <= 1000.0, "rates must be in (0, 1000] Hz");
  }
  require(gps_lever_arm_m.allFinite(), "gps_lever_arm_m must be finite");
  require(q_body_imu.coeffs().allFinite() && q_body_imu.norm() > 0.5 && q_body_imu.norm() < 2.0,
          "q_body_imu must be near unit norm");
  require(mag_A.allFinite() && mag_b.allFinite(), "mag_A and mag_b must be finite");
  require(IsFinite(kv_over_L) && kv_over_L > 0.0, "kv_over_L must be > 0");
  require(IsFinite(k_theta) && k_theta != 0.0, "k_theta must be nonzero");
  require(IsFinite(k_gamma), "k_gamma must be finite");
  require(IsFinite(wheelbase_m) && wheelbase_m > 0.0, "wheelbase_m must be > 0");
  require(gyro_bias_radps.allFinite(), "gyro_bias_radps must be finite");
  require(IsFinite(imu_time_offset_s) && std::abs(imu_time_offset_s) <= 1.0, "imu_time_offset_s must be in [-1, 1]");
  for (double sigma : {sigma_gps_m, sigma_mag, sigma_acc_mps2, sigma_gyro_radps, sigma_speed_mps, sigma_steering_rad,
                       gps_bias_sigma_m}) {
    require(IsFinite(sigma) && sigma >= 0.0, "noise sigmas must be >= 0");
  }
  require(IsFinite(gps_bias_tau_s) && gps_bias_tau_s > 0.0, "gps_bias_tau_s must be > 0");
  require(field_world.allFinite() && field_world.norm() > 0.0, "field_world must be finite and nonzero");
  return problems.str();
}

SyntheticRecording MakeAtvRecording(const SyntheticOptions& options) {
  const std::string problem = options.Validate();
  ROAMLAB_CHECK(problem.empty(), "invalid SyntheticOptions: " << problem);

  const std::int64_t end_ns = std::llround(options.duration_s * 1e9);
  // The IMU's and magnetometer's rows stamped t are read at t - imu_time_offset_s.
  const std::int64_t imu_offset_ns = std::llround(options.imu_time_offset_s * 1e9);
  const AtvTruth truth_model(options.hilly, options.wheelbase_m, std::min<std::int64_t>(0, -imu_offset_ns),
                             end_ns + std::max<std::int64_t>(0, -imu_offset_ns));
  const Eigen::Quaterniond q_body_imu = options.q_body_imu.normalized();
  const double k_v = options.kv_over_L * options.wheelbase_m;

  SyntheticRecording out;
  recording::Recording& rec = out.recording;
  rec.platform.kind = "ackermann";
  rec.platform.geometry = {{"wheelbase_m", options.wheelbase_m}};
  rec.origin = kOrigin;
  rec.provenance.source = "simulated";
  rec.provenance.seed = options.seed;
  rec.provenance.description = "synthetic kinematic ATV (tests/support)";

  NoiseStream gyro_noise(options.noise, options.seed, kGyroNoise);
  NoiseStream accel_noise(options.noise, options.seed, kAccelNoise);
  NoiseStream mag_noise(options.noise, options.seed, kMagNoise);
  NoiseStream gps_noise(options.noise, options.seed, kGpsNoise);
  NoiseStream speed_noise(options.noise, options.seed, kSpeedNoise);
  NoiseStream steering_noise(options.noise, options.seed, kSteeringNoise);
  NoiseStream gps_bias_noise(options.noise, options.seed, kGpsBias);

  // IMU (gyro, specific force) and ground truth at the IMU times.
  recording::Stream imu = MakeStream("imu", recording::StreamType::kImu, options.imu_rate_hz,
                                     {"wx", "wy", "wz", "ax", "ay", "az"}, "", end_ns);
  imu.info.mounting = recording::Mounting{};
  imu.info.noise = {{"gyro_sigma_radps", options.sigma_gyro_radps}, {"accel_sigma_mps2", options.sigma_acc_mps2}};
  Trajectory ground_truth;
  ground_truth.reserve(imu.t.size());
  for (std::size_t k = 0; k < imu.t.size(); ++k) {
    const AtvTruth::Kinematics truth = truth_model.At(imu.t[k].nanoseconds());
    const AtvTruth::Kinematics read = truth_model.At(imu.t[k].nanoseconds() - imu_offset_ns);
    const Eigen::Vector3d gyro =
        q_body_imu.conjugate() * read.omega_body + options.gyro_bias_radps + gyro_noise.Draw3(options.sigma_gyro_radps);
    const Eigen::Vector3d accel = q_body_imu.conjugate() * (read.q_world_body.conjugate() *
                                                            (read.a_world + estimator::kSpecificForceAtRest_world)) +
                                  accel_noise.Draw3(options.sigma_acc_mps2);
    imu.values.row(static_cast<Eigen::Index>(k)) << gyro.transpose(), accel.transpose();

    StampedPose pose{imu.t[k], truth.p_world_body, truth.q_world_body};
    // Keep the quaternion sign continuous so that the TUM file has no jumps.
    if (!ground_truth.empty() && ground_truth.back().q_world_body.dot(pose.q_world_body) < 0.0) {
      pose.q_world_body.coeffs() = -pose.q_world_body.coeffs();
    }
    ground_truth.push_back(pose);
  }

  // Magnetometer, in the IMU's frame, at the IMU rate.
  recording::Stream mag = MakeStream("magnetometer", recording::StreamType::kMagnetometer, options.imu_rate_hz,
                                     {"mx", "my", "mz"}, "normalized", end_ns);
  mag.info.mounting = recording::Mounting{};
  mag.info.noise = {{"sigma_normalized", options.sigma_mag}};
  for (std::size_t k = 0; k < mag.t.size(); ++k) {
    const AtvTruth::Kinematics truth = truth_model.At(mag.t[k].nanoseconds() - imu_offset_ns);
    const Eigen::Vector3d z = options.mag_A * ((truth.q_world_body * q_body_imu).conjugate() * options.field_world) +
                              options.mag_b + mag_noise.Draw3(options.sigma_mag);
    mag.values.row(static_cast<Eigen::Index>(k)) = z.transpose();
  }

  // GPS: antenna position with ENU noise, converted to geodetic coordinates.
  recording::Stream gps = MakeStream("gps", recording::StreamType::kGps, options.gps_rate_hz,
                                     {"latitude", "longitude", "altitude"}, "deg", end_ns);
  gps.info.mounting = recording::Mounting{};
  gps.info.noise = {{"sigma_m", options.sigma_gps_m}};
  const GeographicLib::LocalCartesian local(kOrigin.latitude_deg, kOrigin.longitude_deg, kOrigin.altitude_m);
  const double bias_decay = std::exp(-1.0 / (options.gps_rate_hz * options.gps_bias_tau_s));
  Eigen::Vector3d bias_world = gps_bias_noise.Draw3(options.gps_bias_sigma_m);
  for (std::size_t k = 0; k < gps.t.size(); ++k) {
    if (k > 0)
      bias_world = bias_decay * bias_world +
                   gps_bias_noise.Draw3(options.gps_bias_sigma_m * std::sqrt(1.0 - bias_decay * bias_decay));
    const AtvTruth::Kinematics truth = truth_model.At(gps.t[k].nanoseconds());
    const Eigen::Vector3d antenna_world = truth.p_world_body + truth.q_world_body * options.gps_lever_arm_m +
                                          bias_world + gps_noise.Draw3(options.sigma_gps_m);
    double latitude = 0.0, longitude = 0.0, altitude = 0.0;
    local.Reverse(antenna_world.x(), antenna_world.y(), antenna_world.z(), latitude, longitude, altitude);
    gps.values.row(static_cast<Eigen::Index>(k)) << latitude, longitude, altitude;
  }

  // Rear-wheel speed and handlebar angle (eq. 15 inverted for the body yaw rate).
  recording::Stream wheel = MakeStream("rear_wheel", recording::StreamType::kWheelEncoders, options.odometer_rate_hz,
                                       {"rear"}, "m/s", end_ns);
  wheel.info.noise = {{"sigma_mps", options.sigma_speed_mps}};
  recording::Stream steering =
      MakeStream("steering", recording::StreamType::kSteering, options.odometer_rate_hz, {"angle"}, "rad", end_ns);
  steering.info.noise = {{"sigma_rad", options.sigma_steering_rad}};
  for (std::size_t k = 0; k < wheel.t.size(); ++k) {
    const AtvTruth::Kinematics truth = truth_model.At(wheel.t[k].nanoseconds());
    const double delta_eff = std::atan(options.wheelbase_m * truth.omega_body.z() / truth.speed_mps);
    wheel.values(static_cast<Eigen::Index>(k), 0) = truth.speed_mps / k_v + speed_noise.Draw(options.sigma_speed_mps);
    steering.values(static_cast<Eigen::Index>(k), 0) =
        (delta_eff - options.k_gamma) / options.k_theta + steering_noise.Draw(options.sigma_steering_rad);
  }

  rec.streams = {std::move(imu), std::move(mag), std::move(gps), std::move(wheel), std::move(steering)};
  rec.ground_truth = std::move(ground_truth);

  // The true calibration.
  Eigen::Matrix<double, 3, 3, Eigen::RowMajor> A_row_major = options.mag_A;
  out.truth.calibration = {
      {"gps.lever_arm", {options.gps_lever_arm_m.x(), options.gps_lever_arm_m.y(), options.gps_lever_arm_m.z()}},
      {"imu.misalignment", {q_body_imu.w(), q_body_imu.x(), q_body_imu.y(), q_body_imu.z()}},
      {"magnetometer.A", std::vector<double>(A_row_major.data(), A_row_major.data() + 9)},
      {"magnetometer.b", {options.mag_b.x(), options.mag_b.y(), options.mag_b.z()}},
      {"odometer.kv_over_L", {options.kv_over_L}},
      {"odometer.k_theta", {options.k_theta}},
      {"odometer.k_gamma", {options.k_gamma}},
  };
  if (!options.gyro_bias_radps.isZero(0.0)) {
    const Eigen::Vector3d& b = options.gyro_bias_radps;
    out.truth.calibration["imu.gyro_bias"] = {b.x(), b.y(), b.z()};
  }
  if (options.imu_time_offset_s != 0.0) out.truth.calibration["imu.time_offset_s"] = {options.imu_time_offset_s};
  return out;
}

}  // namespace roamlab::testing
