#include "importers/rosbag.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>
#include <sstream>
#include <variant>

#include "common/atomic_file.h"
#include "importers/internal/bag.h"
#include "importers/internal/ros_messages.h"

namespace roamlab::importers {

using internal::Bag;
using internal::BagTopic;
using internal::RosMessage;
using recording::GeodeticOrigin;
using recording::Mounting;
using recording::Recording;
using recording::Stream;
using recording::StreamInfo;
using recording::StreamType;

namespace {

constexpr double kLargeGapS = 10.0;
constexpr double kClockOffsetS = 0.05;
constexpr double kUnitTolerance = 1e-3;

struct Sample {
  Time t;
  Time receive;
  Eigen::VectorXd row;
  std::string frame;      // camera: the frame's bytes
  std::string extension;  // camera: "pgm", "ppm", "jpg", "png"
};

// One output stream built from one topic.
struct Build {
  StreamInfo info;
  int value_columns = 0;      // leading columns of the constant check (covariances aside)
  std::string reason_prefix;  // "" for a topic's main stream, "pose: " for an odometry topic's pose stream
  std::vector<Sample> samples;
  std::vector<double> sigma_a, sigma_b;  // imu: gyro, accel; gps, pose: position
};

struct TopicWork {
  const BagTopic* topic = nullptr;
  RosbagTopicReport* report = nullptr;
  const RosbagImportOptions* options = nullptr;
  std::vector<Build> builds;  // one, or two for nav_msgs/Odometry (the twist and the pose)
  std::vector<std::string> joints;
  int beams = -1;
};

double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

template <std::size_t N>
Eigen::VectorXd Vec(const std::array<double, N>& a) {
  return Eigen::Map<const Eigen::VectorXd>(a.data(), static_cast<Eigen::Index>(N));
}

Eigen::VectorXd UpperTriangle(const Eigen::Matrix<double, 6, 6>& cov) {
  Eigen::VectorXd out(21);
  int k = 0;
  for (int i = 0; i < 6; ++i)
    for (int j = i; j < 6; ++j) out[k++] = cov(i, j);
  return out;
}

Build MakeBuild(StreamType type, const std::string& name, bool covariance) {
  Build b;
  b.info.type = type;
  b.info.name = name;
  b.info.columns = recording::FixedColumns(type);
  b.value_columns = static_cast<int>(b.info.columns.size());
  if (covariance) {
    const std::vector<std::string>& cov = recording::CovarianceColumns(type);
    b.info.columns.insert(b.info.columns.end(), cov.begin(), cov.end());
  }
  return b;
}

// The streams a topic of `type` becomes, named `name` (their columns set by the first message where they depend on
// it).
std::vector<Build> BuildsOf(const std::string& type, const std::string& name) {
  if (type == "sensor_msgs/Imu") return {MakeBuild(StreamType::kImu, name, false)};
  if (type == "sensor_msgs/NavSatFix") return {MakeBuild(StreamType::kGps, name, true)};
  if (type == "sensor_msgs/MagneticField") {
    Build b = MakeBuild(StreamType::kMagnetometer, name, false);
    b.info.units = "uT";
    return {b};
  }
  if (type == "sensor_msgs/JointState") return {MakeBuild(StreamType::kWheelEncoders, name, false)};
  if (type == "sensor_msgs/LaserScan") return {MakeBuild(StreamType::kLaserScan, name, false)};
  if (type == "sensor_msgs/Image" || type == "sensor_msgs/CompressedImage") {
    Build b = MakeBuild(StreamType::kCamera, name, false);
    b.value_columns = 0;
    return {b};
  }
  if (type == "nav_msgs/Odometry") {
    Build pose = MakeBuild(StreamType::kPose, name + "_pose", false);
    pose.reason_prefix = "pose: ";
    return {MakeBuild(StreamType::kOdometry, name, true), pose};
  }
  if (type == "geometry_msgs/TwistStamped") return {MakeBuild(StreamType::kOdometry, name, false)};
  return {MakeBuild(StreamType::kPose, name, false)};  // PoseStamped, PoseWithCovarianceStamped
}

void Skip(TopicWork* w, const Build& b, const std::string& reason) { ++w->report->skipped[b.reason_prefix + reason]; }

// Appends a pose sample (x y z qx qy qz qw), or counts it skipped when its orientation is not a unit quaternion.
void AddPose(const internal::RosPose& pose, Time t, Time receive, Build* b, TopicWork* w) {
  const Eigen::VectorXd q = Vec(pose.orientation_xyzw);
  if (!(std::abs(q.norm() - 1.0) <= kUnitTolerance)) return Skip(w, *b, "orientation not a unit quaternion");
  Eigen::VectorXd row(7);
  row << Vec(pose.position), q;
  b->samples.push_back({t, receive, row, "", ""});
}

// nav_msgs/Odometry: the twist into the body frame (the frame rule, header comment); "" or the refusal.
std::string AddOdometry(const RosMessage& m, const internal::RosOdometry& o, Time receive, TopicWork* w) {
  Eigen::Matrix<double, 6, 1> twist = Eigen::Map<const Eigen::Matrix<double, 6, 1>>(o.twist.data());
  Eigen::Matrix<double, 6, 6> cov =
      Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>>(o.twist_covariance.data());
  if (o.child_frame_id.empty()) {
    if (m.header.frame_id.empty()) return "neither child_frame_id nor header.frame_id names the twist's frame";
    const auto& q = o.pose.orientation_xyzw;
    const Eigen::Quaterniond q_parent_body(q[3], q[0], q[1], q[2]);
    if (!(std::abs(q_parent_body.norm() - 1.0) <= kUnitTolerance)) {
      std::ostringstream problem;
      problem << "child_frame_id is empty, so the twist is in '" << m.header.frame_id
              << "', but the pose orientation (norm " << q_parent_body.norm()
              << ") is not a unit quaternion to rotate it into the body frame";
      return problem.str();
    }
    Eigen::Matrix<double, 6, 6> b = Eigen::Matrix<double, 6, 6>::Zero();
    b.topLeftCorner<3, 3>() = b.bottomRightCorner<3, 3>() = q_parent_body.normalized().toRotationMatrix().transpose();
    twist = b * twist;
    cov = b * cov * b.transpose();
  }
  Eigen::VectorXd row(27);
  row << twist, UpperTriangle(cov);
  w->builds[0].samples.push_back({m.header.stamp, receive, row, "", ""});
  AddPose(o.pose, m.header.stamp, receive, &w->builds[1], w);
  return "";
}

// sensor_msgs/JointState: the selected joints' positions or velocities; "" or the refusal (no joint, or two joint
// names that give one column name).
std::string AddJoints(const RosMessage& m, const internal::RosJointState& j, Time receive, TopicWork* w) {
  Build& b = w->builds[0];
  const bool velocity = w->options->joint_velocities;
  if (w->joints.empty()) {
    w->joints = w->options->joints.empty() ? j.name : w->options->joints;
    if (w->joints.empty()) return "no joint names in the topic's first message";
    for (const std::string& name : w->joints) {
      const std::string column = StreamNameOfTopic(name);
      if (std::find(b.info.columns.begin(), b.info.columns.end(), column) != b.info.columns.end())
        return "two joints give the column name '" + column + "'";
      b.info.columns.push_back(column);
    }
    b.value_columns = static_cast<int>(b.info.columns.size());
    b.info.units = velocity ? "rad/s" : "rad";
  }
  const std::vector<double>& values = velocity ? j.velocity : j.position;
  Eigen::VectorXd row(static_cast<Eigen::Index>(w->joints.size()));
  for (std::size_t i = 0; i < w->joints.size(); ++i) {
    const auto at = std::find(j.name.begin(), j.name.end(), w->joints[i]);
    const auto k = static_cast<std::size_t>(at - j.name.begin());
    if (at == j.name.end() || k >= values.size()) {
      Skip(w, b, "joint '" + w->joints[i] + "' without a " + (velocity ? "velocity" : "position"));
      return "";
    }
    row[static_cast<Eigen::Index>(i)] = values[k];
  }
  b.samples.push_back({m.header.stamp, receive, row, "", ""});
  return "";
}

// sensor_msgs/LaserScan: geometry and ranges, non-finite ranges as -1 (no return).
void AddScan(const RosMessage& m, const internal::RosLaserScan& s, Time receive, TopicWork* w) {
  Build& b = w->builds[0];
  if (w->beams < 0 && !s.ranges.empty()) {
    w->beams = static_cast<int>(s.ranges.size());
    b.info.columns = recording::LaserScanColumns(w->beams);
    b.value_columns = static_cast<int>(b.info.columns.size());
    b.info.units = "rad,m";
  }
  if (static_cast<int>(s.ranges.size()) != w->beams) return Skip(w, b, "beam count differs from the first scan's");
  if (!(s.angle_increment != 0.0f && s.range_min >= 0.0f && s.range_max > s.range_min) || !std::isfinite(s.angle_min) ||
      !std::isfinite(s.angle_increment) || !std::isfinite(s.range_max))
    return Skip(w, b, "invalid scan geometry");
  Eigen::VectorXd row(4 + w->beams);
  row.head<4>() << s.angle_min, s.angle_increment, s.range_min, s.range_max;
  for (int k = 0; k < w->beams; ++k) {
    const float r = s.ranges[static_cast<std::size_t>(k)];
    row[4 + k] = std::isfinite(r) ? r : -1.0;
  }
  b.samples.push_back({m.header.stamp, receive, row, "", ""});
}

// sensor_msgs/Image as PGM / PPM bytes.
void AddImage(const RosMessage& m, const internal::RosImage& im, Time receive, TopicWork* w) {
  Build& b = w->builds[0];
  const int channels = im.encoding == "mono8" ? 1 : (im.encoding == "rgb8" || im.encoding == "bgr8") ? 3 : 0;
  if (channels == 0) return Skip(w, b, "image encoding '" + im.encoding + "' not written");
  if (im.width == 0 || im.height == 0) return Skip(w, b, "empty image");
  const std::uint64_t row_bytes = std::uint64_t{im.width} * static_cast<std::uint64_t>(channels);
  if (im.step < row_bytes || std::uint64_t{im.step} * im.height > im.data.size())
    return Skip(w, b, "image data shorter than height x step");
  Sample s{m.header.stamp, receive, Eigen::VectorXd(), "", channels == 1 ? "pgm" : "ppm"};
  s.frame = (channels == 1 ? "P5\n" : "P6\n") + std::to_string(im.width) + " " + std::to_string(im.height) + "\n255\n";
  for (std::uint32_t y = 0; y < im.height; ++y) {
    std::string line(im.data.substr(std::size_t{y} * im.step, row_bytes));
    if (im.encoding == "bgr8")
      for (std::size_t x = 0; x + 2 < line.size(); x += 3) std::swap(line[x], line[x + 2]);
    s.frame += line;
  }
  b.samples.push_back(std::move(s));
}

// sensor_msgs/CompressedImage: the bytes as given, named by their signature (else by the format string).
void AddCompressed(const RosMessage& m, const internal::RosCompressedImage& c, Time receive, TopicWork* w) {
  std::string extension;
  if (c.data.substr(0, 3) == "\xff\xd8\xff") {
    extension = "jpg";
  } else if (c.data.substr(0, 4) == "\x89PNG") {
    extension = "png";
  } else if (c.format.find("png") != std::string::npos) {
    extension = "png";
  } else if (c.format.find("jpeg") != std::string::npos || c.format.find("jpg") != std::string::npos) {
    extension = "jpg";
  } else {
    return Skip(w, w->builds[0], "image format '" + c.format + "' not written");
  }
  w->builds[0].samples.push_back({m.header.stamp, receive, Eigen::VectorXd(), std::string(c.data), extension});
}

// Adds one decoded message to its topic's streams; "" or the refusal.
std::string AddMessage(const RosMessage& m, Time receive, TopicWork* w) {
  Build& b = w->builds[0];
  const Time t = m.header.stamp;
  if (const auto* imu = std::get_if<internal::RosImu>(&m.body)) {
    Eigen::VectorXd row(6);
    row << Vec(imu->angular_velocity), Vec(imu->linear_acceleration);
    b.samples.push_back({t, receive, row, "", ""});
    if (imu->angular_velocity_covariance[0] > 0.0) b.sigma_a.push_back(std::sqrt(imu->angular_velocity_covariance[0]));
    if (imu->linear_acceleration_covariance[0] > 0.0)
      b.sigma_b.push_back(std::sqrt(imu->linear_acceleration_covariance[0]));
  } else if (const auto* fix = std::get_if<internal::RosNavSatFix>(&m.body)) {
    if (fix->status < 0) {
      Skip(w, b, "no fix");
      return "";
    }
    if (!(std::abs(fix->latitude_deg) <= 90.0 && std::abs(fix->longitude_deg) <= 180.0)) {
      Skip(w, b, "latitude or longitude outside the Earth's range");
      return "";
    }
    const auto& c = fix->position_covariance;
    Eigen::VectorXd row(9);
    row << fix->latitude_deg, fix->longitude_deg, fix->altitude_m, c[0], c[1], c[2], c[4], c[5], c[8];
    b.samples.push_back({t, receive, row, "", ""});
    if (c[0] > 0.0 && c[4] > 0.0) b.sigma_a.push_back(std::sqrt(0.5 * (c[0] + c[4])));
  } else if (const auto* mag = std::get_if<internal::RosMagneticField>(&m.body)) {
    b.samples.push_back({t, receive, Vec(mag->field_t) * 1e6, "", ""});
  } else if (const auto* joints = std::get_if<internal::RosJointState>(&m.body)) {
    return AddJoints(m, *joints, receive, w);
  } else if (const auto* scan = std::get_if<internal::RosLaserScan>(&m.body)) {
    AddScan(m, *scan, receive, w);
  } else if (const auto* image = std::get_if<internal::RosImage>(&m.body)) {
    AddImage(m, *image, receive, w);
  } else if (const auto* compressed = std::get_if<internal::RosCompressedImage>(&m.body)) {
    AddCompressed(m, *compressed, receive, w);
  } else if (const auto* odometry = std::get_if<internal::RosOdometry>(&m.body)) {
    return AddOdometry(m, *odometry, receive, w);
  } else if (const auto* twist = std::get_if<internal::RosTwistStamped>(&m.body)) {
    b.samples.push_back({t, receive, Vec(twist->twist), "", ""});
  } else if (const auto* pose = std::get_if<internal::RosPoseStamped>(&m.body)) {
    AddPose(pose->pose, t, receive, &b, w);
  } else if (const auto* pose_cov = std::get_if<internal::RosPoseWithCovarianceStamped>(&m.body)) {
    AddPose(pose_cov->pose, t, receive, &b, w);
    const auto& c = pose_cov->covariance;
    if (c[0] > 0.0 && c[7] > 0.0) b.sigma_a.push_back(std::sqrt(0.5 * (c[0] + c[7])));
  }
  return "";
}

// The checks of the header comment on one build's samples (in the bag's order), into the topic's report (the main
// stream only) and its warnings.
void Check(const Build& b, const std::vector<Sample>& kept, TopicWork* w, std::vector<std::string>* warnings) {
  RosbagTopicReport& rep = *w->report;
  const std::string who = w->topic->name + " (" + b.info.name + "): ";
  if (b.reason_prefix.empty()) {
    for (std::size_t i = 1; i < b.samples.size(); ++i) rep.stamps_back += b.samples[i].t < b.samples[i - 1].t;
    if (rep.stamps_back > 0)
      warnings->push_back(who + std::to_string(rep.stamps_back) +
                          " header stamps jump back from the previous message's (sorted by stamp)");
    std::vector<double> offsets;
    for (const Sample& s : kept) offsets.push_back(SecondsBetween(s.receive, s.t));
    rep.clock_offset_s = Median(offsets);
    if (std::abs(rep.clock_offset_s) > kClockOffsetS)
      warnings->push_back(who + DescribeClockOffset(rep.clock_offset_s));
    for (std::size_t i = 1; i < kept.size(); ++i) {
      const double gap = SecondsBetween(kept[i - 1].t, kept[i].t);
      if (gap > kLargeGapS) ++rep.gaps;
      rep.largest_gap_s = std::max(rep.largest_gap_s, gap);
    }
    if (rep.gaps > 0) {
      std::ostringstream line;
      line << who << rep.gaps << " gaps of more than " << kLargeGapS << " s between header stamps (largest "
           << rep.largest_gap_s << " s)";
      warnings->push_back(line.str());
    }
  }
  if (b.value_columns == 0 || kept.size() < 2) return;
  bool zero = true, constant = true;
  for (const Sample& s : kept) {
    zero = zero && s.row.head(b.value_columns).isZero(0.0);
    constant = constant && s.row.head(b.value_columns) == kept.front().row.head(b.value_columns);
  }
  if (zero || constant) warnings->push_back(who + (zero ? "all values are zero" : "all values are constant"));
  if (b.reason_prefix.empty()) {
    rep.all_zero = zero;
    rep.constant = constant && !zero;
  }
}

// Sorts and filters a build's samples into its stream; false when fewer than two samples are left.
bool Finish(Build* b, TopicWork* w, std::vector<CameraFrame>* frames, std::vector<std::string>* warnings, Stream* out) {
  std::vector<Sample> kept;
  for (Sample& s : b->samples) {
    if (s.row.allFinite()) {
      kept.push_back(std::move(s));
    } else {
      Skip(w, *b, "non-finite value");
    }
  }
  std::stable_sort(kept.begin(), kept.end(), [](const Sample& x, const Sample& y) { return x.t < y.t; });
  const auto repeated =
      std::unique(kept.begin(), kept.end(), [](const Sample& x, const Sample& y) { return x.t == y.t; });
  for (auto it = repeated; it != kept.end(); ++it) Skip(w, *b, "repeated header stamp");
  kept.erase(repeated, kept.end());
  Check(*b, kept, w, warnings);
  if (kept.size() < 2) return false;
  out->info = b->info;
  out->values.resize(b->info.type == StreamType::kCamera ? 0 : static_cast<Eigen::Index>(kept.size()),
                     b->info.type == StreamType::kCamera ? 0 : static_cast<Eigen::Index>(b->info.columns.size()));
  for (std::size_t i = 0; i < kept.size(); ++i) {
    out->t.push_back(kept[i].t);
    if (b->info.type != StreamType::kCamera) {
      out->values.row(static_cast<Eigen::Index>(i)) = kept[i].row.transpose();
      continue;
    }
    char file[32];
    std::snprintf(file, sizeof(file), "/%06zu.", i);
    out->text.push_back(b->info.name + file + kept[i].extension);
    frames->push_back({out->text.back(), std::move(kept[i].frame)});
  }
  out->info.rate_hz = static_cast<double>(kept.size() - 1) / SecondsBetween(out->t.front(), out->t.back());
  return true;
}

// The topics to import: topic index -> stream name; "" or the problem.
std::string Select(const Bag& bag, const RosbagImportOptions& options, std::map<std::size_t, std::string>* out) {
  const auto index_of = [&](const std::string& name) {
    std::size_t i = 0;
    while (i < bag.topics.size() && bag.topics[i].name != name) ++i;
    return i;
  };
  for (const auto& [topic, stream] : options.topics) {
    const std::size_t i = index_of(topic);
    if (i == bag.topics.size()) return "no topic '" + topic + "' in the bag";
    if (out->count(i)) return "topic " + topic + " is selected twice";
    if (!internal::IsSupportedRosType(bag.topics[i].type))
      return "topic " + topic + " has type " + bag.topics[i].type + ", which is not imported";
    if (stream.empty() || StreamNameOfTopic(stream) != stream)
      return "stream name '" + stream + "' for " + topic + " is not [A-Za-z0-9_]+";
    (*out)[i] = stream;
  }
  if (!options.topics.empty()) return "";
  for (std::size_t i = 0; i < bag.topics.size(); ++i)
    if (internal::IsSupportedRosType(bag.topics[i].type)) (*out)[i] = StreamNameOfTopic(bag.topics[i].name);
  if (out->empty()) {
    std::string names;
    for (const std::string& t : internal::SupportedRosTypes()) names += (names.empty() ? "" : ", ") + t;
    return "no topic of a supported type (" + names + ")";
  }
  return "";
}

// Messages decoded of the selected topics' `total`, reported through RosbagImportOptions::progress.
struct DecodeProgress {
  const std::function<void(double)>* report = nullptr;
  std::size_t done = 0;
  std::size_t total = 0;

