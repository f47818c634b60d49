#include "experiment/init.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <utility>

#include <Eigen/Geometry>

#include "common/atomic_file.h"
#include "estimator/problem.h"
#include "recording/odometry_pose.h"

namespace roamlab::experiment {
namespace {

using recording::Recording;
using recording::Stream;
using recording::StreamInfo;
using recording::StreamType;

constexpr double kPi = 3.14159265358979323846;

// One YAML key (or list item) with the comment line written above it, and a flow value or nested keys.
struct Node {
  std::string key;  // "" for a list item
  std::string comment;
  std::string value;  // flow text; empty when `children` holds the value
  std::vector<Node> children;
};

// The shortest decimal text that reads back as exactly `x`.
std::string Number(double x) {
  for (int digits = 6; digits <= 17; ++digits) {
    std::ostringstream s;
    s.precision(digits);
    s << x;
    if (std::strtod(s.str().c_str(), nullptr) == x) return s.str();
  }
  return std::to_string(x);
}

std::string List(const std::vector<double>& v) {
  std::string text = "[";
  for (std::size_t i = 0; i < v.size(); ++i) text += (i ? ", " : "") + Number(v[i]);
  return text + "]";
}

// A name as a YAML scalar: plain when it is an identifier, else double-quoted.
std::string Name(const std::string& name) {
  const bool plain = !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.' || c == '-';
  });
  if (plain && !std::isdigit(static_cast<unsigned char>(name[0])) && name[0] != '-') return name;
  std::string quoted = "\"";
  for (char c : name) {
    if (c == '"' || c == '\\') quoted += '\\';
    quoted += c;
  }
  return quoted + "\"";
}

std::string NameList(const std::vector<std::string>& names) {
  std::string text = "[";
  for (std::size_t i = 0; i < names.size(); ++i) text += (i ? ", " : "") + Name(names[i]);
  return text + "]";
}

// `text` as comment lines of at most 120 characters (a longer word keeps its own line).
void Comment(const std::string& text, const std::string& pad, std::ostringstream* out) {
  std::istringstream words(text);
  std::string word, line;
  while (words >> word) {
    if (!line.empty() && pad.size() + 2 + line.size() + 1 + word.size() > 120) {
      *out << pad << "# " << line << "\n";
      line.clear();
    }
    line += (line.empty() ? "" : " ") + word;
  }
  if (!line.empty()) *out << pad << "# " << line << "\n";
}

void Emit(const Node& node, int indent, std::ostringstream* out) {
  const std::string pad(static_cast<std::size_t>(indent), ' ');
  Comment(node.comment, pad, out);
  *out << pad << (node.key.empty() ? "-" : node.key + ":");
  if (node.children.empty()) {
    *out << " " << node.value << "\n";
    return;
  }
  *out << "\n";
  for (const Node& child : node.children) Emit(child, indent + 2, out);
}

// A stated noise entry of a stream (the first of `keys` present, positive and finite) or the default.
// The accelerometer noise a wheeled vehicle's configuration takes at least [m/s^2].
constexpr double kVehicleAccelFloorMps2 = 0.5;

struct Noise {
  double value = 0.0;
  std::string origin;
};
Noise StatedNoise(const std::string& rec_name, const StreamInfo& info, const std::vector<std::string>& keys,
                  double fallback, const std::string& why) {
  for (const std::string& key : keys) {
    const auto it = info.noise.find(key);
    if (it == info.noise.end()) continue;
    const std::string where = rec_name + "/recording.yaml " + info.name + ".noise." + key;
    if (std::isfinite(it->second) && it->second > 0.0) return {it->second, "noise from " + where};
    return {fallback, "default " + why + ": " + where + " = " + Number(it->second) + " is not positive"};
  }
  return {fallback, "default: no stated noise; " + why};
}

std::string TypeName(const Stream& s) { return recording::StreamTypeName(s.info.type); }

// The configuration under construction: the YAML nodes and what the comments need.
class Builder {
 public:
  Builder(const Recording& rec, std::string rec_name, std::string kind, std::string kind_origin)
      : rec_(rec), rec_name_(std::move(rec_name)), kind_(std::move(kind)), kind_origin_(std::move(kind_origin)) {}

  Status Build();
  std::string Yaml() const;
  const std::vector<std::string>& left_out() const { return left_out_; }

 private:
  std::string Where(const std::string& key) const { return rec_name_ + "/recording.yaml " + key; }
  void LeaveOut(const Stream& s, const std::string& reason) {
    left_out_.push_back(s.info.name + " (" + TypeName(s) + "): " + reason);
  }
  std::string UniqueName(const std::string& wanted) {
    std::string name = wanted;
    for (int i = 2; used_names_.count(name); ++i) name = wanted + "_" + std::to_string(i);
    used_names_.insert(name);
    return name;
  }
  // A parameter entry: its value with the value's origin, free or fixed with the reason; free ones join a stage.
  void Parameter(const std::string& name, const std::vector<double>& value, const std::string& value_origin, bool free,
                 const std::string& free_reason, int stage);
  // The stream entry's first keys: model and source.
  Node StreamNode(const std::string& name, const std::string& comment, const std::string& model,
                  const std::string& model_origin, const Stream& source);
  void AddNoise(Node* stream, const std::string& key, const Noise& noise);
  // The mounting's lever arm and misalignment of a sensor as fixed or free parameters of <name>.
  void MountingParameters(const std::string& name, const Stream& s, bool lever_arm, bool free, const std::string& why,
                          int stage);
  std::vector<double> LeverArm(const Stream& s, std::string* origin) const;
  std::vector<double> Rotation(const Stream& s, std::string* origin) const;

