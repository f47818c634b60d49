#include "eval/visual_odometry.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace roamlab::eval {
namespace {

constexpr double kDegPerRad = 180.0 / 3.14159265358979323846;
constexpr double kMovingMps = 0.05;  // below this the speed ratio is noise over noise

Eigen::Matrix3d Exp(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  if (angle < 1e-12) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

Eigen::Vector3d Log(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

// Pose of O at t, interpolated between the two truth poses around it; nullopt outside the truth's span.
std::optional<StampedPose> PoseAt(const Trajectory& truth, Time t) {
  const auto it =
      std::lower_bound(truth.begin(), truth.end(), t, [](const StampedPose& p, Time time) { return p.t < time; });
  if (it == truth.end()) return std::nullopt;
  if (it->t == t) return *it;
  if (it == truth.begin()) return std::nullopt;
  const StampedPose& a = *(it - 1);
  const StampedPose& b = *it;
  const double w = SecondsBetween(a.t, t) / SecondsBetween(a.t, b.t);
  return StampedPose{t, (1.0 - w) * a.p_world_body + w * b.p_world_body, a.q_world_body.slerp(w, b.q_world_body)};
}

double Json(double x) { return std::isfinite(x) ? x : 0.0; }

nlohmann::json StatsJson(const ErrorStatistics& s) {
  return {{"count", s.count},
          {"rmse", Json(s.rmse)},
          {"mean", Json(s.mean)},
          {"median", Json(s.median)},
          {"max", Json(s.max)}};
}

}  // namespace

std::optional<VisualOdometryErrors> CompareVisualOdometry(const recording::Stream& stream, const Trajectory& truth) {
  if (stream.values.cols() < 6 || !stream.info.mounting || !(stream.info.rate_hz > 0.0) || truth.size() < 2)
    return std::nullopt;
  const double T = 1.0 / stream.info.rate_hz;
  const std::int64_t half_ns = std::llround(0.5e9 * T);
  const Eigen::Matrix3d R_oc = stream.info.mounting->q_body_sensor.toRotationMatrix();
  const Eigen::Vector3d p_oc = stream.info.mounting->p_body_sensor;
  const bool with_covariance = stream.values.cols() == 27;

  VisualOdometryErrors out;
  out.pairs =
      static_cast<int>(std::floor(SecondsBetween(truth.front().t, truth.back().t) * stream.info.rate_hz + 1e-9));
  std::vector<double> rotation_deg, speed_ratio;
  for (std::size_t r = 0; r < stream.t.size(); ++r) {
    const auto a = PoseAt(truth, Time::FromNanoseconds(stream.t[r].nanoseconds() - half_ns));
    const auto b = PoseAt(truth, Time::FromNanoseconds(stream.t[r].nanoseconds() + half_ns));
    if (!a || !b) continue;
    const Eigen::Matrix3d R_a = a->q_world_body.toRotationMatrix();
    const Eigen::Matrix3d R_ab = R_a.transpose() * b->q_world_body.toRotationMatrix();
    const Eigen::Matrix3d R_true = R_oc.transpose() * R_ab * R_oc;
    const Eigen::Vector3d p_true = R_oc.transpose() * (R_a.transpose() * (b->p_world_body - a->p_world_body) +
                                                       (R_ab - Eigen::Matrix3d::Identity()) * p_oc);
    const Eigen::Vector3d v = stream.values.block<1, 3>(static_cast<Eigen::Index>(r), 0).transpose();
    const Eigen::Vector3d omega = stream.values.block<1, 3>(static_cast<Eigen::Index>(r), 3).transpose();
    rotation_deg.push_back(Log(Exp(omega * T).transpose() * R_true).norm() * kDegPerRad);
    const double true_speed = p_true.norm() / T;
    if (true_speed > kMovingMps) speed_ratio.push_back(v.norm() / true_speed);
    if (with_covariance) {
      const Eigen::Vector3d omega_true = Log(R_true) / T;
      Eigen::Matrix<double, 6, 1> e;
      e << v - Exp(-0.5 * T * omega_true) * p_true / T, omega - omega_true;
      Eigen::Matrix<double, 6, 6> P;
      int c = 6;
      for (int i = 0; i < 6; ++i)
        for (int j = i; j < 6; ++j) P(i, j) = P(j, i) = stream.values(static_cast<Eigen::Index>(r), c++);
      const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(P);
      if (ldlt.info() == Eigen::Success && ldlt.isPositive()) out.nees.push_back(e.dot(ldlt.solve(e)));
    }
    ++out.rows;
  }
  out.failure_rate = out.pairs > 0 ? std::max(0.0, 1.0 - static_cast<double>(out.rows) / out.pairs) : 0.0;
  out.rotation_deg = Summarize(rotation_deg);
  out.speed_ratio = Summarize(speed_ratio);
  out.nees_statistics = Summarize(out.nees);
  return out;
}

nlohmann::json VisualOdometryJson(const VisualOdometryErrors& errors) {
  return {{"pairs", errors.pairs},
          {"rows", errors.rows},
          {"failure_rate", errors.failure_rate},
          {"rotation_error_deg", StatsJson(errors.rotation_deg)},
          {"speed_ratio", StatsJson(errors.speed_ratio)},
          {"nees", StatsJson(errors.nees_statistics)}};
}

}  // namespace roamlab::eval
