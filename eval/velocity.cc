#include "eval/velocity.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include <Eigen/Geometry>

#include "recording/wheel_kinematics.h"

namespace roamlab::eval {
namespace {

// Rotation vector (full angle) of a unit quaternion.
Eigen::Vector3d Log(const Eigen::Quaterniond& q_in) {
  const Eigen::Quaterniond q = q_in.w() < 0.0 ? Eigen::Quaterniond(-q_in.coeffs()) : q_in;
  const Eigen::AngleAxisd aa(q);
  return aa.angle() * aa.axis();
}

StampedTwist Between(const StampedPose& a, const StampedPose& b) {
  StampedTwist s;
  s.t_begin = a.t;
  s.t_end = b.t;
  const double dt = SecondsBetween(a.t, b.t);
  const Eigen::Vector3d phi = Log(a.q_world_body.conjugate() * b.q_world_body);
  s.omega_body = phi / dt;
  const double angle = phi.norm();
  const Eigen::Quaterniond half =
      angle > 0.0 ? Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * angle, phi / angle)) : Eigen::Quaterniond::Identity();
  s.v_body = (a.q_world_body * half).conjugate() * ((b.p_world_body - a.p_world_body) / dt);
  return s;
}

// Index of the pose nearest to t within tolerance, or -1.
long Nearest(const Trajectory& trajectory, Time t, double tolerance_s) {
  const auto it = std::lower_bound(trajectory.begin(), trajectory.end(), t,
                                   [](const StampedPose& p, Time time) { return p.t < time; });
  long best = -1;
  double best_dt = tolerance_s;
  for (auto candidate : {it, it == trajectory.begin() ? it : it - 1}) {
    if (candidate == trajectory.end()) continue;
    const double dt = std::abs(SecondsBetween(candidate->t, t));
    if (dt <= best_dt) {
      best_dt = dt;
      best = static_cast<long>(candidate - trajectory.begin());
    }
  }
  return best;
}

}  // namespace

std::vector<StampedTwist> TrajectoryVelocities(const Trajectory& trajectory) {
  std::vector<StampedTwist> out;
  for (std::size_t i = 0; i + 1 < trajectory.size(); ++i) out.push_back(Between(trajectory[i], trajectory[i + 1]));
  return out;
}

Result<EncoderOdometry> EncoderOnlyOdometry(const recording::Recording& rec) {
  // The last stream of cumulative angles whose columns the platform's kinematics reads (rows in column order).
  const recording::Stream* encoders = nullptr;
  Result<recording::WheelKinematics> kinematics = Status::Error("no wheel_encoders stream of cumulative angles");
  for (const recording::Stream& s : rec.streams) {
    if (s.info.type != recording::StreamType::kWheelEncoders || s.info.units != "rad") continue;
    Result<recording::WheelKinematics> k = recording::NominalWheelKinematics(rec.platform, s.info.columns);
    if (k.ok() && s.values.cols() == k.value().wheels()) {
      encoders = &s;
      kinematics = std::move(k);
    } else if (encoders == nullptr) {
      kinematics = k.ok() ? Status::Error("no wheel_encoders stream of cumulative angles with one column per wheel")
                          : k.status();
    }
  }
  if (encoders == nullptr) return kinematics.status();
  EncoderOdometry out;
  StampedPose pose{encoders->t.empty() ? Time() : encoders->t.front(), Eigen::Vector3d::Zero(),
                   Eigen::Quaterniond::Identity()};
  out.dead_reckoning.push_back(pose);
  for (std::size_t k = 0; k + 1 < encoders->t.size(); ++k) {
    const double dt = SecondsBetween(encoders->t[k], encoders->t[k + 1]);
    const Eigen::VectorXd rates =
        (encoders->values.row(static_cast<Eigen::Index>(k) + 1) - encoders->values.row(static_cast<Eigen::Index>(k)))
            .transpose() /
        dt;
    const Eigen::Vector3d twist = kinematics.value().TwistFromRates(rates);
    StampedTwist s;
    s.t_begin = encoders->t[k];
    s.t_end = encoders->t[k + 1];
    s.v_body = Eigen::Vector3d(twist[0], twist[1], 0.0);
    s.omega_body = Eigen::Vector3d(0.0, 0.0, twist[2]);
    out.twists.push_back(s);
    // Eq. 7: rotate half-way, translate, rotate the rest.
    const Eigen::Quaterniond half(Eigen::AngleAxisd(0.5 * twist[2] * dt, Eigen::Vector3d::UnitZ()));
    const Eigen::Quaterniond q_mid = pose.q_world_body * half;
    pose.p_world_body += q_mid * (s.v_body * dt);
    pose.q_world_body = (q_mid * half).normalized();
    pose.t = encoders->t[k + 1];
    out.dead_reckoning.push_back(pose);
  }
  return out;
}

VelocityErrors CompareVelocities(const std::vector<StampedTwist>& estimate, const Trajectory& truth,
                                 double tolerance_s) {
  VelocityErrors out;
  std::vector<double> linear, angular;
  if (truth.empty()) return out;
  for (const StampedTwist& e : estimate) {
    const long a = Nearest(truth, e.t_begin, tolerance_s);
    const long b = Nearest(truth, e.t_end, tolerance_s);
    if (a < 0 || b <= a) continue;
    const StampedTwist t = Between(truth[static_cast<std::size_t>(a)], truth[static_cast<std::size_t>(b)]);
    out.t_s.push_back(SecondsBetween(truth.front().t, e.t_begin) + 0.5 * SecondsBetween(e.t_begin, e.t_end));
    out.estimate.push_back(e);
    out.truth.push_back(t);
    linear.push_back((e.v_body.head<2>() - t.v_body.head<2>()).norm());
    angular.push_back(std::abs(e.omega_body.z() - t.omega_body.z()));
  }
  out.linear_mps = Summarize(linear);
  out.angular_radps = Summarize(angular);
  return out;
}

nlohmann::json VelocityJson(const VelocityErrors& errors, double rpe_rot_deg) {
  const auto number = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(); };
  return {{"linear_rmse", number(errors.linear_mps.rmse)},
          {"angular_rmse", number(errors.angular_radps.rmse)},
          {"rpe_rot_deg", number(rpe_rot_deg)},
          {"intervals", errors.linear_mps.count}};
}

}  // namespace roamlab::eval