  Status ChooseMaster();
  Status AddWheels(const Stream& s);
  Status AddWheelGeometry(const Stream& s, const std::string& model, const std::string& param_prefix);
  Status AddAckermann(const Stream& s);
  Status AddTricycle(const Stream& s);
  const Stream* FirstSteering() const;
  Result<double> PositiveGeometry(const std::string& key, const std::string& model) const;
  Noise WheelRateNoise(const Stream& s) const;
  Result<double> WheelRadius(const Stream& s, const std::string& model, std::string* origin) const;
  void AddVelocity(const Stream& s, bool master);
  void AddImu(const Stream& s, bool gyroscope, bool accelerometer);
  void AddGps(const Stream& s);
  void AddPose(const Stream& s);
  void AddOthers();

  const Recording& rec_;
  std::string rec_name_, kind_, kind_origin_;
  const Stream* master_ = nullptr;
  std::string master_name_;
  bool imu_master_ = false;     // no odometric stream: the IMU's gyroscope creates the poses
  std::string gyroscope_name_;  // the last gyroscope stream added
  std::set<const Stream*> used_;
  std::set<std::string> used_names_;
  std::vector<Node> streams_, parameters_;
  std::vector<std::string> stages_[2];
  std::vector<std::string> left_out_;
};

void Builder::Parameter(const std::string& name, const std::vector<double>& value, const std::string& value_origin,
                        bool free, const std::string& free_reason, int stage) {
  static const std::map<std::string, std::string> what = {
      {"radius", "wheel radius [m]"},
      {"baseline", "distance between the wheels' contact points [m]"},
      {"distance", "the wheels' distance from the centre [m]"},
      {"lx_plus_ly", "half length plus half width [m]"},
      {"kv_over_L", "speed scale over the wheelbase [1/m]"},
      {"k_theta", "steering gain"},
      {"k_gamma", "steering offset [rad]"},
      {"misalignment", "rotation of the sensor frame into O [w, x, y, z]"},
      {"lever_arm", "position of the sensor in O [m]"},
      {"bias", "gyroscope bias [rad/s]"}};
  const auto slot = what.find(name.substr(name.rfind('.') + 1));
  Node p{Name(name), slot != what.end() ? slot->second : std::string("a calibration parameter"), "", {}};
  p.children.push_back({"value", value_origin, List(value), {}});
  p.children.push_back({"free", free_reason, free ? "true" : "false", {}});
  parameters_.push_back(p);
  if (free) stages_[stage].push_back(name);
}

Node Builder::StreamNode(const std::string& name, const std::string& comment, const std::string& model,
                         const std::string& model_origin, const Stream& source) {
  used_.insert(&source);
  Node n{Name(name), comment, "", {}};
  n.children.push_back({"model", model_origin, model, {}});
  n.children.push_back({"source",
                        "the recording's stream '" + source.info.name + "' (" + TypeName(source) + ", " +
                            Number(source.info.rate_hz) + " Hz)",
                        Name(source.info.name),
                        {}});
  return n;
}

void Builder::AddNoise(Node* stream, const std::string& key, const Noise& noise) {
  auto it =
      std::find_if(stream->children.begin(), stream->children.end(), [](const Node& n) { return n.key == "noise"; });
  if (it == stream->children.end()) {
    stream->children.push_back({"noise", "the measurement noise, one sigma per row kind", "", {}});
    it = stream->children.end() - 1;
  }
  it->children.push_back({key, noise.origin, Number(noise.value), {}});
}

std::vector<double> Builder::LeverArm(const Stream& s, std::string* origin) const {
  if (!s.info.mounting) {
    *origin = "no mounting stated for '" + s.info.name + "' in recording.yaml: at O";
    return {0.0, 0.0, 0.0};
  }
  *origin = "from " + Where(s.info.name + ".mounting.p_body_sensor_m");
  const Eigen::Vector3d& p = s.info.mounting->p_body_sensor;
  return {p.x(), p.y(), p.z()};
}

std::vector<double> Builder::Rotation(const Stream& s, std::string* origin) const {
  if (!s.info.mounting) {
    *origin = "no mounting stated for '" + s.info.name + "' in recording.yaml: aligned with O [w, x, y, z]";
    return {1.0, 0.0, 0.0, 0.0};
  }
  *origin = "from " + Where(s.info.name + ".mounting.q_body_sensor_wxyz");
  const Eigen::Quaterniond q = s.info.mounting->q_body_sensor.normalized();
  return {q.w(), q.x(), q.y(), q.z()};
}

