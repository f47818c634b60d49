#include "estimator/odometry/training_data.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <Eigen/Geometry>

namespace roamlab::estimator::odometry {
namespace {

using recording::Stream;
using recording::StreamType;

// The stream named `name`, or the only stream of `type` when `name` is empty.
Result<const Stream*> PickStream(const recording::Recording& rec, const std::string& rec_name, StreamType type,
                                 const std::string& name) {
  const char* type_name = recording::StreamTypeName(type);
  if (!name.empty()) {
    const Stream* stream = rec.Find(name);
    if (stream == nullptr) return Status::Error(rec_name + ": no stream '" + name + "'");
    if (stream->info.type != type) {
      return Status::Error(rec_name + ": stream '" + name + "' is not of type " + type_name);
    }
    return stream;
  }
  const Stream* found = nullptr;
  for (const Stream& stream : rec.streams) {
    if (stream.info.type != type) continue;
    if (found != nullptr) {
      return Status::Error(rec_name + ": several " + type_name + " streams ('" + found->info.name + "', '" +
                           stream.info.name + "'); name one");
    }
    found = &stream;
  }
  if (found == nullptr) return Status::Error(rec_name + ": no " + type_name + " stream");
  return found;
}

// Index i with t[i] <= q < t[i+1] (clamped to [0, size-2]) and the fraction of q between them.
std::pair<std::size_t, double> Bracket(const std::vector<Time>& t, Time q) {
  const auto it = std::upper_bound(t.begin(), t.end(), q);
  std::size_t i = it == t.begin() ? 0 : static_cast<std::size_t>(it - t.begin()) - 1;
  i = std::min(i, t.size() - 2);
  const double w = SecondsBetween(t[i], q) / SecondsBetween(t[i], t[i + 1]);
  return {i, w};
}

// Planar pose (x, y, yaw) of a pose-stream row: x y z qx qy qz qw.
Pose2 PlanarPose(const Eigen::MatrixXd& values, Eigen::Index row) {
  const double qx = values(row, 3), qy = values(row, 4), qz = values(row, 5), qw = values(row, 6);
  const double yaw = std::atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz));
  return Pose2(values(row, 0), values(row, 1), yaw);
}

// Jacobians of c = a (+) b (Table I) with respect to a and b.
Eigen::Matrix3d JacobianComposeA(const Pose2& a, const Pose2& b) {
  const double c = std::cos(a[2]);
  const double s = std::sin(a[2]);
  Eigen::Matrix3d J = Eigen::Matrix3d::Identity();
  J(0, 2) = -b[0] * s - b[1] * c;
  J(1, 2) = b[0] * c - b[1] * s;
  return J;
}

Eigen::Matrix3d JacobianComposeB(const Pose2& a) {
  const double c = std::cos(a[2]);
  const double s = std::sin(a[2]);
  Eigen::Matrix3d J = Eigen::Matrix3d::Identity();
  J.topLeftCorner<2, 2>() << c, -s, s, c;
  return J;
}

// The sensor's planar mounting l = (x, y, yaw) in O; zero when the stream has none.
Pose2 PlanarMounting(const Stream& stream) {
  if (!stream.info.mounting) return Pose2::Zero();
  const Eigen::Vector3d& p = stream.info.mounting->p_body_sensor;
  const Eigen::Quaterniond& q = stream.info.mounting->q_body_sensor;
  const double yaw = std::atan2(2.0 * (q.w() * q.z() + q.x() * q.y()), 1.0 - 2.0 * (q.y() * q.y() + q.z() * q.z()));
  return Pose2(p.x(), p.y(), yaw);
}

// The sensor stream: named, else the only pose stream, else the only scan_matching stream.
Result<const Stream*> PickSensor(const recording::Recording& rec, const std::string& rec_name,
                                 const std::string& name) {
  if (!name.empty()) {
    const Stream* stream = rec.Find(name);
    if (stream == nullptr) return Status::Error(rec_name + ": no stream '" + name + "'");
    if (stream->info.type != StreamType::kPose && stream->info.type != StreamType::kScanMatching) {
      return Status::Error(rec_name + ": stream '" + name + "' is not of type pose or scan_matching");
    }
    return stream;
  }
  bool has_pose = false;
  for (const Stream& stream : rec.streams) has_pose = has_pose || stream.info.type == StreamType::kPose;
  bool has_scans = false;
  for (const Stream& stream : rec.streams) has_scans = has_scans || stream.info.type == StreamType::kScanMatching;
  if (!has_pose && has_scans) return PickStream(rec, rec_name, StreamType::kScanMatching, "");
  return PickStream(rec, rec_name, StreamType::kPose, "");
}

