// Accuracy metrics of an estimated trajectory against a reference (ground truth): absolute trajectory error (ATE) and
// relative pose error (RPE), as defined by Sturm et al. 2012 (the TUM RGB-D benchmark) and Burgard et al. 2009 (the
// seed's ref. [22], used in its Section VI).
//
// All functions take matched trajectories (eval/association.h: SelectMatched): pose i of the estimate and pose i of
// the reference describe the same instant. Positions in metres, angles in degrees, world frames as in
// recording/trajectory.h.
//
//   ATE   e_i = |s R p_est_i + t - p_ref_i| after the alignment T = (s, R, t) of eval/alignment.h; its rotation part
//         is the angle of R_ref_i^T (R R_est_i) [deg]; per axis, the components of the position error in the reference
//         world frame, horizontal |(e_x, e_y)| and vertical |e_z|.
//   RPE   for a pair (i, j): E_ij = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j) with Q the reference and P the estimate poses;
//         translation error |trans(E_ij)| [m], rotation error angle(rot(E_ij)) [deg]. E_ij does not change when a rigid
//         transform is applied to the whole estimate, so RPE needs no alignment.
//         By step: all pairs (i, i + k), k poses apart.
//         By distance: for every i, j is the first pose at which the path length travelled along the reference since i
//         reaches d metres (poses with no such j are not used).
#pragma once

#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "eval/alignment.h"
#include "recording/trajectory.h"

namespace roamlab::eval {

// Summary of errors (non-negative magnitudes, or signed components); all NaN when count is 0.
struct ErrorStatistics {
  std::size_t count = 0;
  double rmse = 0.0;
  double mean = 0.0;
  double median = 0.0;  // of an even count: the mean of the two middle values
  double std = 0.0;     // population standard deviation about the mean
  double min = 0.0;
  double max = 0.0;
};
ErrorStatistics Summarize(const std::vector<double>& errors);

struct AbsoluteTrajectoryError {
  AlignmentKind alignment_kind = AlignmentKind::kNone;
  RigidTransform alignment;                  // T_ref_est
  Trajectory aligned_estimate;               // the estimate mapped into the reference frame
  std::vector<Eigen::Vector3d> error_world;  // aligned p_est - p_ref per pose, reference world frame [m]
  std::vector<double> error_m;               // |error_world| per pose [m]
  std::vector<double> rotation_deg;          // angle of R_ref^T R_aligned_est per pose [deg]
  ErrorStatistics statistics;                // of error_m [m]
  ErrorStatistics rotation;                  // of rotation_deg [deg]
  ErrorStatistics axis[3];                   // of the signed components x, y, z of error_world [m]
  ErrorStatistics horizontal;                // of |(e_x, e_y)| [m]
  ErrorStatistics vertical;                  // of |e_z| [m]
};
// Matched trajectories of the same size (CHECK), aligned on all poses.
AbsoluteTrajectoryError ComputeAte(const Trajectory& estimate, const Trajectory& reference, AlignmentKind kind);
// The same with a given alignment (e.g. one computed on part of the poses).
AbsoluteTrajectoryError ComputeAte(const Trajectory& estimate, const Trajectory& reference, AlignmentKind kind,
                                   const RigidTransform& alignment);

struct RelativePoseError {
  std::vector<std::size_t> first;  // pair (first[n], second[n]) of pose indices
  std::vector<std::size_t> second;
  std::vector<double> translation_m;  // per pair [m]
  std::vector<double> rotation_deg;   // per pair [deg]
  ErrorStatistics translation;        // [m]
  ErrorStatistics rotation;           // [deg]
};
// Pairs k = step poses apart; step >= 1 (CHECK); sizes equal (CHECK).
RelativePoseError RpeByStep(const Trajectory& estimate, const Trajectory& reference, std::size_t step);
// Segments of distance_m metres along the reference; distance_m > 0 (CHECK); sizes equal (CHECK).
RelativePoseError RpeByDistance(const Trajectory& estimate, const Trajectory& reference, double distance_m);

// The step k that spans about `seconds` on this trajectory: round(seconds / median sample period), at least 1.
// 1 for trajectories of fewer than two poses.
std::size_t StepForDuration(const Trajectory& trajectory, double seconds);

// Rotation angle of a unit quaternion in [0, 180] degrees (q and -q give the same angle).
double RotationAngleDeg(const Eigen::Quaterniond& q);

}  // namespace roamlab::eval
