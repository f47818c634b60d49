// Planar (top view) comparison of trajectories: the reference's planar pose at any time, and the figure of the
// reference with every estimate (the seed 001's Fig. 5).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "common/time.h"
#include "recording/trajectory.h"

namespace roamlab::eval {

// Planar pose (x [m], y [m], yaw [rad]) of `trajectory` at t, linearly interpolated (yaw along the shorter arc);
// false outside its span or with fewer than two poses.
bool PlanarPoseAt(const Trajectory& trajectory, Time t, Eigen::Vector3d* x_y_yaw);

// One estimated planar trajectory of the figure, sampled at the reference's times.
struct TopViewSeries {
  std::string label;
  std::vector<Eigen::Vector3d> poses;  // x, y, yaw
};

// Top view of the reference (black, titled `reference_label`) and every series: NAME.dat, NAME.gp and NAME.png (drawn
// with gnuplot) in `dir`.
Status WriteTopViewFigure(const std::string& dir, const std::string& name, const std::string& title,
                          const std::vector<Eigen::Vector3d>& reference, const std::vector<TopViewSeries>& series,
                          const std::string& reference_label = "reference (ground_truth.tum)");

}  // namespace roamlab::eval