  void Advance() {
    ++done;
    if (*report && (done % RosbagImportOptions::kProgressMessages == 0 || done == total))
      (*report)(static_cast<double>(done) / static_cast<double>(total));
  }
};

// Decodes one topic's messages into its streams; "" or the refusal naming the message.
std::string DecodeTopic(const Bag& bag, const std::vector<std::size_t>& messages, TopicWork* w,
                        DecodeProgress* progress) {
  for (std::size_t k = 0; k < messages.size(); ++k) {
    const internal::BagMessage& m = bag.messages[messages[k]];
    Result<RosMessage> decoded = internal::DecodeRosMessage(w->topic->type, m.data, w->topic->encoding);
    std::string problem = decoded.ok() ? AddMessage(decoded.value(), m.receive_time, w) : decoded.status().message();
    if (!problem.empty()) return w->topic->name + " message " + std::to_string(k) + " (counting from 0): " + problem;
    progress->Advance();
  }
  return "";
}

// The noise and mounting a stream gets from its samples and the options.
void SetNoise(const Build& b, const RosbagImportOptions& options, Stream* s) {
  if (b.info.type == StreamType::kImu) {
    if (!b.sigma_a.empty()) s->info.noise["gyro_sigma_radps"] = Median(b.sigma_a);
    if (!b.sigma_b.empty()) s->info.noise["accel_sigma_mps2"] = Median(b.sigma_b);
    if (options.q_body_imu) s->info.mounting = Mounting{Eigen::Vector3d::Zero(), options.q_body_imu->normalized()};
  } else if (!b.sigma_a.empty()) {
    s->info.noise["sigma_m"] = Median(b.sigma_a);
  }
}

// Stream `wheels` re-expressed from the odometry (header comment); "" or the problem.
std::string AddWheels(const RosbagImportOptions& options, const std::map<std::string, std::string>& odometry_streams,
                      Recording* rec) {
  const auto r = rec->platform.geometry.find("wheel_radius_m");
  const auto b = rec->platform.geometry.find("baseline_m");
  if (r == rec->platform.geometry.end() || b == rec->platform.geometry.end() || !(r->second > 0.0) ||
      !(b->second > 0.0))
    return "wheels from odometry need positive wheel_radius_m and baseline_m in the platform geometry";
  const double separation_m = options.odometry_wheel_separation_m.value_or(b->second);
  if (!(std::isfinite(separation_m) && separation_m > 0.0 && separation_m < 1e3))
    return "the odometry's wheel separation must be a positive number of metres below 1000";
  std::string name;
  if (!options.odometry_topic.empty()) {
    const auto it = odometry_streams.find(options.odometry_topic);
    if (it == odometry_streams.end()) return "--odometry-topic " + options.odometry_topic + " is no imported odometry";
    name = it->second;
  } else if (odometry_streams.size() == 1) {
    name = odometry_streams.begin()->second;
  } else {
    std::string topics;
    for (const auto& [topic, stream] : odometry_streams) topics += (topics.empty() ? "" : ", ") + topic;
    return odometry_streams.empty()
               ? "wheels from odometry need an odometry topic"
               : "wheels from odometry: several odometry topics (" + topics + "); choose one with --odometry-topic";
  }
  const Stream& odo = *rec->Find(name);
  Stream wheels;
  wheels.info.name = "wheels";
  wheels.info.type = StreamType::kWheelEncoders;
  wheels.info.columns = {"left", "right"};
  wheels.info.units = "rad";
  wheels.info.rate_hz = odo.info.rate_hz;
  wheels.info.attributes["derived_from_odometry"] = 1.0;
  wheels.info.attributes["wheel_separation_m"] = separation_m;
  wheels.t = odo.t;
  wheels.values = Eigen::MatrixXd::Zero(odo.values.rows(), 2);
  // Wheel rate of side `side` (-1 left, +1 right) at sample k [rad/s].
  const auto rate = [&](Eigen::Index k, double side) {
    return (odo.values(k, 0) + side * 0.5 * odo.values(k, 5) * separation_m) / r->second;
  };
  for (Eigen::Index k = 1; k < odo.values.rows(); ++k) {
    const double dt = SecondsBetween(odo.t[static_cast<std::size_t>(k - 1)], odo.t[static_cast<std::size_t>(k)]);
    wheels.values(k, 0) = wheels.values(k - 1, 0) + 0.5 * dt * (rate(k - 1, -1.0) + rate(k, -1.0));
    wheels.values(k, 1) = wheels.values(k - 1, 1) + 0.5 * dt * (rate(k - 1, 1.0) + rate(k, 1.0));
  }
  rec->streams.push_back(std::move(wheels));
  return "";
}

// Turns the selected topics into streams; "" or the problem.
std::string BuildStreams(const Bag& bag, const RosbagImportOptions& options,
                         const std::map<std::size_t, std::string>& selected, RosbagImportReport* rep, Recording* rec) {
  std::vector<std::vector<std::size_t>> per_topic(bag.topics.size());
  for (std::size_t i = 0; i < bag.messages.size(); ++i) per_topic[bag.messages[i].topic].push_back(i);
  std::set<std::string> names;
  std::map<std::string, std::string> odometry_streams;  // topic -> stream
  DecodeProgress progress{&options.progress, 0, 0};
  for (const auto& [index, name] : selected) progress.total += per_topic[index].size();
  for (const auto& [index, name] : selected) {
    TopicWork w{&bag.topics[index], &rep->topics[index], &options, BuildsOf(bag.topics[index].type, name), {}, -1};
    if (std::string problem = DecodeTopic(bag, per_topic[index], &w, &progress); !problem.empty()) return problem;
    w.report->decoded = true;
    for (Build& b : w.builds) {
      Stream s;
      if (!Finish(&b, &w, &rep->frames, &rep->warnings, &s)) {
        if (!options.topics.empty() && b.reason_prefix.empty()) {
          std::string skipped;
          for (const auto& [reason, n] : w.report->skipped)
            skipped += (skipped.empty() ? " (skipped: " : ", ") + std::to_string(n) + " " + reason;
          return w.topic->name + " has fewer than two usable messages" + (skipped.empty() ? "" : skipped + ")");
        }
        rep->warnings.push_back(w.topic->name + " (" + b.info.name +
                                "): not imported (fewer than two usable messages)");
        continue;
      }
      if (!names.insert(s.info.name).second)
        return "two streams named '" + s.info.name + "' (choose names with --topic)";
      SetNoise(b, options, &s);
      if (s.info.type == StreamType::kGps && !rec->origin)
        rec->origin = GeodeticOrigin{s.values(0, 0), s.values(0, 1), s.values(0, 2)};
      if (s.info.type == StreamType::kOdometry) odometry_streams[w.topic->name] = s.info.name;
      w.report->streams.push_back(s.info.name);
      rec->streams.push_back(std::move(s));
    }
  }
  if (rec->streams.empty()) return "no topic has two usable messages";
  if (!options.wheels_from_odometry) return "";
  if (names.count("wheels")) return "a stream is already named 'wheels' (rename it with --topic)";
  return AddWheels(options, odometry_streams, rec);
}

}  // namespace

const RosbagTopicReport* RosbagImportReport::Find(const std::string& topic) const {
  for (const RosbagTopicReport& t : topics)
    if (t.topic == topic) return &t;
  return nullptr;
}

std::string DescribeClockOffset(double offset_s) {
  if (std::lround(std::abs(offset_s) * 1e3) == 0) return "header stamps match the bag's receive times (within 1 ms)";
  return "header stamps are " + std::to_string(std::lround(std::abs(offset_s) * 1e3)) + " ms " +
         (offset_s < 0.0 ? "earlier" : "later") + " than the bag's receive times";
}

std::string StreamNameOfTopic(const std::string& topic) {
  std::string name;
  for (char ch : topic) {
    if (std::isalnum(static_cast<unsigned char>(ch))) {
      name += ch;
    } else if (!name.empty() && name.back() != '_') {
      name += '_';
    }
  }
  while (!name.empty() && name.back() == '_') name.pop_back();
  return name.empty() ? "topic" : name;
}

Result<Recording> ImportRosbag(const std::string& bag_path, const RosbagImportOptions& options,
                               RosbagImportReport* report) {
  RosbagImportReport local;
  RosbagImportReport& rep = report ? *report : local;
  rep = RosbagImportReport();
  Result<Bag> read = internal::ReadAnyBag(bag_path);
  if (!read.ok()) return read.status();
  const Bag& bag = read.value();
  rep.format = bag.format;
  rep.chunks = bag.chunks;
  for (const BagTopic& t : bag.topics)
    rep.topics.push_back({t.name, t.type, false, {}, 0, {}, 0, 0, 0.0, 0.0, false, false});
  for (const internal::BagMessage& m : bag.messages) ++rep.topics[m.topic].messages;
  std::map<std::size_t, std::string> selected;
  if (std::string problem = Select(bag, options, &selected); !problem.empty())
    return Status::Error(bag_path + ": " + problem);
  Recording rec;
  rec.platform = options.platform;
  if (std::string problem = BuildStreams(bag, options, selected, &rep, &rec); !problem.empty())
    return Status::Error(bag_path + ": " + problem);
  rec.provenance.source = "imported";
  std::ostringstream description;
  description << bag.format << " " << std::filesystem::path(bag_path).filename().string() << " (header stamps; topics:";
  for (const auto& [index, name] : selected) description << " " << bag.topics[index].name;
  description << ")";
  rec.provenance.description = description.str();
  return rec;
}

Status WriteCameraFrames(const std::vector<CameraFrame>& frames, const std::string& directory) {
  for (const CameraFrame& f : frames) {
    const std::filesystem::path path = std::filesystem::path(directory) / f.file;
    std::error_code ec;
    std::filesystem::create_directories(path.parent_path(), ec);
    if (ec) return Status::Error(path.parent_path().string() + ": cannot create the frame directory: " + ec.message());
    if (Status s = WriteFileAtomic(path.string(), std::string_view(f.bytes.data(), f.bytes.size())); !s.ok()) return s;
  }
  return Status::Ok();
}

Result<std::vector<RosbagTopicListing>> ListRosbag(const std::string& bag_path) {
  Result<Bag> read = internal::ReadAnyBag(bag_path);
  if (!read.ok()) return read.status();
  const Bag& bag = read.value();
  std::vector<RosbagTopicListing> rows;
  for (const BagTopic& t : bag.topics)
    rows.push_back({t.name, t.type, internal::IsSupportedRosType(t.type), 0, 0.0, Time(), Time()});
  for (const internal::BagMessage& m : bag.messages) {
    RosbagTopicListing& row = rows[m.topic];
    if (row.messages == 0 || m.receive_time < row.first) row.first = m.receive_time;
    if (row.messages == 0 || m.receive_time > row.last) row.last = m.receive_time;
    ++row.messages;
  }
  for (RosbagTopicListing& row : rows) {
    const double span = SecondsBetween(row.first, row.last);
    if (row.messages > 1 && span > 0.0) row.rate_hz = (row.messages - 1) / span;
  }
  return rows;
}

}  // namespace roamlab::importers