void Builder::MountingParameters(const std::string& name, const Stream& s, bool lever_arm, bool free,
                                 const std::string& why, int stage) {
  std::string origin;
  if (lever_arm) {
    const std::vector<double> p = LeverArm(s, &origin);
    Parameter(name + ".lever_arm", p, origin, free, why, stage);
  }
  const std::vector<double> q = Rotation(s, &origin);
  Parameter(name + ".misalignment", q, origin, free, why, stage);
}

const std::map<std::string, std::string>& WheelModels() {
  static const std::map<std::string, std::string> models = {{"differential_drive", "differential_drive"},
                                                            {"skid_steer", "differential_drive"},
                                                            {"omni3", "omni3_drive"},
                                                            {"mecanum", "mecanum_drive"},
                                                            {"omni4", "omni4_drive"},
                                                            {"tricycle", "tricycle_drive"},
                                                            {"ackermann", "ackermann"}};
  return models;
}

// The master: the wheel encoders under the platform's model, else an odometry, else a visual odometry or scan
// matcher as an odometer.
Status Builder::ChooseMaster() {
  const auto model = WheelModels().find(kind_);
  for (const Stream& s : rec_.streams) {
    if (s.info.type != StreamType::kWheelEncoders || master_) continue;
    if (model == WheelModels().end()) {
      LeaveOut(s, "no wheel model for platform kind '" + kind_ + "' (give --platform KIND)");
      used_.insert(&s);
      continue;
    }
    if (model->second == "ackermann") return AddAckermann(s);
    return model->second == "tricycle_drive" ? AddTricycle(s) : AddWheels(s);
  }
  for (StreamType type : {StreamType::kOdometry, StreamType::kVisualOdometry, StreamType::kScanMatching})
    for (const Stream& s : rec_.streams)
      if (s.info.type == type && !master_) AddVelocity(s, true);
  if (master_) return Status::Ok();
  // No odometric stream: an IMU creates a pose at each of its samples (the IMU master); not when wheel encoders are
  // there without a model for the kind (--platform names one).
  for (const Stream& s : rec_.streams) {
    if (s.info.type != StreamType::kImu || master_ || !left_out_.empty()) continue;
    imu_master_ = true;
    AddImu(s, true, true);
    used_.insert(&s);
    master_ = &s;
    master_name_ = gyroscope_name_;
  }
  if (master_) return Status::Ok();
  const std::string wheels = left_out_.empty() ? std::string()
                                               : " (" + left_out_.front().substr(0, left_out_.front().find(' ')) +
                                                     ": no wheel model for platform kind '" + kind_ + "')";
  return Status::Error(
      rec_name_ +
      ": no stream can make the poses: the master needs wheel_encoders of platform kind "
      "differential_drive, skid_steer, omni3, omni4, mecanum, tricycle or ackermann (--platform KIND)" +
      wheels + ", odometry, visual_odometry, scan_matching or an imu");
}

Status Builder::AddWheels(const Stream& s) {
  const std::string model = WheelModels().at(kind_);
  const std::string name = UniqueName(s.info.name);
  const std::size_t wheels = model == "differential_drive" ? 2 : model == "omni3_drive" ? 3 : 4;
  if (s.info.columns.size() != wheels || s.info.units != "rad")
    return Status::Error(rec_name_ + ": stream '" + s.info.name + "': the " + model + " model of platform kind '" +
                         kind_ + "' needs " + std::to_string(wheels) + " wheel angle columns in rad, found " +
                         std::to_string(s.info.columns.size()) + " in " + (s.info.units.empty() ? "?" : s.info.units));
  Node n = StreamNode(name, "the master: the wheel encoders create the poses", model,
                      "platform kind '" + kind_ + "' (" + kind_origin_ + ")", s);
  const bool skid = kind_ == "skid_steer";
  AddNoise(&n, "wheel_radps", WheelRateNoise(s));
  const double slack = skid ? 0.1 : 0.02;
  const std::string slack_why = skid ? "default: a skid-steer platform slides sideways as it turns"
                                     : "default: the casters and soft contacts let O move a little (0.02 m/s)";
  if (model == "differential_drive") AddNoise(&n, "lateral_mps", {slack, slack_why});
  AddNoise(&n, "vertical_mps", {slack, slack_why});
  AddNoise(&n, "tilt_radps", {0.1, "default: roll and pitch rates of a chassis rocking on its wheels (0.1 rad/s)"});
  Node slots{"parameters", "one radius shared by all wheels: the odometry's scale", "", {}};
  const std::vector<std::string> radii =
      model == "differential_drive" ? std::vector<std::string>{"radius_left", "radius_right"}
      : model == "omni3_drive"      ? std::vector<std::string>{"radius_0", "radius_1", "radius_2"}
                                    : std::vector<std::string>{"radius_0", "radius_1", "radius_2", "radius_3"};
  for (const std::string& slot : radii)
    slots.children.push_back({slot, "the shared radius " + name + ".radius", Name(name + ".radius"), {}});
  n.children.push_back(slots);
  streams_.push_back(n);
  master_ = &s;
  master_name_ = name;
  return AddWheelGeometry(s, model, name);
}

