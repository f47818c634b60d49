#include "sim/internal/simulation_metadata.h"

#include <sstream>

#include <mujoco/mujoco.h>

namespace roamlab::sim::internal {
namespace {

// "<stream>.lever_arm" and "<stream>.misalignment" of a mounting.
void AddMounting(const std::string& stream, const recording::Mounting& mounting,
                 std::map<std::string, std::vector<double>>* cal) {
  const Eigen::Vector3d& s = mounting.p_body_sensor;
  const Eigen::Quaterniond& q = mounting.q_body_sensor;
  (*cal)[stream + ".lever_arm"] = {s.x(), s.y(), s.z()};
  (*cal)[stream + ".misalignment"] = {q.w(), q.x(), q.y(), q.z()};
}

}  // namespace

recording::Provenance SimulatedProvenance(const Scenario& scenario, std::uint64_t seed, const std::string& model_where,
                                          bool noise) {
  recording::Provenance provenance;
  provenance.source = "simulated";
  provenance.scenario = scenario.source_file;
  provenance.seed = seed;
  std::ostringstream description;
  if (!scenario.name.empty()) description << scenario.name << ": ";
  description << "MuJoCo " << mj_versionString() << ", model " << model_where << ", terrain "
              << (scenario.terrain.type == TerrainOptions::Type::kHills
                      ? "hills (seed " + std::to_string(scenario.terrain.seed) + ")"
                      : std::string("flat"))
              << (noise ? "" : ", noise off");
  provenance.description = description.str();
  return provenance;
}

std::map<std::string, std::vector<double>> TrueCalibration(const SensorOptions& sensors,
                                                           const TrueSensorFrames& frames) {
  std::map<std::string, std::vector<double>> cal;
  if (sensors.gps) {
    const Eigen::Vector3d& s = sensors.gps->lever_arm_m;
    cal["gps.lever_arm"] = {s.x(), s.y(), s.z()};
  }
  if (sensors.imu) {
    const Eigen::Quaterniond& q = frames.imu.q_body_imu;
    const Eigen::Vector3d& p = frames.imu.p_body_imu;
    cal["imu.misalignment"] = {q.w(), q.x(), q.y(), q.z()};
    if (!p.isZero(0.0)) cal["imu.lever_arm"] = {p.x(), p.y(), p.z()};
  }
  if (sensors.magnetometer) {
    const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> A = frames.magnetometer.A;
    const Eigen::Vector3d& b = frames.magnetometer.b;
    cal["magnetometer.A"] = std::vector<double>(A.data(), A.data() + 9);
    cal["magnetometer.b"] = {b.x(), b.y(), b.z()};
  }
  if (sensors.wheel_encoders) {
    for (const auto& [name, value] : frames.wheels) cal[name] = value;
  }
  if (sensors.laser) AddMounting("scan_matching", frames.laser, &cal);
  if (frames.camera) AddMounting("visual_odometry", *frames.camera, &cal);
  if (sensors.odometer) {
    // The reading z_v = omega r / k_v takes the tires' geometric radius r; the ground passes at omega times their
    // travel per radian, so the true gain is the scenario's times that over r, which is stated beside it.
    cal["odometer.kv_over_L"] = {sensors.odometer->kv_over_L * frames.rear_rolling_over_radius};
    cal["odometer.kv_over_L_geometric"] = {sensors.odometer->kv_over_L};
    cal["odometer.k_theta"] = {sensors.odometer->k_theta};
    cal["odometer.k_gamma"] = {sensors.odometer->k_gamma};
  }
  return cal;
}

}  // namespace roamlab::sim::internal
