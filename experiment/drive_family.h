// The drive families of `roamlab design` (experiment/design.h): per driver type, a drive as a few numbers, their
// normalized coordinates in [0, 1]^n for the search, the scenario profiles they make and how they read back from a
// scenario. The robot's envelope (sim/drive_envelope.h) bounds them.
//
//   ackermann       speed v(t) = v0 + dv cos(4 pi t / P), handlebar delta(t) = d0 + da sin(2 pi t / P) (one weave of
//                   period P: slowest where the handlebar is turned most), start heading h. Coordinates: v0; dv as a
//                   fraction of the room v0 leaves; da; P; d0 as a fraction of the room da leaves (0.5: none); h over
//                   a turn (wraps).
//   body_velocity   forward speed v(t) = v0 + dv sin(2 pi t / Pv), yaw rate w(t) = w0 + wa sin(2 pi t / Pw), and for
//                   a holonomic robot the sideways speed u(t) = ua sin(2 pi t / Pu + 1 rad); the scenario's start
//                   heading (on a flat floor it changes nothing the bound sees). Coordinates: v0; dv as a fraction of
//                   the room v0 leaves; wa; Pw; w0 as a fraction of the room wa leaves (0.5: none); Pv; ua; Pu. Back
//                   and forth (v0 near 0, dv large) and yaw both ways separate the wheel radii from a gyroscope's
//                   error; separate periods keep forward speed and yaw rate from moving together.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "common/status.h"
#include "sim/scenario.h"

namespace roamlab::experiment {

// One drive of a family: its numbers by name (the family's), as written into the designed scenario.
struct DriveDesign {
  std::map<std::string, double> values;
  double at(const std::string& name) const { return values.at(name); }
};

// The family's bounds (the robot's envelope unless given) and the feasibility limits (experiment/design.h).
struct DesignLimits;

class DriveFamily {
 public:
  virtual ~DriveFamily() = default;
  virtual int dimension() const = 0;
  // The coordinates in the pattern search's order (the most exciting first).
  virtual std::vector<int> SearchOrder() const = 0;
  // The coordinate that wraps around (the heading), or -1.
  virtual int Wrapping() const { return -1; }
  // The coarse grid's drives around the start's coordinates.
  virtual std::vector<std::vector<double>> Grid(const std::vector<double>& start) const = 0;
  // The drive at coordinates u in [0, 1]^n, rounded as written; and back.
  virtual DriveDesign FromCoordinates(const std::vector<double>& u) const = 0;
  virtual std::vector<double> ToCoordinates(const DriveDesign& d) const = 0;
  // The scenario's own drive mapped into the family (its constant and first sine terms), clamped to the bounds.
  virtual DriveDesign StartDrive(const sim::Scenario& scenario) const = 0;
  // The driver's profiles by their scenario key (driver.speed_mps, ...) and the start heading [deg] of the drive.
  virtual std::vector<std::pair<std::string, sim::Profile>> Profiles(const DriveDesign& d) const = 0;
  virtual double HeadingDeg(const sim::Scenario& scenario, const DriveDesign& d) const = 0;
  // The family's formula (the header comment's line) and one drive in words, for the table and the designed file.
  virtual std::string Formula() const = 0;
  virtual std::string Describe(const DriveDesign& d) const = 0;
};

// The family of the scenario's driver type, bounded by `limits` (complete: WithRobotDefaults). Error: a driver type
// without a family.
Result<std::unique_ptr<DriveFamily>> MakeDriveFamily(const sim::Scenario& scenario, const DesignLimits& limits);

// The scenario with `drive` as its driver and start heading (the values as written).
sim::Scenario WithDrive(const DriveFamily& family, const sim::Scenario& scenario, const DriveDesign& drive);

}  // namespace roamlab::experiment