// Wheel-rate noise: the stated one, else one tick of quantization on each end of a sample period (sigma q / sqrt(6)
// per angle difference, over 1 / rate_hz) when the angles were counted in ticks, else a default.
Noise Builder::WheelRateNoise(const Stream& s) const {
  const auto ticks = s.info.attributes.find("ticks_per_revolution");
  const bool skid = kind_ == "skid_steer";
  Noise wheel = StatedNoise(rec_name_, s.info, {"wheel_radps", "sigma_radps"}, skid ? 0.3 : 0.15,
                            skid ? "skid-steer wheel speeds are a loose measure of the body's motion (0.3 rad/s)"
                                 : "0.15 rad/s, as configs/indoor_diffdrive_tracking.yaml");
  // ticks_per_revolution 1 states revolutions (a log of fractional wheel turns), not counted ticks: no quantization.
  if (wheel.origin.rfind("default", 0) == 0 && ticks != s.info.attributes.end() && ticks->second > 1.0 &&
      s.info.rate_hz > 0.0) {
    wheel = {2.0 * kPi / ticks->second * s.info.rate_hz / std::sqrt(6.0),
             "quantization of " + Where(s.info.name + ".attributes.ticks_per_revolution") + " = " +
                 Number(ticks->second) + " over 1 / rate_hz = 1 / " + Number(s.info.rate_hz) +
                 " s: 2 pi / ticks * rate_hz / sqrt(6)"};
  }
  return wheel;
}

// The nominal wheel radius from the platform geometry: wheel_radius_m, else the mean of wheel_radius_<column>_m.
Result<double> Builder::WheelRadius(const Stream& s, const std::string& model, std::string* origin) const {
  const std::map<std::string, double>& g = rec_.platform.geometry;
  double radius = 0.0;
  if (g.count("wheel_radius_m")) {
    radius = g.at("wheel_radius_m");
    *origin = "from " + Where("platform.geometry.wheel_radius_m");
  } else {
    std::vector<std::string> keys;
    for (const std::string& column : s.info.columns) {
      const std::string key = "wheel_radius_" + column + "_m";
      if (!g.count(key)) break;
      radius += g.at(key) / static_cast<double>(s.info.columns.size());
      keys.push_back(key);
    }
    if (keys.size() != s.info.columns.size())
      return Status::Error(rec_name_ +
                           "/recording.yaml: platform.geometry has no wheel_radius_m (nor "
                           "wheel_radius_<wheel>_m for every column of '" +
                           s.info.name + "') for the " + model + " model");
    *origin = "mean of " + Where("platform.geometry");
    for (const std::string& key : keys) *origin += " " + key;
  }
  if (!(radius > 0.0))
    return Status::Error(rec_name_ + "/recording.yaml: platform.geometry: wheel radius must be positive");
  return radius;
}

// The radius (free) and the yaw lever arm (fixed) of a wheel model from the platform geometry.
Status Builder::AddWheelGeometry(const Stream& s, const std::string& model, const std::string& name) {
  const std::map<std::string, double>& g = rec_.platform.geometry;
  std::string origin;
  const Result<double> radius = WheelRadius(s, model, &origin);
  if (!radius.ok()) return radius.status();
  Parameter(name + ".radius", {radius.value()}, origin, true, "free: the odometry's scale, self-calibrated", 1);
  // The yaw lever arm's slot and the geometry keys it is read from: the first of the alternatives, or their sum.
  struct YawLever {
    std::string slot;
    std::vector<std::string> keys;
    bool sum;
    std::string described;
  };
  const YawLever lever =
      model == "omni3_drive" ? YawLever{"distance", {"wheel_distance_m"}, false, "wheel_distance_m"}
      : model == "mecanum_drive"
          ? YawLever{"lx_plus_ly", {"half_length_m", "half_width_m"}, true, "half_length_m and half_width_m"}
      : model == "omni4_drive"
          ? YawLever{"wheelbase_plus_track", {"wheelbase_m", "track_m"}, true, "wheelbase_m and track_m"}
          : YawLever{"baseline", {"baseline_m", "track_m"}, false, "baseline_m or track_m"};
  double value = 0.0;
  std::string used;
  std::size_t found = 0;
  for (const std::string& key : lever.keys) {
    if (!g.count(key) || (!lever.sum && found > 0)) continue;
    value += g.at(key);
    used += (used.empty() ? "" : " + ") + key;
    ++found;
  }
  if (found == 0 || (lever.sum && found != lever.keys.size()) || !(value > 0.0))
    return Status::Error(rec_name_ + "/recording.yaml: platform.geometry has no positive " + lever.described +
                         " for the " + model + " model");
  const std::string slot = lever.slot;
  Parameter(name + "." + slot, {value}, "from " + Where("platform.geometry." + used), false,
            "fixed: the yaw lever arm is believed (with one free radius it trades with the yaw reference's scale)", 1);
  return Status::Ok();
}