// Steps of a pose stream between the key times: interpolated poses, s_jk = (-)s_j (+) s_k.
Status PoseSteps(const Stream& sensor, const std::string& rec_name, KeySequence* seq) {
  Eigen::Vector2d sigma(kDefaultPositionSigma_m, kDefaultOrientationSigma_rad);
  const auto& noise = sensor.info.noise;
  if (auto it = noise.find("position_m"); it != noise.end()) sigma[0] = it->second;
  if (auto it = noise.find("orientation_rad"); it != noise.end()) sigma[1] = it->second;
  if (!(sigma.array() > 0.0).all()) {
    return Status::Error(rec_name + ": stream '" + sensor.info.name +
                         "' needs positive position_m and "
                         "orientation_rad noise");
  }
  std::vector<Pose2> poses;
  for (int k = 0; k < seq->size(); ++k) {
    const auto [i, w] = Bracket(sensor.t, seq->t[k]);
    const Pose2 a = PlanarPose(sensor.values, static_cast<Eigen::Index>(i));
    const Pose2 b = PlanarPose(sensor.values, static_cast<Eigen::Index>(i) + 1);
    Pose2 p = (1.0 - w) * a + w * b;
    p[2] = a[2] + w * WrapAngle(b[2] - a[2]);
    poses.push_back(p);
  }
  const Eigen::Vector3d variance(2.0 * sigma[0] * sigma[0], 2.0 * sigma[0] * sigma[0], 2.0 * sigma[1] * sigma[1]);
  for (int k = 1; k < seq->size(); ++k) {
    seq->sensor_step.push_back(Between(poses[k - 1], poses[k]));
    seq->sensor_step_sigma.row(k - 1) = variance.cwiseSqrt().transpose();
    seq->step_valid.push_back(true);
  }
  return Status::Ok();
}

// Steps of an interval stream: the rows' displacements composed over each key interval, with first-order covariance.
Status IntervalSteps(const Stream& sensor, const std::string& rec_name, KeySequence* seq) {
  const auto& noise = sensor.info.noise;
  const auto sv = noise.find("sigma_mps");
  const auto sw = noise.find("sigma_radps");
  if (sv == noise.end() || sw == noise.end() || !(sv->second > 0.0) || !(sw->second > 0.0)) {
    return Status::Error(rec_name + ": stream '" + sensor.info.name +
                         "' needs positive sigma_mps and sigma_radps "
                         "noise");
  }
  if (!(sensor.info.rate_hz > 0.0)) return Status::Error(rec_name + ": stream '" + sensor.info.name + "' has no rate");
  const std::int64_t period_ns = std::llround(1e9 / sensor.info.rate_hz);
  const double dt = static_cast<double>(period_ns) * 1e-9;
  const Eigen::Vector3d row_variance =
      Eigen::Vector3d(sv->second * dt, sv->second * dt, sw->second * dt).array().square();
  constexpr std::int64_t kToleranceNs = 1000;
  std::size_t row = 0;
  int covered = 0;
  for (int k = 1; k < seq->size(); ++k) {
    const std::int64_t begin = seq->t[k - 1].nanoseconds();
    const std::int64_t end = seq->t[k].nanoseconds();
    // Rows starting before the interval are skipped; then rows must follow each other without a gap to its end.
    while (row < sensor.t.size() && sensor.t[row].nanoseconds() - period_ns / 2 < begin - kToleranceNs) ++row;
    Pose2 step = Pose2::Zero();
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    std::int64_t reached = begin;
    const auto row_start = [&](std::size_t i) { return sensor.t[i].nanoseconds() - period_ns / 2; };
    while (row < sensor.t.size() && std::abs(row_start(row) - reached) <= kToleranceNs &&
           reached + period_ns <= end + kToleranceNs) {
      const auto r = static_cast<Eigen::Index>(row);
      const double theta = sensor.values(r, 5) * dt;
      const Eigen::Vector2d v(sensor.values(r, 0), sensor.values(r, 1));
      Pose2 d;
      d << Eigen::Rotation2Dd(0.5 * theta) * v * dt, theta;
      const Eigen::Matrix3d Ja = JacobianComposeA(step, d);
      const Eigen::Matrix3d Jb = JacobianComposeB(step);
      covariance = Ja * covariance * Ja.transpose() + Jb * row_variance.asDiagonal() * Jb.transpose();
      step = Compose(step, d);
      reached += period_ns;
      ++row;
    }
    const bool ok = std::abs(reached - end) <= kToleranceNs;
    covered += ok ? 1 : 0;
    step[2] = WrapAngle(step[2]);
    seq->sensor_step.push_back(step);
    seq->sensor_step_sigma.row(k - 1) = covariance.diagonal().cwiseMax(0.0).cwiseSqrt().transpose();
    seq->step_valid.push_back(ok);
  }
  if (covered == 0) {
    return Status::Error(rec_name + ": no key interval is tiled by whole rows of stream '" + sensor.info.name +
                         "' (choose an interval that is a multiple of 1 / rate_hz)");
  }
  return Status::Ok();
}

