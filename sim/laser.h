// Planar laser range finder (Hokuyo URG-04LX-like) simulated by MuJoCo ray casts (mj_ray): one ray per beam from the
// laser site's origin along the beam direction in the site's x-y plane. Only geom group 0 (the world: walls, clutter,
// floor) is cast against, so the robot's own geoms (groups 1 and 3 in models/diffdrive.xml) never return. A ray that
// hits nothing within max_range_m, or hits closer than min_range_m, has no return (NaN).
#pragma once

#include <vector>

#include <mujoco/mujoco.h>

#include "frontend/scan_matcher.h"

namespace roamlab::sim {

// Noise-free ranges [m] of one scan; precondition: kinematics of `data` are current (mj_forward).
std::vector<double> CastScan(const mjModel* model, const mjData* data, int laser_site,
                             const frontend::ScanGeometry& geometry);

}  // namespace roamlab::sim