// The recording's first steering stream, or null.
const Stream* Builder::FirstSteering() const {
  for (const Stream& t : rec_.streams)
    if (t.info.type == StreamType::kSteering) return &t;
  return nullptr;
}

// A positive platform geometry value the model needs.
Result<double> Builder::PositiveGeometry(const std::string& key, const std::string& model) const {
  const auto it = rec_.platform.geometry.find(key);
  if (it == rec_.platform.geometry.end() || !(it->second > 0.0))
    return Status::Error(rec_name_ + "/recording.yaml: platform.geometry has no positive " + key + " for the " + model +
                         " model");
  return it->second;
}

// The tricycle: the steered, driven front wheel's angle and its steering angle. The radius and the steering offset
// free, the wheel-to-axle distance believed (on a drive of nearly constant steering it trades with the offset).
Status Builder::AddTricycle(const Stream& s) {
  const Stream* steering = FirstSteering();
  if (!steering || s.info.columns.size() != 1 || s.info.units != "rad")
    return Status::Error(rec_name_ + ": stream '" + s.info.name +
                         "': the tricycle_drive model of platform kind 'tricycle' needs one wheel angle column in rad "
                         "and a steering stream");
  const Result<double> axle = PositiveGeometry("wheel_to_axle_m", "tricycle_drive");
  if (!axle.ok()) return axle.status();
  std::string origin;
  const Result<double> radius = WheelRadius(s, "tricycle_drive", &origin);
  if (!radius.ok()) return radius.status();
  const std::string name = UniqueName(s.info.name);
  Node n = StreamNode(name, "the master: the front wheel's angle and its steering create the poses", "tricycle_drive",
                      "platform kind 'tricycle' (" + kind_origin_ + ")", s);
  used_.insert(steering);
  n.children.back() = {
      "source",
      "wheel: the recording's '" + s.info.name + "' (rad), steering: its '" + steering->info.name + "'",
      "{wheel: " + Name(s.info.name) + ", steering: " + Name(steering->info.name) + "}",
      {}};
  AddNoise(&n, "wheel_radps", WheelRateNoise(s));
  AddNoise(&n, "steering_rad", StatedNoise(rec_name_, steering->info, {"sigma_rad"}, 0.01, "0.01 rad"));
  const std::string slack_why = "default: the rear wheels' soft contacts let O move a little (0.02 m/s)";
  AddNoise(&n, "lateral_mps", {0.02, slack_why});
  AddNoise(&n, "vertical_mps", {0.02, slack_why});
  AddNoise(&n, "tilt_radps", {0.1, "default: roll and pitch rates of a chassis rocking on its wheels (0.1 rad/s)"});
  streams_.push_back(n);
  master_ = &s;
  master_name_ = name;
  Parameter(name + ".radius", {radius.value()}, origin, true, "free: the odometry's scale, self-calibrated", 1);
  Parameter(name + ".wheel_to_axle", {axle.value()}, "from " + Where("platform.geometry.wheel_to_axle_m"), false,
            "fixed: the wheel-to-axle distance is believed (it trades with the steering offset on steady turns)", 1);
  const auto offset = rec_.platform.geometry.find("steering_offset_rad");
  const bool stated = offset != rec_.platform.geometry.end();
  Parameter(name + ".steering_offset", {stated ? offset->second : 0.0},
            stated ? "from " + Where("platform.geometry.steering_offset_rad") : "default: no steering offset [rad]",
            true, "free: the steering sensor's zero, self-calibrated", 1);
  return Status::Ok();
}

Status Builder::AddAckermann(const Stream& s) {
  const Stream* steering = FirstSteering();
  if (!steering || s.info.units != "m/s")
    return Status::Error(rec_name_ + ": stream '" + s.info.name +
                         "': the ackermann model of platform kind 'ackermann' needs the wheel speed in m/s and a "
                         "steering stream");
  const Result<double> wheelbase = PositiveGeometry("wheelbase_m", "ackermann");
  if (!wheelbase.ok()) return wheelbase.status();
  const std::string name = UniqueName(s.info.name);
  Node n = StreamNode(name, "the master: the rear wheel speed and the steering angle create the poses", "ackermann",
                      "platform kind 'ackermann' (" + kind_origin_ + ")", s);
  used_.insert(steering);
  n.children.back() = {
      "source",
      "speed: the recording's '" + s.info.name + "' (m/s), steering: its '" + steering->info.name + "'",
      "{speed: " + Name(s.info.name) + ", steering: " + Name(steering->info.name) + "}",
      {}};
  AddNoise(&n, "speed_mps", StatedNoise(rec_name_, s.info, {"sigma_mps"}, 0.05, "0.05 m/s"));
  AddNoise(&n, "steering_rad", StatedNoise(rec_name_, steering->info, {"sigma_rad"}, 0.02, "0.02 rad"));
  AddNoise(&n, "lateral_mps", {0.02, "default: eq. 15's no side slip on a suspended vehicle (0.02 m/s)"});
  AddNoise(&n, "vertical_mps", {0.1, "default: eq. 15's no vertical motion on a suspended vehicle (0.1 m/s)"});
  n.children.push_back({"options", "the wheelbase", "", {}});
  n.children.back().children.push_back(
      {"wheelbase_m", "from " + Where("platform.geometry.wheelbase_m"), Number(wheelbase.value()), {}});
  streams_.push_back(n);
  master_ = &s;
  master_name_ = name;
  Parameter(name + ".kv_over_L", {1.0 / wheelbase.value()}, "1 / platform.geometry.wheelbase_m (k_v = 1)", true,
            "free: the speed scale over the wheelbase, self-calibrated", 1);
  Parameter(name + ".k_theta", {1.0}, "default: the steering sensor's gain 1", true,
            "free: the steering gain, self-calibrated", 1);
  Parameter(name + ".k_gamma", {0.0}, "default: the steering sensor's zero", false,
            "fixed: the handlebar sensor's zero is believed", 1);
  return Status::Ok();
}

