#include "beacon_drive.h"

#include <cmath>
#include <random>
#include <sstream>

namespace beacon {

using roamlab::Time;
using roamlab::recording::Recording;
using roamlab::recording::Stream;
using roamlab::recording::StreamType;

Recording SimulateBeaconDrive(const BeaconDriveOptions& o) {
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  const int n = static_cast<int>(std::lround(o.duration_s * o.rate_hz)) + 1;
  Recording rec;
  rec.platform.kind = "differential_drive";
  rec.provenance.source = "simulated";
  rec.provenance.description = "examples/consumer: a slalom among three range beacons";
  Stream odometer;
  odometer.info = {"odometer", StreamType::kOdometry, o.rate_hz, {"vx", "vy", "vz", "wx", "wy", "wz"}, "", {}, {}, {}};
  odometer.values.resize(n, 6);
  std::vector<Stream> ranges(o.beacons_world.size());
  for (std::size_t b = 0; b < ranges.size(); ++b) {
    ranges[b].info = {"uwb_" + std::to_string(b), StreamType::kInputs, o.rate_hz, {"range_m"}, "m", {}, {}, {}};
    ranges[b].values.resize(n, 1);
  }
  roamlab::Trajectory truth;
  const double dt = 1.0 / o.rate_hz;
  Eigen::Vector3d p_world_body = Eigen::Vector3d::Zero();
  double yaw = 0.0;
  for (int k = 0; k < n; ++k) {
    const double t = k * dt;
    const Time stamp = Time::FromSeconds(t);
    const Eigen::Quaterniond q_world_body(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
    truth.push_back({stamp, p_world_body, q_world_body});
    const double w = o.yaw_rate_amplitude_radps * std::cos(2.0 * M_PI * t / o.yaw_rate_period_s);
    odometer.t.push_back(stamp);
    odometer.values.row(k) << o.speed_mps + o.odometer_sigma_mps * normal(rng), o.odometer_sigma_mps * normal(rng),
        o.odometer_sigma_mps * normal(rng), o.odometer_sigma_radps * normal(rng), o.odometer_sigma_radps * normal(rng),
        w + o.odometer_sigma_radps * normal(rng);
    const Eigen::Vector3d p_world_antenna = p_world_body + q_world_body * o.p_body_antenna;
    for (std::size_t b = 0; b < ranges.size(); ++b) {
      ranges[b].t.push_back(stamp);
      ranges[b].values(k, 0) = (p_world_antenna - o.beacons_world[b]).norm() + o.range_sigma_m * normal(rng);
    }
    // Rotate half-way, translate, rotate the rest (estimator/geometry.h PredictPose).
    const Eigen::AngleAxisd half_turn(yaw + 0.5 * w * dt, Eigen::Vector3d::UnitZ());
    p_world_body += half_turn * Eigen::Vector3d(o.speed_mps * dt, 0.0, 0.0);
    yaw += w * dt;
  }
  rec.streams.push_back(std::move(odometer));
  for (Stream& s : ranges) rec.streams.push_back(std::move(s));
  rec.ground_truth = std::move(truth);
  return rec;
}

std::string BeaconDriveConfig(const BeaconDriveOptions& o) {
  std::ostringstream yaml;
  yaml << "master: odometer\n"
       << "parameters:\n"
       << "  antenna.lever_arm: {value: [0, 0, " << o.p_body_antenna.z()
       << "], free: true, prior_sigma: [.inf, .inf, 0.001]}\n"
       << "streams:\n"
       << "  odometer:\n"
       << "    model: odometer\n"
       << "    source: odometer\n"
       << "    noise: {linear_mps: " << o.odometer_sigma_mps << ", angular_radps: " << o.odometer_sigma_radps << "}\n";
  for (std::size_t b = 0; b < o.beacons_world.size(); ++b) {
    const Eigen::Vector3d& p = o.beacons_world[b];
    yaml << "  uwb_" << b << ":\n"
         << "    model: range_beacon\n"
         << "    source: uwb_" << b << "\n"
         << "    noise: {sigma_m: " << o.range_sigma_m << "}\n"
         << "    options: {beacon_world: [" << p.x() << ", " << p.y() << ", " << p.z() << "]}\n"
         << "    parameters: {lever_arm: antenna.lever_arm}\n";
  }
  return yaml.str();
}

}  // namespace beacon
