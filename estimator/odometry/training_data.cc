#include "estimator/odometry/training_data.h"

#include <algorithm>
#include <cmath>

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
    Result<const Stream*> picked = PickStream(rec, rec_name, StreamType::kPose, options.sensor_stream);
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
  // Key times T apart inside both streams.
  Time t_begin = enc.t.front();
  Time t_end = enc.t.back();
  if (sensor != nullptr) {
    t_begin = std::max(t_begin, sensor->t.front());
    t_end = std::min(t_end, sensor->t.back());
  }
  const auto step_ns = static_cast<std::int64_t>(std::llround(options.interval_s * 1e9));
  KeySequence seq;
  seq.wheels = enc.info.columns;
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
    for (int k = 0; k < seq.size(); ++k) {
      const auto [i, w] = Bracket(sensor->t, seq.t[k]);
      const Pose2 a = PlanarPose(sensor->values, static_cast<Eigen::Index>(i));
      const Pose2 b = PlanarPose(sensor->values, static_cast<Eigen::Index>(i) + 1);
      Pose2 p = (1.0 - w) * a + w * b;
      p[2] = a[2] + w * WrapAngle(b[2] - a[2]);
      seq.sensor_pose.push_back(p);
    }
    const auto& noise = sensor->info.noise;
    if (auto it = noise.find("position_m"); it != noise.end()) seq.sensor_sigma[0] = it->second;
    if (auto it = noise.find("orientation_rad"); it != noise.end()) seq.sensor_sigma[1] = it->second;
    if (!(seq.sensor_sigma.array() > 0.0).all()) {
      return Status::Error(rec_name + ": stream '" + sensor->info.name + "' needs positive position_m and "
                           "orientation_rad noise");
    }
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
    if (static_cast<int>(seq.sensor_pose.size()) != seq.size()) {
      return Status::Error("a training recording has no sensor poses");
    }
    n += seq.size() - 1;
  }
  const auto m = static_cast<Eigen::Index>(set.wheels.size());
  set.delta.resize(n, m);
  set.s.resize(n, 3);
  set.s_sigma.resize(n, 3);
  int row = 0;
  for (const KeySequence& seq : sequences) {
    const Eigen::MatrixXd delta = seq.WheelIncrements();
    const double sp = std::sqrt(2.0) * seq.sensor_sigma[0];
    const double so = std::sqrt(2.0) * seq.sensor_sigma[1];
    for (int k = 1; k < seq.size(); ++k, ++row) {
      set.delta.row(row) = delta.row(k - 1);
      set.s.row(row) = Between(seq.sensor_pose[k - 1], seq.sensor_pose[k]).transpose();
      set.s_sigma.row(row) << sp, sp, so;
    }
  }
  return set;
}

}  // namespace roamlab::estimator::odometry
