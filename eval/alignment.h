// Explicit alignment of an estimated trajectory to a reference before comparing absolute positions.
//
// An estimate may live in its own world frame W_est (without an absolute sensor the seed fixes W at the first pose,
// Section III-A). Alignment finds the rigid transform T_ref_est (W_est -> W_ref) that minimizes
//     sum_i |p_ref_i - (R p_est_i + t)|^2
// over matched positions, in closed form:
//   kNone            identity.
//   kSe3             rotation and translation, no scale: Horn / Umeyama (1991) with scale fixed to 1. With the
//                    centred points a_i = p_est_i - mean(p_est), b_i = p_ref_i - mean(p_ref) and the SVD
//                    sum b_i a_i^T = U D V^T:  R = U diag(1, 1, det(U V^T)) V^T,  t = mean(p_ref) - R mean(p_est).
//   kYawTranslation  rotation about the world z axis only, plus a 3-D translation (4 DoF: what remains unobservable
//                    when gravity fixes roll and pitch):  yaw = atan2(sum a_x b_y - a_y b_x, sum a_x b_x + a_y b_y),
//                    t = mean(p_ref) - Rz(yaw) mean(p_est).
//   kSim3            kSe3 with a scale s (Umeyama 1991): minimizes sum |p_ref_i - (s R p_est_i + t)|^2;
//                    s = trace(D S) / sum |a_i|^2 with S = diag(1, 1, det(U V^T)), t = mean(p_ref) - s R mean(p_est).
//                    For monocular or otherwise scale-free estimates.
//   kOrigin          the first poses made equal: R = R_ref_0 R_est_0^T, t = p_ref_0 - R p_est_0 (orientations are used;
//                    AlignPositions, which has none, makes the first positions equal with R = I).
// Degenerate inputs (fewer than three non-collinear points for kSe3/kSim3, no horizontal spread for kYawTranslation)
// return one of the minimizers; no points give the identity (and scale 1 when the estimate's points do not spread).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "recording/trajectory.h"

namespace roamlab::eval {

enum class AlignmentKind { kNone, kSe3, kYawTranslation, kSim3, kOrigin };

// "none", "se3", "yaw_translation", "sim3", "origin"; ParseAlignmentKind is the inverse and also accepts "yaw" for
// kYawTranslation (nullopt for anything else).
const char* AlignmentKindName(AlignmentKind kind);
std::optional<AlignmentKind> ParseAlignmentKind(const std::string& name);

// T_ref_est: maps coordinates in the estimate's world frame into the reference's world frame (a similarity when
// scale != 1, which only kSim3 produces).
struct RigidTransform {
  Eigen::Quaterniond q_ref_est = Eigen::Quaterniond::Identity();
  Eigen::Vector3d p_ref_est = Eigen::Vector3d::Zero();  // [m]
  double scale = 1.0;                                   // reference metres per estimate unit

  Eigen::Vector3d Apply(const Eigen::Vector3d& p_est) const { return scale * (q_ref_est * p_est) + p_ref_est; }
  // The pose of the body in the reference frame: (s R p + t, R q). Keeps the stamp.
  StampedPose Apply(const StampedPose& pose_est) const;
};

// Closed-form alignment of matched positions (same size, CHECK) [m].
RigidTransform AlignPositions(const std::vector<Eigen::Vector3d>& p_est, const std::vector<Eigen::Vector3d>& p_ref,
                              AlignmentKind kind);

// Same on two matched trajectories (same size, CHECK); orientations are used by kOrigin only.
RigidTransform AlignTrajectories(const Trajectory& estimate, const Trajectory& reference, AlignmentKind kind);

// Every pose of `trajectory` mapped through `transform`.
Trajectory TransformTrajectory(const RigidTransform& transform, const Trajectory& trajectory);

}  // namespace roamlab::eval