// odometry, visual_odometry, scan_matching: odometer as the master, else relative_motion (interval sensors) or
// linear_velocity (odometry).
void Builder::AddVelocity(const Stream& s, bool master) {
  const bool odometry = s.info.type == StreamType::kOdometry;
  const std::string model = master ? "odometer" : odometry ? "linear_velocity" : "relative_motion";
  const std::string name = UniqueName(s.info.name);
  const std::string why = master ? "the master: no wheel model, so this velocity stream creates the poses (eqs. 5-8)"
                          : odometry
                              ? "a velocity sensor beside the master: its linear velocity"
                              : "a velocity measured over an interval, between the master poses nearest its ends";
  Node n = StreamNode(name, why, model, "stream type " + TypeName(s), s);
  if (model == "linear_velocity") {
    AddNoise(&n, "sigma_mps", StatedNoise(rec_name_, s.info, {"sigma_mps", "linear_mps"}, 0.05, "0.05 m/s"));
  } else {
    AddNoise(&n, "linear_mps", StatedNoise(rec_name_, s.info, {"linear_mps", "sigma_mps"}, 0.05, "0.05 m/s"));
    AddNoise(&n, "angular_radps", StatedNoise(rec_name_, s.info, {"angular_radps", "sigma_radps"}, 0.05, "0.05 rad/s"));
  }
  streams_.push_back(n);
  if (master) {
    master_ = &s;
    master_name_ = name;
  }
  MountingParameters(name, s, true, false, "fixed: the sensor's mounting is believed", 0);
}

// An imu (gyroscope and accelerometer sharing its misalignment) or a lone gyroscope or accelerometer stream.
void Builder::AddImu(const Stream& s, bool gyroscope, bool accelerometer) {
  const bool both = gyroscope && accelerometer;
  const std::string misalignment = s.info.name + ".misalignment";
  std::string origin;
  const std::vector<double> q = Rotation(s, &origin);
  if (imu_master_) {
    Parameter(misalignment, q, origin, false,
              "fixed: with the IMU the only motion sensor its attitude on the body is a gauge freedom", 0);
  } else {
    Parameter(misalignment, q, origin, true, "free: the IMU's attitude on the body, self-calibrated", 0);
  }
  if (gyroscope) {
    const std::string name = UniqueName(both ? std::string("gyroscope") : s.info.name);
    gyroscope_name_ = name;
    Node n = StreamNode(name, "the turn rates", "gyroscope", "stream type " + TypeName(s), s);
    AddNoise(&n, "sigma_radps",
             StatedNoise(rec_name_, s.info, {"gyro_sigma_radps", "sigma_radps"}, 0.02, "0.02 rad/s"));
    n.children.push_back({"parameters", "the misalignment shared by the IMU's streams", "", {}});
    n.children.back().children.push_back(
        {"misalignment", "the IMU's misalignment " + misalignment, Name(misalignment), {}});
    streams_.push_back(n);
    Parameter(name + ".bias", {0.0, 0.0, 0.0}, "default: no bias [rad/s]", true,
              "free: a constant gyroscope bias, self-calibrated", 1);
  }
  if (accelerometer) {
    const std::string name = UniqueName(both ? std::string("accelerometer") : s.info.name);
    Node n = StreamNode(name, "the specific force", "accelerometer", "stream type " + TypeName(s), s);
    Noise noise = StatedNoise(rec_name_, s.info, {"accel_sigma_mps2", "sigma_mps2"}, kVehicleAccelFloorMps2,
                              "0.5 m/s^2 (a chassis' vibration over the sensor's own noise)");
    // A stated noise is the sensor's own white noise; on a vehicle the chassis' vibration and the second difference
    // of the pose grid the model compares with are far larger, and a fit at the sensor's noise lets the accelerometer
    // pull the wheel radii and the misalignment away (the Husky's stated 0.098 m/s^2 gives chi2/dof about 25).
    if (master_ && noise.value < kVehicleAccelFloorMps2) {
      noise = {kVehicleAccelFloorMps2, noise.origin + ", raised to 0.5 m/s^2: a vehicle's vibration floor"};
    }
    AddNoise(&n, "sigma_mps2", noise);
    n.children.push_back({"parameters", "the misalignment shared by the IMU's streams", "", {}});
    n.children.back().children.push_back(
        {"misalignment", "the IMU's misalignment " + misalignment, Name(misalignment), {}});
    streams_.push_back(n);
    const std::vector<double> p = LeverArm(s, &origin);
    Parameter(name + ".lever_arm", p, origin, false, "fixed: the IMU's position on the body is believed", 0);
  }
}