// Carries every step from the sensor frame to O: q = l (+) s (+) (-)l, Sigma_q = J Sigma_s J^T.
void MountSteps(const Pose2& l, KeySequence* seq) {
  if (l.isZero()) return;
  const Pose2 l_inverse = Inverse(l);
  for (std::size_t k = 0; k < seq->sensor_step.size(); ++k) {
    const Pose2& s = seq->sensor_step[k];
    const Pose2 right = Compose(s, l_inverse);
    const Eigen::Matrix3d J = JacobianComposeB(l) * JacobianComposeA(s, l_inverse);
    const Eigen::Vector3d sigma = seq->sensor_step_sigma.row(static_cast<Eigen::Index>(k)).transpose();
    const Eigen::Matrix3d covariance = J * sigma.cwiseAbs2().asDiagonal() * J.transpose();
    Pose2 q = Compose(l, right);
    q[2] = WrapAngle(q[2]);
    seq->sensor_step[k] = q;
    seq->sensor_step_sigma.row(static_cast<Eigen::Index>(k)) = covariance.diagonal().cwiseSqrt().transpose();
  }
}

// A tricycle's inputs as cumulative columns: for every encoder interval the wheel increment times the cosine and the
// sine of the measured steering angle (the mean of the interval's two ends); columns <wheel>_cos_steering and
// <wheel>_sin_steering.
Status TricycleColumns(const recording::Recording& rec, const std::string& rec_name, const Stream& enc,
                       Eigen::MatrixXd* angle, std::vector<std::string>* columns) {
  Result<const Stream*> picked = PickStream(rec, rec_name, StreamType::kSteering, "");
  if (!picked.ok()) return picked.status();
  const Stream& steering = *picked.value();
  if (enc.values.cols() != 1 || steering.t.size() < 2 || steering.values.cols() != 1) {
    return Status::Error(rec_name + ": a tricycle needs one wheel_encoders column and a steering stream of two or " +
                         "more samples");
  }
  const auto steering_at = [&steering](Time t) {
    const auto [i, w] = Bracket(steering.t, t);
    const double clamped = std::clamp(w, 0.0, 1.0);
    const auto r = static_cast<Eigen::Index>(i);
    return (1.0 - clamped) * steering.values(r, 0) + clamped * steering.values(r + 1, 0);
  };
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(angle->rows(), 2);
  for (Eigen::Index r = 1; r < angle->rows(); ++r) {
    const auto i = static_cast<std::size_t>(r);
    const double delta = 0.5 * (steering_at(enc.t[i - 1]) + steering_at(enc.t[i]));
    const double increment = (*angle)(r, 0) - (*angle)(r - 1, 0);
    out(r, 0) = out(r - 1, 0) + std::cos(delta) * increment;
    out(r, 1) = out(r - 1, 1) + std::sin(delta) * increment;
  }
  *angle = std::move(out);
  *columns = {enc.info.columns.front() + "_cos_steering", enc.info.columns.front() + "_sin_steering"};
  return Status::Ok();
}

}  // namespace

std::string KeyTimeOptions::Validate() const {
  if (!(interval_s > 0.0) || !std::isfinite(interval_s)) return "the key-time interval must be positive";
  return "";
}

Eigen::MatrixXd KeySequence::WheelIncrements() const {
  const Eigen::Index n = wheel_angle_rad.rows();
  if (n < 2) return Eigen::MatrixXd(0, wheel_angle_rad.cols());
  return wheel_angle_rad.bottomRows(n - 1) - wheel_angle_rad.topRows(n - 1);
}

