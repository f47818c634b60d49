// Trajectories of the odometric frame O in the world frame W, and their TUM text form ("t x y z qx qy qz qw").
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/status.h"
#include "common/time.h"

namespace roamlab {

struct StampedPose {
  Time t;
  Eigen::Vector3d p_world_body = Eigen::Vector3d::Zero();            // [m]
  Eigen::Quaterniond q_world_body = Eigen::Quaterniond::Identity();  // rotates O coordinates into W
};

using Trajectory = std::vector<StampedPose>;

// Reads a TUM file: one pose per line, '#' comments allowed, strictly increasing time, unit quaternions (normalized on
// read if within 1e-3 of unit norm, an error otherwise). Errors name the file and line.
Result<Trajectory> ReadTum(const std::string& path);

// Writes a TUM file with nine fractional digits for time and 17 significant digits for values.
Status WriteTum(const Trajectory& trajectory, const std::string& path);

}  // namespace roamlab