void Builder::AddGps(const Stream& s) {
  const bool gps = s.info.type == StreamType::kGps;
  const std::string name = UniqueName(s.info.name);
  Node n = StreamNode(name, gps ? "the position fixes (ENU about the recording's origin)" : "the absolute positions",
                      "gps", "stream type " + TypeName(s), s);
  AddNoise(&n, "sigma_m",
           StatedNoise(rec_name_, s.info, {"sigma_m"}, gps ? 1.0 : 0.01, gps ? "1 m (a single GPS fix)" : "0.01 m"));
  streams_.push_back(n);
  std::string origin;
  const std::vector<double> p = LeverArm(s, &origin);
  // Free on a vehicle driving over relief (the seed's ATV, configs/atv_calibration.yaml); on a robot that moves in a
  // plane its height is unobservable and the rest trades with the IMU's misalignment, so it is believed there (as
  // gap/nominal_config.h does for the holonomic robots).
  if (kind_ == "ackermann") {
    Parameter(name + ".lever_arm", p, origin, true, "free: the antenna's position on the body, self-calibrated", 0);
  } else {
    Parameter(name + ".lever_arm", p, origin, false,
              "fixed: on a platform moving in a plane ('" + kind_ +
                  "') the antenna's height is unobservable and its horizontal offset trades with the IMU's yaw",
              0);
  }
}

void Builder::AddPose(const Stream& s) {
  const std::string name = UniqueName(s.info.name);
  Node n = StreamNode(name, "the absolute reference the rest is calibrated against (not read as truth)",
                      "absolute_pose", "stream type pose", s);
  AddNoise(&n, "position_m", StatedNoise(rec_name_, s.info, {"position_m", "sigma_m"}, 0.01, "0.01 m"));
  AddNoise(&n, "orientation_rad", StatedNoise(rec_name_, s.info, {"orientation_rad", "sigma_rad"}, 0.01, "0.01 rad"));
  streams_.push_back(n);
  MountingParameters(name, s, true, false, "fixed: the reference's mounting frames the calibration", 0);
}

// The streams beside the master, and those left out with their reason.
void Builder::AddOthers() {
  const bool derived_wheels = master_ && master_->info.attributes.count("derived_from_odometry") &&
                              master_->info.attributes.at("derived_from_odometry") != 0.0;
  for (const Stream& s : rec_.streams) {
    if (used_.count(&s)) continue;
    switch (s.info.type) {
      case StreamType::kOdometry:
        if (derived_wheels) {
          LeaveOut(s, "the master '" + master_->info.name + "' was derived from it (attribute derived_from_odometry)");
        } else {
          AddVelocity(s, false);
        }
        break;
      case StreamType::kVisualOdometry:
      case StreamType::kScanMatching:
        AddVelocity(s, false);
        break;
      case StreamType::kImu:
        AddImu(s, true, true);
        break;
      case StreamType::kGyroscope:
        AddImu(s, true, false);
        break;
      case StreamType::kAccelerometer:
        AddImu(s, false, true);
        break;
      case StreamType::kGps:
      case StreamType::kPosition:
        AddGps(s);
        break;
      case StreamType::kPose:
        if (const Stream* odometry = recording::PosedOdometry(rec_, s)) {
          LeaveOut(s, "the pose of the odometry '" + odometry->info.name +
                          "' (an importer's <odometry>_pose): dead-reckoned in its parent frame, not an absolute "
                          "reference");
        } else {
          AddPose(s);
        }
        break;
      case StreamType::kMagnetometer:
        LeaveOut(s,
                 "the magnetometer model needs the field in W (options.field_world), which the recording does "
                 "not state");
        break;
      case StreamType::kCamera:
      case StreamType::kLaserScan:
        LeaveOut(s, "raw sensor data: run `roamlab frontend` for a velocity stream the estimator reads");
        break;
      case StreamType::kWheelEncoders:
        LeaveOut(s, "one wheel stream is the master ('" + master_->info.name + "')");
        break;
      case StreamType::kSteering:
      case StreamType::kInputs:
        LeaveOut(s, "no model reads it here");
        break;
    }
  }
}

Status Builder::Build() {
  if (Status s = ChooseMaster(); !s.ok()) return s;
  AddOthers();
  return Status::Ok();
}

