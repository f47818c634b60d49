// Shared fixtures of the rendering and visual odometry tests: the textured room of models/vo_test_room.xml and a
// kinematic drive of its camera rig (a mocap body) at indoor-robot speeds.
#pragma once

#include <cmath>
#include <string>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "sim/mujoco_model.h"
#include "tests/sim/sim_testing.h"

namespace roamlab::sim::testing {

// The room, compiled (it must compile).
inline ModelPtr VoTestRoom() {
  auto model = LoadModelFromString(ReadText(SourcePath("models/vo_test_room.xml")), "models/vo_test_room.xml");
  EXPECT_TRUE(model.ok()) << model.status().message();
  return model.ok() ? std::move(model).value() : nullptr;
}

// Planar pose of the rig at time t [s] of the test drive: speed 0.6 + 0.35 sin(0.5 t) m/s (0.25 to 0.95) and yaw rate
// 0.45 + 1.1 sin^3(0.9 t) rad/s (-0.65 to 1.55, i.e. up to 89 deg/s), from (0, -1.2) heading east: a wobbling loop of
// about 1.3 m radius around the room's centre, clear of the boxes. Integrated by the midpoint rule in 1 ms steps.
struct RigPose {
  double x_m = 0.0;
  double y_m = -1.2;
  double yaw_rad = 0.0;
};

inline double RigSpeed(double t) { return 0.6 + 0.35 * std::sin(0.5 * t); }
inline double RigYawRate(double t) { return 0.45 + 1.1 * std::pow(std::sin(0.9 * t), 3); }

inline RigPose RigPoseAt(double t_s) {
  RigPose pose;
  constexpr double kStep = 1e-3;
  for (double t = 0.0; t < t_s - 1e-12; t += kStep) {
    const double h = std::min(kStep, t_s - t);
    const double yaw_mid = pose.yaw_rad + 0.5 * h * RigYawRate(t);
    pose.x_m += h * RigSpeed(t + 0.5 * h) * std::cos(yaw_mid);
    pose.y_m += h * RigSpeed(t + 0.5 * h) * std::sin(yaw_mid);
    pose.yaw_rad += h * RigYawRate(t + 0.5 * h);
  }
  return pose;
}

// Moves the rig to `pose` and updates positions (camera poses included).
inline void PlaceRig(const mjModel* model, mjData* data, const RigPose& pose) {
  data->mocap_pos[0] = pose.x_m;
  data->mocap_pos[1] = pose.y_m;
  data->mocap_pos[2] = 0.0;
  data->mocap_quat[0] = std::cos(0.5 * pose.yaw_rad);
  data->mocap_quat[1] = 0.0;
  data->mocap_quat[2] = 0.0;
  data->mocap_quat[3] = std::sin(0.5 * pose.yaw_rad);
  mj_forward(model, data);
}

}  // namespace roamlab::sim::testing
