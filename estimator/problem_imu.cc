// The IMU master of ProblemBuilder (problem.h, "IMU master"): the pose grid, the gyroscope's integration for the
// initial orientations, the gravity- and field-aligned start and the placement on the GPS fixes.
#include <algorithm>
#include <cmath>

#include "estimator/factor.h"
#include "estimator/geometry.h"
#include "estimator/internal/problem_impl.h"
#include "estimator/models/prior.h"

namespace roamlab::estimator {

namespace {

// The span of samples that the start's orientation averages [s].
constexpr double kAlignmentSpan = 1.0;
// Variance of a prior component that carries no information [rad^2].
constexpr double kNoInformationVariance = 1e6;
// Variance of the first pose's yaw prior (the gauge) without a magnetometer or an absolute sensor [rad^2].
constexpr double kGaugeVariance = 1e-12;
// GPS track headings: fixes at least this far apart [m] and at most this long apart [s].
constexpr double kTrackMinDistance = 3.0;
constexpr double kTrackMaxSeconds = 10.0;

// Mean of a stream's three columns from `column` over [t0, t0 + kAlignmentSpan] (the first row when none is there).
Eigen::Vector3d MeanOverStart(const recording::Stream& s, int column, Time t0) {
  const auto first = std::lower_bound(s.t.begin(), s.t.end(), t0);
  std::size_t i = first == s.t.end() ? s.t.size() - 1 : static_cast<std::size_t>(first - s.t.begin());
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int n = 0;
  for (; i < s.t.size() && (n == 0 || SecondsBetween(t0, s.t[i]) <= kAlignmentSpan); ++i, ++n)
    sum += s.values.row(static_cast<Eigen::Index>(i)).segment<3>(column).transpose();
  return sum / std::max(n, 1);
}

Eigen::Quaterniond QuaternionOf(const Eigen::VectorXd& v) { return Eigen::Quaterniond(v[0], v[1], v[2], v[3]); }

double YawOf(const Eigen::Quaterniond& q) {
  const Eigen::Vector3d x = q * Eigen::Vector3d::UnitX();
  return std::atan2(x.y(), x.x());
}

}  // namespace

Eigen::Vector3d ProblemBuilder::ImuBodyRate(const MeasurementRef& m) const {
  const StreamBinding& s = impl_->streams[m.stream];
  const auto value = [&](std::size_t slot) {
    const std::string& name = s.slot_parameters[slot];
    return poses_.empty() ? impl_->parameter_initial.at(name)
                          : graph_.variable(ParameterAt(name, poses_.size() - 1)).value;
  };
  const Eigen::Vector3d z = s.primary->values.row(m.row).segment<3>(s.column).transpose();
  const Eigen::VectorXd bias = value(1), scale = value(2);
  return QuaternionOf(value(0)).normalized() * (z - bias).cwiseQuotient(scale);
}

// The start's orientation: the body's up from the accelerometer's mean (its reading at rest is the up axis), the yaw
// from the magnetometer's mean field against field_world (through its A, b and misalignment at their initial values).
Eigen::Quaterniond ProblemBuilder::InitialImuOrientation(Time t0) const {
  const Impl& im = *impl_;
  const auto initial = [&](const StreamBinding& s, std::size_t slot) {
    return im.parameter_initial.at(s.slot_parameters[slot]);
  };
  const StreamBinding& a = im.streams[static_cast<std::size_t>(im.imu->accelerometer)];
  const Eigen::Vector3d f_sensor =
      (MeanOverStart(*a.primary, a.column, t0) - initial(a, 2).head<3>()).cwiseQuotient(initial(a, 3).head<3>());
  const Eigen::Vector3d f_body = QuaternionOf(initial(a, 0)).normalized() * f_sensor;
  Eigen::Quaterniond q = f_body.norm() > 0.0 ? Eigen::Quaterniond::FromTwoVectors(f_body, Eigen::Vector3d::UnitZ())
                                             : Eigen::Quaterniond::Identity();
  if (im.imu->magnetometer >= 0) {
    const StreamBinding& m = im.streams[static_cast<std::size_t>(im.imu->magnetometer)];
    const Eigen::Matrix3d A = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(initial(m, 1).data());
    const Eigen::Vector3d h_sensor =
        A.fullPivLu().solve(MeanOverStart(*m.primary, m.column, t0) - initial(m, 2).head<3>());
    const Eigen::Vector3d h_world = q * (QuaternionOf(initial(m, 0)).normalized() * h_sensor);
    if (h_world.head<2>().norm() > 0.0 && m.field_world.head<2>().norm() > 0.0) {
      const double yaw = std::atan2(m.field_world.y(), m.field_world.x()) - std::atan2(h_world.y(), h_world.x());
      q = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * q;
    }
  }
  return q.normalized();
}

void ProblemBuilder::CreateImuPose(Time t) {
  Impl& im = *impl_;
  const Pose<double> last = PoseFromArray(graph_.variable(poses_.back().id).value.data());
  Pose<double> next{last.p_world_body, (last.q_world_body * im.imu->delta).normalized()};
  if (poses_.size() >= 2) {
    const Pose<double> before = PoseFromArray(graph_.variable(poses_[poses_.size() - 2].id).value.data());
    const double dt_before = SecondsBetween(poses_[poses_.size() - 2].t, poses_.back().t);
    next.p_world_body += (last.p_world_body - before.p_world_body) * (SecondsBetween(poses_.back().t, t) / dt_before);
  }
  Eigen::VectorXd value(7);
  PoseToArray(next, value.data());
  const VariableId id = CreatePose(t, value);
  im.imu->delta = Eigen::Quaterniond::Identity();
  if (!has_absolute_sensor_) {
    // The handheld's weak position prior about the origin; the orientation components carry no information.
    const double s2 = im.config.poses.position_sigma_m * im.config.poses.position_sigma_m;
    Eigen::VectorXd x0 = value;
    x0.head<3>().setZero();
    Eigen::VectorXd variance(6);
    variance << s2, s2, s2, kNoInformationVariance, kNoInformationVariance, kNoInformationVariance;
    graph_.AddFactor(MakeFactor(PriorError<PoseBlock>(x0)), {id}, Eigen::MatrixXd(variance.asDiagonal()),
                     Loss::Trivial(), "prior", t);
  }
}

bool ProblemBuilder::AddImuMasterSample(const MeasurementRef& m) {
  Impl& im = *impl_;
  ImuMasterState& st = *im.imu;
  if (poses_.empty()) {
    st.first_t = m.t;
    st.cursor = m.t;
    Eigen::VectorXd value(7);
    PoseToArray(Pose<double>{Eigen::Vector3d::Zero(), InitialImuOrientation(m.t)}, value.data());
    const VariableId id = CreatePose(m.t, value);
    if (!has_absolute_sensor_) {
      // The position prior as on every pose; without a magnetometer the yaw (about the body's z) is the gauge.
      const double s2 = im.config.poses.position_sigma_m * im.config.poses.position_sigma_m;
      Eigen::VectorXd variance(6);
      variance << s2, s2, s2, kNoInformationVariance, kNoInformationVariance,
          st.magnetometer >= 0 ? kNoInformationVariance : kGaugeVariance;
      graph_.AddFactor(MakeFactor(PriorError<PoseBlock>(value)), {id}, Eigen::MatrixXd(variance.asDiagonal()),
                       Loss::Trivial(), "prior", m.t);
    }
    st.omega_body = ImuBodyRate(m);
    return true;
  }
  if (m.t <= st.cursor) {
    ++counts_[im.streams[m.stream].name].too_late;
    return false;
  }
  // Hold the last sample's rate up to this one, creating the grid poses passed on the way.
  const double rate_hz = im.config.poses.rate_hz;
  const auto advance = [&](Time to) {
    st.delta = (st.delta * QuaternionExp<double>(st.omega_body * SecondsBetween(st.cursor, to))).normalized();
    st.cursor = to;
  };
  if (rate_hz > 0.0) {
    for (;;) {
      const Time grid = Time::FromNanoseconds(st.first_t.nanoseconds() +
                                              std::llround(1e9 * static_cast<double>(st.next_index) / rate_hz));
      if (grid > m.t) break;
      advance(grid);
      CreateImuPose(grid);
      ++st.next_index;
    }
    advance(m.t);
  } else {
    advance(m.t);
    CreateImuPose(m.t);
  }
  st.omega_body = ImuBodyRate(m);
  return true;
}

// With GPS fixes: without a magnetometer, the yaw turned so that the body's x axis follows the GPS track (the
// displacement-weighted circular mean of the heading differences over fixes kTrackMinDistance apart); then every
// position at the fixes interpolated linearly in time (the first or last fix beyond them).
void ProblemBuilder::AlignImuMasterToFixes() {
  if (absolute_fixes_.size() < 2) return;
  std::vector<std::pair<Time, Eigen::Vector3d>> fixes;
  for (const auto& [id, z] : absolute_fixes_) fixes.emplace_back(*graph_.variable(id).stamp, z);
  std::stable_sort(fixes.begin(), fixes.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  if (impl_->imu->magnetometer < 0) {
    double sin_sum = 0.0, cos_sum = 0.0;
    for (std::size_t i = 0, j = 1; i < fixes.size(); ++i) {
      j = std::max(j, i + 1);
      while (j < fixes.size() && (fixes[j].second - fixes[i].second).head<2>().norm() < kTrackMinDistance) ++j;
      if (j >= fixes.size()) break;
      if (SecondsBetween(fixes[i].first, fixes[j].first) > kTrackMaxSeconds) continue;
      const Eigen::Vector2d d = (fixes[j].second - fixes[i].second).head<2>();
      const Time middle = Time::FromNanoseconds((fixes[i].first.nanoseconds() + fixes[j].first.nanoseconds()) / 2);
      const Pose<double> pose = PoseFromArray(graph_.variable(poses_[NearestPose(middle)].id).value.data());
      const double difference = std::atan2(d.y(), d.x()) - YawOf(pose.q_world_body);
      sin_sum += d.norm() * std::sin(difference);
      cos_sum += d.norm() * std::cos(difference);
    }
    if (std::hypot(sin_sum, cos_sum) > 0.0) {
      const Eigen::Quaterniond q_yaw(Eigen::AngleAxisd(std::atan2(sin_sum, cos_sum), Eigen::Vector3d::UnitZ()));
      for (const PoseNode& node : poses_) {
        Eigen::VectorXd& x = graph_.mutable_variable(node.id).value;
        QuaternionToArray(Eigen::Quaterniond(q_yaw * QuaternionFromArray(x.data() + 3)).normalized(), x.data() + 3);
      }
    }
  }
  for (const PoseNode& node : poses_) {
    const auto after =
        std::lower_bound(fixes.begin(), fixes.end(), node.t, [](const auto& fix, Time t) { return fix.first < t; });
    Eigen::Vector3d p;
    if (after == fixes.begin()) {
      p = fixes.front().second;
    } else if (after == fixes.end()) {
      p = fixes.back().second;
    } else {
      const auto before = std::prev(after);
      const double span = SecondsBetween(before->first, after->first);
      const double w = span > 0.0 ? SecondsBetween(before->first, node.t) / span : 1.0;
      p = (1.0 - w) * before->second + w * after->second;
    }
    graph_.mutable_variable(node.id).value.head<3>() = p;
  }
}

}  // namespace roamlab::estimator
