// The effective rolling radius of a robot's wheels, measured on its physics without the estimator.
//
// The wheel models' radius r turns a wheel's spin rate into its contact's speed (v = r omega). A roller wheel (omni3,
// mecanum) rests on the roller under it: a sphere of radius rho whose centre is c from the hub, so the hub is
// rho + c cos(phi) above the floor at wheel angle phi from that roller's bottom position, and it advances that much
// per radian of the wheel. Between two of the N rollers the axle dips, and the travel per radian over a pitch 2 pi / N
// is rho + c sin(pi / N) / (pi / N), below the rollers' envelope rho + c; the soft contact's penetration under the
// robot's weight lowers it further. That travel per radian, not the envelope, is the truth of r.
//
// MeasureRollingRadii drives a copy of the bound model: placed at rest on the floor (every world geom but the ground,
// `terrain`, out of contact, so that walls cannot stop it), settled, then for each rolling direction in turn a slow
// straight drive along it, ramped up and held at constant speed; over a whole number of roller pitches (one
// revolution for a tire) the wheel's hub travel along its rolling direction divided by its rotation. The speed is
// low enough for the rollers to keep their contact (faster, the roller contacts' bouncing makes the travel per
// radian differ between wheels by a tenth of a millimetre).
// Driven along its own rolling direction, a wheel's rollers do not turn and nothing asks it to slip. Deterministic:
// the same model and start give the same radii.
//
// The Ackermann vehicle's rear tires (spheres of the geometric radius r) roll below r too: the soft contact lets a tire
// sink into the ground under the vehicle's weight, MuJoCo puts the contact point midway through the penetration, and
// on a heightfield a tire over a triangle's edge rests on two contacts. MeasureRearRollingRadius drives a copy of the
// bound model on its own ground made level (a heightfield's samples and geom set to z = 0, so that the tires meet the
// same triangles; a plane as it is; every other world geom out of contact): placed at rest at the origin heading
// along x, settled, then straight (handlebar 0) under the speed controller, ramped up to a slow speed and held; over
// whole revolutions of the rear wheels, each rear hub's travel along its rolling direction over its rotation, the
// mean of the two. On level ground at constant speed the tires carry only the rolling resistance: the free-rolling
// travel per radian, which does not depend on the speed or the heading. Deterministic.
//
// Driven, a tire slips: MuJoCo's soft friction passes a tangential force through a slip velocity that grows with it,
// so the wheel turns faster than its hub advances. The drive's `grade` puts the force balance of a slope on the same
// level ground: gravity turned by atan(grade) about the lateral axis, so that the rear tires carry the weight's
// component along the slope, m g sin(atan(grade)), on top of the rolling resistance, at the same contact geometry (the
// level ground's triangles). MeasureRearRoll reports the window's travel per radian with the traction the ground puts
// on the rear tires and their spin rate, from which a slip-versus-traction curve follows unconfounded by the terrain's
// shape.
#pragma once

#include <string>
#include <vector>

#include <mujoco/mujoco.h>

#include "common/status.h"
#include "sim/ackermann.h"
#include "sim/wheeled_robot.h"

namespace roamlab::sim {

struct RollingRadiusDrive {
  double speed_mps = 0.2;  // body speed along the rolling direction
  double settle_s = 0.5;   // at rest after placing
  double ramp_s = 0.3;     // speed ramp of each direction's drive
  double hold_s = 0.3;     // at constant speed before the measurement
  int pitches = 4;         // roller pitches measured over (a tire: one revolution)
};

// The travel per radian [m] of each wheel of `robot` (bound to `model`), started at (x, y) heading yaw_rad. Errors
// name `what` (a wheel that does not turn its window within the time the drive allows, a diverged simulation).
Result<std::vector<double>> MeasureRollingRadii(const mjModel* model, const WheeledRobot& robot, double x, double y,
                                                double yaw_rad, const std::string& what,
                                                const RollingRadiusDrive& drive = {});

struct RearRollingDrive {
  double speed_mps = 1.0;  // the speed controller's set-point
  double settle_s = 1.0;   // at rest after placing
  double ramp_s = 1.0;     // speed ramp
  double hold_s = 2.0;     // at constant speed before the measurement
  int revolutions = 4;     // of the rear wheels, measured over
  double grade = 0.0;      // rise per run of the slope driven up (negative: down), |grade| < 1

  // Empty when usable; otherwise "<field>: <problem>".
  std::string Validate() const;
};

// What one straight drive of the rear wheels measures over its window.
struct RearRoll {
  double travel_per_rad_m = 0.0;  // the rear hubs' travel along their rolling direction over their rotation (mean)
  double wheel_rate_radps = 0.0;  // the rear wheels' mean spin rate over the window
  double traction_n = 0.0;        // the ground's force on both rear tires along their rolling direction (mean)
};

// The free-rolling travel per radian [m] of the rear tires of `vehicle` (bound to `model`), driven by `controller`
// (drive.grade 0: level ground). Errors name `what` (a wheel that does not turn its window within the time the drive
// allows, a diverged simulation, an unusable drive).
Result<double> MeasureRearRollingRadius(const mjModel* model, const AckermannVehicle& vehicle,
                                        const SpeedControllerOptions& controller, const std::string& what,
                                        const RearRollingDrive& drive = {});

// The ground's force [N] on the rear tires of the Ackermann model `model` (models/atv.xml's names) along their mean
// rolling direction (the rear hinges' axes crossed with the world's z), summed over their contacts in `data`, whose
// constraint forces must be current (after mj_forward or a step). Positive: pushing the vehicle forward.
double RearTractionN(const mjModel* model, const mjData* data);

// The same drive's window in full: travel per radian, spin rate and traction. The slip velocity against a reference
// travel per radian r_ref (e.g. the level drive's) is wheel_rate_radps (r_ref - travel_per_rad_m).
Result<RearRoll> MeasureRearRoll(const mjModel* model, const AckermannVehicle& vehicle,
                                 const SpeedControllerOptions& controller, const std::string& what,
                                 const RearRollingDrive& drive = {});

}  // namespace roamlab::sim