std::string Builder::Yaml() const {
  std::ostringstream out;
  Comment("Nominal estimator configuration of " + rec_name_ +
              ", written by `roamlab init` from what its recording.yaml " + "states (platform kind '" + kind_ + "', " +
              kind_origin_ +
              "). The comment above each key says where its value came from. Edit it before trusting it: the " +
              "defaults are generic.",
          "", &out);
  for (const std::string& line : left_out_) Comment("Left out: " + line, "", &out);
  Emit({"master",
        imu_master_ ? "the IMU's gyroscope creates a pose at each IMU sample (no odometric stream: IMU master)"
                    : "the odometric stream that creates the pose nodes",
        Name(master_name_),
        {}},
       0, &out);
  Node solver{
      "solver", "the batch solves, as the simulated robots' nominal configurations (gap/nominal_config.h)", "", {}};
  solver.children = {{"method", "default: damped Gauss-Newton", "levenberg_marquardt", {}},
                     {"max_iterations", "nominal: up to 100 iterations per stage", "100", {}},
                     {"function_tolerance", "nominal: stop below a 1e-10 relative cost decrease", "1.0e-10", {}}};
  Emit(solver, 0, &out);
  Node parameters{"parameters", "the calibration: a parameter not listed keeps its model default and is fixed", "",
                  parameters_};
  if (!parameters_.empty()) Emit(parameters, 0, &out);
  Emit({"streams", "one entry per recording stream the estimator reads", "", streams_}, 0, &out);
  std::vector<std::vector<std::string>> stages;
  if (!stages_[0].empty() && !stages_[1].empty()) {
    std::vector<std::string> all = stages_[0];
    all.insert(all.end(), stages_[1].begin(), stages_[1].end());
    stages = {stages_[0], stages_[1], all};
  } else if (!stages_[0].empty() || !stages_[1].empty()) {
    stages = {stages_[0].empty() ? stages_[1] : stages_[0]};
  }
  if (stages.empty()) return out.str();
  Node stage_node{"stages", "the free parameters, staged as configs/atv_calibration.yaml", "", {}};
  const char* why[] = {"the lever arms and misalignments first", "then the odometric gains and biases",
                       "then all jointly"};
  for (std::size_t i = 0; i < stages.size(); ++i)
    stage_node.children.push_back(
        {"", stages.size() == 1 ? "every free parameter in one stage" : why[i], NameList(stages[i]), {}});
  Emit(stage_node, 0, &out);
  return out.str();
}

}  // namespace

const std::vector<std::string>& InitPlatformKinds() {
  static const std::vector<std::string> kinds = [] {
    std::vector<std::string> k;
    for (const auto& [kind, model] : WheelModels()) k.push_back(kind);
    return k;
  }();
  return kinds;
}

Result<InitConfig> NominalConfigFromRecording(const recording::Recording& recording, const std::string& recording_path,
                                              const std::string& platform_kind) {
  if (!platform_kind.empty() && !WheelModels().count(platform_kind)) {
    std::string known;
    for (const std::string& k : InitPlatformKinds()) known += (known.empty() ? "" : ", ") + k;
    return Status::Error("--platform '" + platform_kind + "': unknown platform kind (known: " + known + ")");
  }
  const std::string kind = platform_kind.empty() ? recording.platform.kind : platform_kind;
  Builder builder(recording, recording_path, kind,
                  platform_kind.empty() ? "from recording.yaml platform.kind" : "from --platform");
  if (Status s = builder.Build(); !s.ok()) return s;
  InitConfig result;
  result.yaml = builder.Yaml();
  result.platform_kind = kind;
  result.left_out = builder.left_out();
  // Never hand out what the estimator would refuse: parse it back and bind it to the recording.
  auto parsed = estimator::ParseEstimatorConfig(result.yaml, recording_path + " (roamlab init)");
  if (!parsed.ok()) return Status::Error("the written configuration does not load: " + parsed.status().message());
  auto bound = estimator::ProblemBuilder::Create(parsed.value(), recording);
  if (!bound.ok())
    return Status::Error("the written configuration does not fit the recording: " + bound.status().message());
  result.config = std::move(parsed).value();
  return result;
}

Outcome InitToFile(const InitRequest& request, InitConfig* result) {
  recording::ReadOptions read;
  read.load_ground_truth = false;
  auto rec = recording::ReadRecording(request.recording, read);
  if (!rec.ok()) return Outcome::BadInput(rec.status());
  auto config = NominalConfigFromRecording(rec.value(), request.recording, request.platform_kind);
  if (!config.ok()) return Outcome::BadInput(config.status());
  const std::filesystem::path out(request.out);
  if (out.has_parent_path())
    if (Status s = MakeOutputDirectory(out.parent_path().string()); !s.ok()) return Outcome::BadInput(s);
  if (Status s = WriteFileAtomic(request.out, config.value().yaml); !s.ok()) return Outcome::Failed(s);
  config.value().config.source_file = request.out;
  if (result) *result = std::move(config).value();
  return Outcome::Ok();
}

}  // namespace roamlab::experiment