Result<KeySequence> CutAtKeyTimes(const recording::Recording& rec, const std::string& rec_name,
                                  const KeyTimeOptions& options, bool with_sensor) {
  if (const std::string problem = options.Validate(); !problem.empty()) return Status::Error(rec_name + ": " + problem);
  // The streams.
  Result<const Stream*> encoders = PickStream(rec, rec_name, StreamType::kWheelEncoders, options.encoder_stream);
  if (!encoders.ok()) return encoders.status();
  const Stream& enc = *encoders.value();
  const Stream* sensor = nullptr;
  if (with_sensor) {
    Result<const Stream*> picked = PickSensor(rec, rec_name, options.sensor_stream);
    if (!picked.ok()) return picked.status();
    sensor = picked.value();
  }
  if (enc.t.size() < 2 || (sensor != nullptr && sensor->t.size() < 2)) {
    return Status::Error(rec_name + ": the encoder and sensor streams need at least two samples");
  }
  // Cumulative wheel angles [rad].
  Eigen::MatrixXd angle = enc.values;
  if (enc.info.units == "rad/s") {
    angle.row(0).setZero();
    for (std::size_t i = 1; i < enc.t.size(); ++i) {
      const double dt = SecondsBetween(enc.t[i - 1], enc.t[i]);
      const auto r = static_cast<Eigen::Index>(i);
      angle.row(r) = angle.row(r - 1) + 0.5 * dt * (enc.values.row(r - 1) + enc.values.row(r));
    }
  } else if (enc.info.units != "rad") {
    return Status::Error(rec_name + ": stream '" + enc.info.name + "' has units '" + enc.info.units +
                         "'; model-free odometry needs wheel angles (rad, ticks) or wheel rates (rad/s)");
  }
  std::vector<std::string> columns = enc.info.columns;
  if (rec.platform.kind == "tricycle") {
    if (Status s = TricycleColumns(rec, rec_name, enc, &angle, &columns); !s.ok()) return s;
  }
  // Key times T apart inside both streams.
  Time t_begin = enc.t.front();
  Time t_end = enc.t.back();
  const bool intervals = sensor != nullptr && sensor->info.type == StreamType::kScanMatching;
  if (sensor != nullptr && !intervals) {
    t_begin = std::max(t_begin, sensor->t.front());
    t_end = std::min(t_end, sensor->t.back());
  } else if (intervals && sensor->info.rate_hz > 0.0) {
    // The rows' grid: the first row's start to the last row's end.
    const std::int64_t half_ns = std::llround(0.5e9 / sensor->info.rate_hz);
    t_begin = std::max(t_begin, Time::FromNanoseconds(sensor->t.front().nanoseconds() - half_ns));
    t_end = std::min(t_end, Time::FromNanoseconds(sensor->t.back().nanoseconds() + half_ns));
  }
  const auto step_ns = static_cast<std::int64_t>(std::llround(options.interval_s * 1e9));
  KeySequence seq;
  seq.wheels = columns;
  for (Time t = t_begin; t <= t_end; t = Time::FromNanoseconds(t.nanoseconds() + step_ns)) seq.t.push_back(t);
  if (seq.t.size() < 2) {
    return Status::Error(rec_name + ": shorter than two key times " + std::to_string(options.interval_s) + " s apart");
  }
  // Interpolated wheel angles and sensor poses.
  seq.wheel_angle_rad.resize(seq.size(), angle.cols());
  for (int k = 0; k < seq.size(); ++k) {
    const auto [i, w] = Bracket(enc.t, seq.t[k]);
    const auto r = static_cast<Eigen::Index>(i);
    seq.wheel_angle_rad.row(k) = (1.0 - w) * angle.row(r) + w * angle.row(r + 1);
  }
  if (sensor != nullptr) {
    seq.sensor_step_sigma.resize(seq.size() - 1, 3);
    Status steps = intervals ? IntervalSteps(*sensor, rec_name, &seq) : PoseSteps(*sensor, rec_name, &seq);
    if (!steps.ok()) return steps;
    MountSteps(PlanarMounting(*sensor), &seq);
  }
  return seq;
}

Result<TrainingSet> MakeTrainingSet(const std::vector<KeySequence>& sequences) {
  if (sequences.empty()) return Status::Error("no training recordings");
  TrainingSet set;
  set.wheels = sequences.front().wheels;
  int n = 0;
  for (const KeySequence& seq : sequences) {
    if (seq.wheels != set.wheels) return Status::Error("training recordings name different wheels");
    if (static_cast<int>(seq.sensor_step.size()) != seq.size() - 1) {
      return Status::Error("a training recording has no sensor steps");
    }
    n += static_cast<int>(std::count(seq.step_valid.begin(), seq.step_valid.end(), true));
  }
  const auto m = static_cast<Eigen::Index>(set.wheels.size());
  set.delta.resize(n, m);
  set.s.resize(n, 3);
  set.s_sigma.resize(n, 3);
  int row = 0;
  for (const KeySequence& seq : sequences) {
    const Eigen::MatrixXd delta = seq.WheelIncrements();
    for (int k = 1; k < seq.size(); ++k) {
      if (!seq.step_valid[static_cast<std::size_t>(k - 1)]) continue;
      set.delta.row(row) = delta.row(k - 1);
      set.s.row(row) = seq.sensor_step[static_cast<std::size_t>(k - 1)].transpose();
      set.s_sigma.row(row) = seq.sensor_step_sigma.row(k - 1);
      ++row;
    }
  }
  return set;
}

}  // namespace roamlab::estimator::odometry
