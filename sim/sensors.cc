#include "sim/sensors.h"

#include "common/check.h"

namespace roamlab::sim {
namespace {

Eigen::Vector3d Vec(const mjtNum* v) { return Eigen::Vector3d(v[0], v[1], v[2]); }

}  // namespace

FrameKinematics ReadSiteKinematics(const mjModel* model, const mjData* data, int site) {
  ROAMLAB_CHECK(site >= 0 && site < model->nsite, "site id " << site);
  FrameKinematics k;
  k.p_world_body = Vec(data->site_xpos + 3 * site);
  Eigen::Matrix3d R_world_body;
  const mjtNum* xmat = data->site_xmat + 9 * site;  // row-major
  R_world_body << xmat[0], xmat[1], xmat[2], xmat[3], xmat[4], xmat[5], xmat[6], xmat[7], xmat[8];
  k.q_world_body = Eigen::Quaterniond(R_world_body).normalized();

  // [angular; linear], in the site frame.
  mjtNum velocity[6];
  mjtNum acceleration[6];
  mj_objectVelocity(model, data, mjOBJ_SITE, site, velocity, 1);
  mj_objectAcceleration(model, data, mjOBJ_SITE, site, acceleration, 1);
  k.omega_body = Vec(velocity);
  k.v_body = Vec(velocity + 3);
  k.alpha_body = Vec(acceleration);
  k.specific_force_body = Vec(acceleration + 3);
  return k;
}

Eigen::Vector3d GyroReading(const FrameKinematics& body, const ImuCalibration& imu) {
  return imu.q_body_imu.conjugate() * body.omega_body;
}

Eigen::Vector3d AccelReading(const FrameKinematics& body, const ImuCalibration& imu) {
  const Eigen::Vector3d& S = imu.p_body_imu;
  const Eigen::Vector3d& w = body.omega_body;
  const Eigen::Vector3d f_at_imu = body.specific_force_body + body.alpha_body.cross(S) + w.cross(w.cross(S));
  return imu.q_body_imu.conjugate() * f_at_imu;
}

Eigen::Vector3d MagnetometerReading(const FrameKinematics& body, const Eigen::Quaterniond& q_body_imu,
                                    const MagnetometerCalibration& magnetometer) {
  return magnetometer.A * ((body.q_world_body * q_body_imu).conjugate() * magnetometer.field_world) + magnetometer.b;
}

Eigen::Vector3d GpsAntennaWorld(const FrameKinematics& body, const Eigen::Vector3d& lever_arm_m) {
  return body.p_world_body + body.q_world_body * lever_arm_m;
}

double SpeedReading(double rear_wheel_rate_radps, double wheel_radius_m, double kv_over_L, double wheelbase_m) {
  return rear_wheel_rate_radps * wheel_radius_m / (kv_over_L * wheelbase_m);
}

double SteeringReading(double delta_rad, double k_theta, double k_gamma) { return (delta_rad - k_gamma) / k_theta; }

}  // namespace roamlab::sim
