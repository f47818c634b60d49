// Planar poses and displacements for model-free odometry (seed 001, Table I).
//
// A planar pose or displacement is a Vector3d (x [m], y [m], theta [rad]). The seed's roto-translation operator and its
// inverse (Table I):
//
//   a (+) b = [a_x + b_x cos a_th - b_y sin a_th,  a_y + b_x sin a_th + b_y cos a_th,  a_th + b_th]
//   (-) a   = [-a_x cos a_th - a_y sin a_th,  a_x sin a_th - a_y cos a_th,  -a_th]
//
// so that the displacement from pose q_j to pose q_k, expressed in the frame of q_j, is q_jk = (-)q_j (+) q_k
// (Section II). Angles are not wrapped by Compose (a trajectory's heading keeps counting turns); Between wraps its
// heading into (-pi, pi] because a displacement over a short interval is a small rotation.
#pragma once

#include <cmath>

#include <Eigen/Core>

namespace roamlab::estimator::odometry {

using Pose2 = Eigen::Vector3d;

// Angle in (-pi, pi].
inline double WrapAngle(double angle_rad) { return std::atan2(std::sin(angle_rad), std::cos(angle_rad)); }

// a (+) b (Table I).
inline Pose2 Compose(const Pose2& a, const Pose2& b) {
  const double c = std::cos(a[2]);
  const double s = std::sin(a[2]);
  return Pose2(a[0] + b[0] * c - b[1] * s, a[1] + b[0] * s + b[1] * c, a[2] + b[2]);
}

// (-) a (Table I): Compose(Inverse(a), a) = 0.
inline Pose2 Inverse(const Pose2& a) {
  const double c = std::cos(a[2]);
  const double s = std::sin(a[2]);
  return Pose2(-a[0] * c - a[1] * s, a[0] * s - a[1] * c, -a[2]);
}

// (-) a (+) b with the heading wrapped into (-pi, pi]: the displacement from a to b in a's frame.
inline Pose2 Between(const Pose2& a, const Pose2& b) {
  Pose2 d = Compose(Inverse(a), b);
  d[2] = WrapAngle(d[2]);
  return d;
}

}  // namespace roamlab::estimator::odometry
