// Private helpers of the simulator: how a scenario's effects (scenario.h) change the robot it builds.
#pragma once

#include <string>
#include <vector>

#include "sim/scenario.h"
#include "sim/wheeled_robot.h"

namespace roamlab::sim::internal {

// Whether the scenario lists the effect `name`.
bool HasEffect(const Scenario& scenario, const std::string& name);

// The tires' deformations: robot.wheel_deformation with the tire effects on top, one entry per deformed wheel so that
// Deform changes each tire once: wheel_radius_asymmetry multiplies the right tire's radius (wheel_1) by the ratio
// rho = r_R / r_L, wheel_radius_scale every wheel's radius (differential_drive 2, omni3 3, skid_steer and mecanum 4),
// wheel_deformation adds its ovality to its wheel's and keeps that tire's mean rolling radius (an out-of-round tire:
// the periodic part of the radius only, not a ratio).
std::vector<WheelDeformation> TireDeformations(const Scenario& scenario);

}  // namespace roamlab::sim::internal
