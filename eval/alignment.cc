#include "eval/alignment.h"

#include <cmath>

#include <Eigen/SVD>

#include "common/check.h"

namespace roamlab::eval {
namespace {

Eigen::Vector3d Mean(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) sum += p;
  return points.empty() ? sum : Eigen::Vector3d(sum / static_cast<double>(points.size()));
}

std::vector<Eigen::Vector3d> Positions(const Trajectory& trajectory) {
  std::vector<Eigen::Vector3d> p;
  p.reserve(trajectory.size());
  for (const StampedPose& pose : trajectory) p.push_back(pose.p_world_body);
  return p;
}

}  // namespace

const char* AlignmentKindName(AlignmentKind kind) {
  switch (kind) {
    case AlignmentKind::kNone:
      return "none";
    case AlignmentKind::kSe3:
      return "se3";
    case AlignmentKind::kYawTranslation:
      return "yaw_translation";
    case AlignmentKind::kSim3:
      return "sim3";
    case AlignmentKind::kOrigin:
      return "origin";
  }
  return "none";
}

std::optional<AlignmentKind> ParseAlignmentKind(const std::string& name) {
  if (name == "yaw") return AlignmentKind::kYawTranslation;
  for (AlignmentKind kind : {AlignmentKind::kNone, AlignmentKind::kSe3, AlignmentKind::kYawTranslation,
                             AlignmentKind::kSim3, AlignmentKind::kOrigin})
    if (name == AlignmentKindName(kind)) return kind;
  return std::nullopt;
}

StampedPose RigidTransform::Apply(const StampedPose& pose_est) const {
  StampedPose pose;
  pose.t = pose_est.t;
  pose.p_world_body = Apply(pose_est.p_world_body);
  pose.q_world_body = (q_ref_est * pose_est.q_world_body).normalized();
  return pose;
}

RigidTransform AlignPositions(const std::vector<Eigen::Vector3d>& p_est, const std::vector<Eigen::Vector3d>& p_ref,
                              AlignmentKind kind) {
  ROAMLAB_CHECK(p_est.size() == p_ref.size(),
                "alignment needs matched points: " << p_est.size() << " estimate vs " << p_ref.size() << " reference");
  RigidTransform transform;
  if (kind == AlignmentKind::kNone || p_est.empty()) return transform;
  if (kind == AlignmentKind::kOrigin) {
    transform.p_ref_est = p_ref.front() - p_est.front();
    return transform;
  }
  const Eigen::Vector3d mean_est = Mean(p_est);
  const Eigen::Vector3d mean_ref = Mean(p_ref);

  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  if (kind == AlignmentKind::kSe3 || kind == AlignmentKind::kSim3) {
    // Cross-covariance of the centred points and its SVD; the sign fix keeps a proper rotation.
    Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
    double spread_est = 0.0;  // sum |a_i|^2
    for (std::size_t i = 0; i < p_est.size(); ++i) {
      h += (p_ref[i] - mean_ref) * (p_est[i] - mean_est).transpose();
      spread_est += (p_est[i] - mean_est).squaredNorm();
    }
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d s = Eigen::Matrix3d::Identity();
    if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0) s(2, 2) = -1.0;
    rotation = svd.matrixU() * s * svd.matrixV().transpose();
    if (kind == AlignmentKind::kSim3 && spread_est > 0.0)
      transform.scale = (svd.singularValues().asDiagonal() * s).trace() / spread_est;
  } else {
    // Yaw maximizing sum b^T Rz(yaw) a: the horizontal dot and cross sums of the centred points.
    double dot = 0.0;
    double cross = 0.0;
    for (std::size_t i = 0; i < p_est.size(); ++i) {
      const Eigen::Vector3d a = p_est[i] - mean_est;
      const Eigen::Vector3d b = p_ref[i] - mean_ref;
      dot += a.x() * b.x() + a.y() * b.y();
      cross += a.x() * b.y() - a.y() * b.x();
    }
    rotation = Eigen::AngleAxisd(std::atan2(cross, dot), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  }
  transform.q_ref_est = Eigen::Quaterniond(rotation).normalized();
  transform.p_ref_est = mean_ref - transform.scale * (rotation * mean_est);
  return transform;
}

RigidTransform AlignTrajectories(const Trajectory& estimate, const Trajectory& reference, AlignmentKind kind) {
  ROAMLAB_CHECK(estimate.size() == reference.size(), "alignment needs matched trajectories");
  if (kind == AlignmentKind::kOrigin && !estimate.empty()) {
    RigidTransform transform;
    transform.q_ref_est = (reference.front().q_world_body * estimate.front().q_world_body.conjugate()).normalized();
    transform.p_ref_est = reference.front().p_world_body - transform.q_ref_est * estimate.front().p_world_body;
    return transform;
  }
  return AlignPositions(Positions(estimate), Positions(reference), kind);
}

Trajectory TransformTrajectory(const RigidTransform& transform, const Trajectory& trajectory) {
  Trajectory out;
  out.reserve(trajectory.size());
  for (const StampedPose& pose : trajectory) out.push_back(transform.Apply(pose));
  return out;
}

}  // namespace roamlab::eval
