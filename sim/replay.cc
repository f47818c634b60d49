#include "sim/replay.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <utility>

#include <GeographicLib/LocalCartesian.hpp>

#include "eval/alignment.h"
#include "recording/odometry_pose.h"
#include "sim/wheeled_robot.h"

namespace roamlab::sim {

namespace {

// The row of `values` at `t_at` (stamps `t`): held or linear between rows, the first before, the last after.
Eigen::VectorXd Interpolate(const std::vector<Time>& t, const Eigen::MatrixXd& values, Time t_at, bool hold) {
  const auto after = std::upper_bound(t.begin(), t.end(), t_at);
  if (after == t.begin()) return values.row(0).transpose();
  const auto k = static_cast<Eigen::Index>(after - t.begin()) - 1;
  if (after == t.end() || hold) return values.row(k).transpose();
  const double a = SecondsBetween(t[static_cast<std::size_t>(k)], t_at) /
                   SecondsBetween(t[static_cast<std::size_t>(k)], t[static_cast<std::size_t>(k) + 1]);
  return ((1.0 - a) * values.row(k) + a * values.row(k + 1)).transpose();
}

}  // namespace

Eigen::VectorXd DriveInputs::At(Time t_at) const { return Interpolate(t, values, t_at, hold); }
Eigen::VectorXd DriveInputs::AnglesAt(Time t_at) const { return Interpolate(t, angles_rad, t_at, false); }
double DriveInputs::TravelAt(Time t_at) const { return Interpolate(t, travel_m, t_at, false)[0]; }

namespace {

using recording::Recording;
using recording::Stream;
using recording::StreamType;

constexpr double kDefaultTicksPerRevolution = 2048.0;
constexpr double kPi = 3.14159265358979323846;

std::string Join(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& item : items) out += (out.empty() ? "" : ", ") + item;
  return out;
}

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

int ColumnIndex(const recording::StreamInfo& info, const std::string& name) {
  const auto it = std::find(info.columns.begin(), info.columns.end(), name);
  return it == info.columns.end() ? -1 : static_cast<int>(it - info.columns.begin());
}

bool IsAngleEncoder(const Stream& s) { return s.info.units.empty() || s.info.units == "rad"; }

// The rows of `s` within the centred window of row k: [first, last], at least one neighbour when there is one.
std::pair<std::size_t, std::size_t> WindowRows(const Stream& s, std::size_t k) {
  const std::int64_t half_ns = std::llround(kRateHalfWindowS * 1e9);
  const std::int64_t t_ns = s.t[k].nanoseconds();
  std::size_t first = k, last = k;
  while (first > 0 && s.t[first - 1].nanoseconds() >= t_ns - half_ns) --first;
  while (last + 1 < s.t.size() && s.t[last + 1].nanoseconds() <= t_ns + half_ns) ++last;
  if (first == last) {
    if (first > 0) --first;
    if (last + 1 < s.t.size()) ++last;
  }
  return {first, last};
}

// Per row, the mean rate of each column over the row's window (a derivative of cumulative angles).
Eigen::MatrixXd WindowRates(const Stream& s) {
  Eigen::MatrixXd rates = Eigen::MatrixXd::Zero(s.values.rows(), s.values.cols());
  for (std::size_t k = 0; k < s.t.size(); ++k) {
    const auto [first, last] = WindowRows(s, k);
    if (first == last) continue;
    const double dt = SecondsBetween(s.t[first], s.t[last]);
    rates.row(static_cast<Eigen::Index>(k)) =
        (s.values.row(static_cast<Eigen::Index>(last)) - s.values.row(static_cast<Eigen::Index>(first))) / dt;
  }
  return rates;
}

// Per row, the mean of column `c` over the row's window.
Eigen::VectorXd WindowMeans(const Stream& s, int c) {
  Eigen::VectorXd means(s.values.rows());
  for (std::size_t k = 0; k < s.t.size(); ++k) {
    const auto [first, last] = WindowRows(s, k);
    means[static_cast<Eigen::Index>(k)] =
        s.values.col(c).segment(static_cast<Eigen::Index>(first), static_cast<Eigen::Index>(last - first + 1)).mean();
  }
  return means;
}

// What the recording's drive inputs can be: absent (nullopt), present (the inputs) or present and unusable (error).
using Found = Result<std::optional<DriveInputs>>;

// 1. Recorded commands, with the driver's columns.
Found FromInputsStream(const Recording& real, bool ackermann, std::string* note) {
  const std::vector<std::string> needed = ackermann
                                              ? std::vector<std::string>{"speed_mps", "handlebar_rad"}
                                              : std::vector<std::string>{"linear_mps", "lateral_mps", "angular_radps"};
  for (const Stream& s : real.streams) {
    if (s.info.type != StreamType::kInputs || s.t.empty()) continue;
    std::vector<int> columns;
    for (const std::string& name : needed) columns.push_back(ColumnIndex(s.info, name));
    const bool usable = ackermann ? columns[0] >= 0 && columns[1] >= 0 : columns[0] >= 0 && columns[2] >= 0;
    if (!usable) {
      *note = "; inputs stream '" + s.info.name + "' has columns " + Join(s.info.columns);
      continue;
    }
    DriveInputs in;
    in.kind = ackermann ? DriveInputs::Kind::kAckermann : DriveInputs::Kind::kBodyVelocity;
    in.t = s.t;
    in.hold = true;
    in.source = "inputs stream '" + s.info.name + "'";
    in.streams = {s.info.name};
    in.values = Eigen::MatrixXd::Zero(s.values.rows(), static_cast<Eigen::Index>(needed.size()));
    for (std::size_t j = 0; j < needed.size(); ++j)
      if (columns[j] >= 0) in.values.col(static_cast<Eigen::Index>(j)) = s.values.col(columns[j]);
    return std::optional<DriveInputs>(std::move(in));
  }
  return std::optional<DriveInputs>();
}

// The name of each model wheel, in wheel index order: its robot.encoder_columns name, else the kind's.
std::vector<std::string> ModelWheelNames(const RobotOptions& robot) {
  std::vector<std::string> names = WheeledRobot::EncoderColumns(robot.kind);
  for (const EncoderColumn& c : robot.encoder_columns)
    if (c.wheel >= 0 && static_cast<std::size_t>(c.wheel) < names.size())
      names[static_cast<std::size_t>(c.wheel)] = c.name;
  return names;
}

// 2. Measured wheel speeds of a wheeled robot.
Found FromWheelEncoders(const Recording& real, const RobotOptions& robot) {
  for (const Stream& s : real.streams) {
    if (s.info.type != StreamType::kWheelEncoders || s.t.size() < 2) continue;
    if (!IsAngleEncoder(s) && s.info.units != "rad/s") continue;
    const std::vector<std::string> model = ModelWheelNames(robot);
    auto match = MatchWheelColumns(s.info.columns, model);
    if (!match.ok()) return Status::Error("wheel_encoders stream '" + s.info.name + "': " + match.status().message());
    const Eigen::MatrixXd rates = IsAngleEncoder(s) ? WindowRates(s) : s.values;
    DriveInputs in;
    in.kind = DriveInputs::Kind::kWheelRates;
    in.t = s.t;
    in.source = "wheel_encoders stream '" + s.info.name + "'" + (IsAngleEncoder(s) ? " (differentiated)" : "");
    in.streams = {s.info.name};
    in.values.resize(rates.rows(), static_cast<Eigen::Index>(model.size()));
    if (IsAngleEncoder(s)) in.angles_rad.resize(rates.rows(), static_cast<Eigen::Index>(model.size()));
    for (std::size_t i = 0; i < model.size(); ++i) {
      in.values.col(static_cast<Eigen::Index>(i)) = rates.col(match.value()[i]);
      if (IsAngleEncoder(s)) in.angles_rad.col(static_cast<Eigen::Index>(i)) = s.values.col(match.value()[i]);
    }
    return std::optional<DriveInputs>(std::move(in));
  }
  return std::optional<DriveInputs>();
}

// 3. A wheeled robot's wheel odometry (an odometry stream: the velocity of its frame, in its frame), as O's body
// velocity through the stream's mounting: v_O = R v_S - omega_O x p, omega_O = R omega_S.
Found FromOdometry(const Recording& real) {
  for (const Stream& s : real.streams) {
    if (s.info.type != StreamType::kOdometry || s.t.empty()) continue;
    const recording::Mounting m = s.info.mounting.value_or(recording::Mounting{});
    const Eigen::Matrix3d R = m.q_body_sensor.toRotationMatrix();
    DriveInputs in;
    in.kind = DriveInputs::Kind::kBodyVelocity;
    in.t = s.t;
    in.source = "odometry stream '" + s.info.name + "'";
    in.streams = {s.info.name};
    in.values.resize(s.values.rows(), 3);
    for (Eigen::Index k = 0; k < s.values.rows(); ++k) {
      const Eigen::Vector3d omega = R * s.values.row(k).segment<3>(3).transpose();
      const Eigen::Vector3d v = R * s.values.row(k).head<3>().transpose() - omega.cross(m.p_body_sensor);
      in.values.row(k) << v.x(), v.y(), omega.z();
    }
    return std::optional<DriveInputs>(std::move(in));
  }
  return std::optional<DriveInputs>();
}

// 4. The Ackermann vehicle's rear-wheel speed and steering angle, through the nominal odometer calibration.
Found FromAckermannOdometer(const Recording& real, const Scenario& nominal) {
  const Stream* speed = nullptr;
  const Stream* steering = nullptr;
  for (const Stream& s : real.streams) {
    if (!speed && s.info.type == StreamType::kWheelEncoders && s.info.units == "m/s" && s.info.columns.size() == 1 &&
        s.t.size() >= 2)
      speed = &s;
    if (!steering && s.info.type == StreamType::kSteering && s.t.size() >= 2) steering = &s;
  }
  if (!speed || !steering) return std::optional<DriveInputs>();
  const OdometerOptions odometer = nominal.sensors.odometer.value_or(OdometerOptions{});
  auto wheelbase = NominalPlatformGeometry(nominal);
  if (!wheelbase.ok()) return wheelbase.status();
  const double L = wheelbase.value().at("wheelbase_m");
  const Eigen::VectorXd v = WindowMeans(*speed, 0) * (odometer.kv_over_L * L);
  const Eigen::VectorXd z_theta = WindowMeans(*steering, 0);
  DriveInputs in;
  in.kind = DriveInputs::Kind::kAckermann;
  in.t = speed->t;
  in.source = "rear-wheel speed '" + speed->info.name + "' and steering '" + steering->info.name + "'";
  in.streams = {speed->info.name, steering->info.name};
  in.values.resize(v.size(), 2);
  in.values.col(0) = v;
  // The steering angle at the speed's stamps (linear between its own rows).
  DriveInputs angle;
  angle.t = steering->t;
  angle.values = odometer.k_theta * z_theta.array() + odometer.k_gamma;
  for (Eigen::Index k = 0; k < v.size(); ++k) in.values(k, 1) = angle.At(in.t[static_cast<std::size_t>(k)])[0];
  in.travel_m = Eigen::VectorXd::Zero(v.size());
  for (Eigen::Index k = 1; k < v.size(); ++k) {
    const double dt = SecondsBetween(in.t[static_cast<std::size_t>(k - 1)], in.t[static_cast<std::size_t>(k)]);
    in.travel_m[k] = in.travel_m[k - 1] + 0.5 * (v[k - 1] + v[k]) * dt;
  }
  return std::optional<DriveInputs>(std::move(in));
}

std::string NeededInputs(bool ackermann) {
  return ackermann ? "an inputs stream with columns speed_mps, handlebar_rad, or a rear-wheel speed (wheel_encoders, "
                     "one column, m/s) and a steering stream"
                   : "an inputs stream with columns linear_mps, angular_radps (lateral_mps optional), a "
                     "wheel_encoders stream in rad or rad/s, or an odometry stream";
}

// The twin's plan: the scenario as replayed, the stamps of each simulated stream, and which recorded stream each
// simulated one stands for.
struct TwinStream {
  std::size_t recorded = 0;   // index in the recording's streams
  std::string simulated;      // the simulator's stream name
  std::size_t first_row = 0;  // the recorded stream's first row in the window
};
struct Plan {
  Scenario scenario;
  std::map<std::string, std::vector<Time>> stamps;
  std::vector<TwinStream> streams;
  std::vector<std::string> left_out;
};

// The simulator's stream for a recorded one, or "" with the reason why there is none.
std::string SimulatedName(const Stream& s, const Recording& real, const Scenario& nominal, std::string* why) {
  const SensorOptions& sensors = nominal.sensors;
  const bool ackermann = nominal.robot.kind == "ackermann";
  const auto need = [why](bool present, const std::string& name, const std::string& reason) {
    if (!present) *why = reason;
    return present ? name : std::string();
  };
  switch (s.info.type) {
    case StreamType::kImu:
      return need(sensors.imu.has_value(), "imu", "the nominal scenario has no imu");
    case StreamType::kMagnetometer:
      return need(sensors.magnetometer.has_value(), "magnetometer", "the nominal scenario has no magnetometer");
    case StreamType::kGps:
      if (!real.origin) return need(false, "", "the recording has no origin");
      return need(sensors.gps.has_value(), "gps", "the nominal scenario has no gps");
    case StreamType::kPose:
      return need(recording::PosedOdometry(real, s) == nullptr, "mocap",
                  "the pose of an odometry stream, dead-reckoned in its parent frame");
    case StreamType::kOdometry:
      return need(!ackermann, "odometry", "an ackermann vehicle has no wheel odometry in the simulator");
    case StreamType::kSteering:
      return need(ackermann && sensors.odometer.has_value(), "steering", "the nominal scenario has no odometer");
    case StreamType::kWheelEncoders:
      if (ackermann)
        return need(s.info.units == "m/s" && s.info.columns.size() == 1 && sensors.odometer.has_value(), "rear_wheel",
                    "not a rear-wheel speed of the nominal scenario's odometer");
      if (!IsAngleEncoder(s)) return need(false, "", "wheel_encoders in " + s.info.units + " are not synthesized");
      return "wheel_encoders";
    default:
      *why = std::string("the simulator does not synthesize ") + recording::StreamTypeName(s.info.type);
      return "";
  }
}

// Each recorded column of a wheel_encoders stream must be driven by a model wheel that the simulator's encoder stream
// reads (its columns: robot.encoder_columns, else every wheel in index order): per recorded column, those simulated
// columns.
Result<std::vector<std::vector<Eigen::Index>>> SimulatedColumnsOf(const Stream& s, const RobotOptions& robot) {
  const std::vector<std::string> names = ModelWheelNames(robot);
  auto match = MatchWheelColumns(s.info.columns, names);
  if (!match.ok()) return match.status();
  std::vector<Eigen::Index> column_of_wheel(names.size(), -1);
  if (robot.encoder_columns.empty()) {
    for (std::size_t i = 0; i < names.size(); ++i) column_of_wheel[i] = static_cast<Eigen::Index>(i);
  }
  for (std::size_t k = 0; k < robot.encoder_columns.size(); ++k) {
    const int wheel = robot.encoder_columns[k].wheel;
    if (wheel >= 0 && static_cast<std::size_t>(wheel) < names.size())
      column_of_wheel[static_cast<std::size_t>(wheel)] = static_cast<Eigen::Index>(k);
  }
  std::vector<std::vector<Eigen::Index>> columns(s.info.columns.size());
  for (std::size_t i = 0; i < match.value().size(); ++i)
    if (column_of_wheel[i] >= 0) columns[static_cast<std::size_t>(match.value()[i])].push_back(column_of_wheel[i]);
  for (std::size_t j = 0; j < columns.size(); ++j)
    if (columns[j].empty())
      return Status::Error("column '" + s.info.columns[j] + "' drives no model wheel the scenario's encoders read");
  return columns;
}

// Which recorded streams the twin holds, at which stamps, and the scenario's sensors for them.
Plan PlanTwin(const Scenario& nominal, const Recording& real, Time from, Time to) {
  Plan plan;
  plan.scenario = nominal;
  for (std::size_t i = 0; i < real.streams.size(); ++i) {
    const Stream& s = real.streams[i];
    std::string why;
    std::string name = SimulatedName(s, real, nominal, &why);
    if (name == "wheel_encoders") {
      if (auto wheels = SimulatedColumnsOf(s, nominal.robot); !wheels.ok()) {
        why = wheels.status().message();
        name.clear();
      }
    }
    if (!name.empty() && plan.stamps.count(name)) {
      why = std::string("a second ") + recording::StreamTypeName(s.info.type) + " stream";
      name.clear();
    }
    const auto first = std::lower_bound(s.t.begin(), s.t.end(), from);
    const auto last = std::upper_bound(s.t.begin(), s.t.end(), to);
    if (!name.empty() && first == last) {
      why = "no samples in the window";
      name.clear();
    }
    if (name.empty()) {
      plan.left_out.push_back(s.info.name + ": " + why);
      continue;
    }
    plan.stamps[name] = std::vector<Time>(first, last);
    plan.streams.push_back({i, name, static_cast<std::size_t>(first - s.t.begin())});
  }
  // The odometer's two streams share one clock.
  if (plan.stamps.count("rear_wheel") && plan.stamps.count("steering") &&
      plan.stamps["rear_wheel"] != plan.stamps["steering"]) {
    const auto it = std::find_if(plan.streams.begin(), plan.streams.end(),
                                 [](const TwinStream& t) { return t.simulated == "steering"; });
    plan.left_out.push_back(real.streams[it->recorded].info.name + ": stamped apart from the rear-wheel speed");
    plan.streams.erase(it);
    plan.stamps.erase("steering");
  }
  return plan;
}

// The scenario's sensors for the plan: only those the twin holds (the IMU stays for a magnetometer), no laser, camera
// or world model; encoders added when the recording has them and the scenario not.
void FitSensors(const Recording& real, Plan* plan) {
  SensorOptions& sensors = plan->scenario.sensors;
  const auto has = [plan](const std::string& name) { return plan->stamps.count(name) > 0; };
  if (!has("imu") && !has("magnetometer")) sensors.imu.reset();
  if (!has("magnetometer")) sensors.magnetometer.reset();
  if (!has("gps")) sensors.gps.reset();
  if (!has("rear_wheel") && !has("steering")) sensors.odometer.reset();
  if (!has("wheel_encoders")) sensors.wheel_encoders.reset();
  if (!has("mocap")) sensors.mocap.reset();
  if (has("mocap") && !sensors.mocap) {  // the rate is the schedule's; one that fits the physics step
    MocapOptions mocap;
    mocap.rate_hz = plan->scenario.ground_truth_rate_hz;
    sensors.mocap = mocap;
  }
  if (has("wheel_encoders") && !sensors.wheel_encoders) {
    WheelEncoderOptions encoders;
    encoders.ticks_per_revolution = kDefaultTicksPerRevolution;
    for (const TwinStream& t : plan->streams) {
      if (t.simulated != "wheel_encoders") continue;
      const auto& attributes = real.streams[t.recorded].info.attributes;
      const auto ticks = attributes.find("ticks_per_revolution");
      if (ticks != attributes.end() && ticks->second >= 1.0 && ticks->second == std::round(ticks->second))
        encoders.ticks_per_revolution = ticks->second;
    }
    sensors.wheel_encoders = encoders;
  }
  if (sensors.laser) plan->left_out.push_back("the scenario's laser: not simulated in a replay (too slow)");
  if (sensors.camera) plan->left_out.push_back("the scenario's camera: not simulated in a replay (too slow)");
  sensors.laser.reset();
  sensors.camera.reset();
  plan->scenario.world_model_file.clear();
}

std::optional<ReplayStart> StartFromPose(const Recording& real, Time from) {
  for (const Stream& s : real.streams) {
    // An odometry's own pose is dead-reckoned in its parent frame: not where the robot is.
    if (s.info.type != StreamType::kPose || recording::PosedOdometry(real, s)) continue;
    const auto row = std::lower_bound(s.t.begin(), s.t.end(), from);
    if (row == s.t.end()) continue;
    const Eigen::Index k = row - s.t.begin();
    const recording::Mounting m = s.info.mounting.value_or(recording::Mounting{});
    const Eigen::Quaterniond q_world_sensor(s.values(k, 6), s.values(k, 3), s.values(k, 4), s.values(k, 5));
    const Eigen::Quaterniond q_world_body = q_world_sensor.normalized() * m.q_body_sensor.conjugate();
    const Eigen::Vector3d p = s.values.row(k).head<3>().transpose() - q_world_body * m.p_body_sensor;
    const Eigen::Vector3d x_axis = q_world_body * Eigen::Vector3d::UnitX();
    return ReplayStart{p.head<2>(), std::atan2(x_axis.y(), x_axis.x()), "pose stream '" + s.info.name + "'"};
  }
  return std::nullopt;
}

// Positions in W of a gps (through the origin) or position stream.
std::vector<Eigen::Vector3d> Positions(const Recording& real, const Stream& s) {
  std::vector<Eigen::Vector3d> p;
  std::optional<GeographicLib::LocalCartesian> local;
  if (s.info.type == StreamType::kGps)
    local.emplace(real.origin->latitude_deg, real.origin->longitude_deg, real.origin->altitude_m);
  for (Eigen::Index k = 0; k < s.values.rows(); ++k) {
    double x = s.values(k, 0), y = s.values(k, 1), z = s.values(k, 2);
    if (local) local->Forward(s.values(k, 0), s.values(k, 1), s.values(k, 2), x, y, z);
    p.emplace_back(x, y, z);
  }
  return p;
}

// The first gps (with an origin) or position stream with a sample at or after `from`.
const Stream* PositionStream(const Recording& real, Time from) {
  for (const Stream& s : real.streams) {
    const bool gps = s.info.type == StreamType::kGps && real.origin;
    if ((gps || s.info.type == StreamType::kPosition) && s.values.cols() >= 3 && !s.t.empty() && s.t.back() >= from)
      return &s;
  }
  return nullptr;
}

std::optional<ReplayStart> StartFromPositions(const Recording& real, const Scenario& nominal, const Stream& s,
                                              Time from) {
  const auto row = std::lower_bound(s.t.begin(), s.t.end(), from);
  const std::vector<Eigen::Vector3d> p = Positions(real, s);
  const std::size_t k0 = static_cast<std::size_t>(row - s.t.begin());
  for (std::size_t k = k0 + 1; k < p.size() && SecondsBetween(s.t[k0], s.t[k]) <= kStartMotionWindowS; ++k) {
    const Eigen::Vector2d d = (p[k] - p[k0]).head<2>();
    if (d.norm() < kStartMotionM) continue;
    const double yaw = std::atan2(d.y(), d.x());
    Eigen::Vector3d lever = s.info.mounting ? s.info.mounting->p_body_sensor : Eigen::Vector3d::Zero();
    if (s.info.type == StreamType::kGps && nominal.sensors.gps) lever = nominal.sensors.gps->lever_arm_m;
    const Eigen::Vector2d lever_world = Eigen::Rotation2Dd(yaw) * lever.head<2>();
    return ReplayStart{p[k0].head<2>() - lever_world, yaw, "the first motion of '" + s.info.name + "'"};
  }
  return std::nullopt;
}

// `start` moved by the planar rigid motion that best fits the track of `s` in `twin` onto the recorded one (matched
// stamps): a rotation about the vertical and a translation, or a translation alone when the recorded track spans less
// than kStartAlignMinExtentM; unchanged with fewer than 3 matched samples.
ReplayStart AlignedStart(const Recording& real, const Stream& s, const Recording& twin, ReplayStart start) {
  const Stream* t = twin.Find(s.info.name);
  if (!t) return start;
  const std::vector<Eigen::Vector3d> real_p = Positions(real, s), twin_p = Positions(real, *t);
  std::vector<Eigen::Vector3d> a, b;  // twin, recorded
  for (std::size_t i = 0, j = 0; i < t->t.size(); ++i) {
    while (j < s.t.size() && s.t[j] < t->t[i]) ++j;
    if (j == s.t.size()) break;
    if (s.t[j] != t->t[i]) continue;
    a.push_back(Eigen::Vector3d(twin_p[i].x(), twin_p[i].y(), 0.0));
    b.push_back(Eigen::Vector3d(real_p[j].x(), real_p[j].y(), 0.0));
  }
  if (a.size() < 3) return start;
  double extent = 0.0;
  for (const Eigen::Vector3d& p : b) extent = std::max(extent, (p - b.front()).norm());
  double yaw = 0.0;
  Eigen::Vector2d translation = Eigen::Vector2d::Zero();
  if (extent >= kStartAlignMinExtentM) {
    const eval::RigidTransform fit = eval::AlignPositions(a, b, eval::AlignmentKind::kYawTranslation);
    const Eigen::Vector3d x_axis = fit.q_ref_est * Eigen::Vector3d::UnitX();
    yaw = std::atan2(x_axis.y(), x_axis.x());
    translation = fit.p_ref_est.head<2>();
  } else {
    for (std::size_t i = 0; i < a.size(); ++i) translation += (b[i] - a[i]).head<2>();
    translation /= static_cast<double>(a.size());
  }
  start.p_m = Eigen::Rotation2Dd(yaw) * start.p_m + translation;
  start.yaw_rad += yaw;
  start.source += ", aligned on its first " + FormatSeconds(Time::FromSeconds(kStartAlignS)) + " s";
  return start;
}

// The twin's values of one planned stream from the simulated one, in the recorded stream's layout.
Eigen::MatrixXd TwinValues(const Stream& recorded, const Stream& simulated, const TwinStream& plan,
                           const RobotOptions& robot) {
  const Eigen::Index n = simulated.values.rows();
  const auto first = static_cast<Eigen::Index>(plan.first_row);
  Eigen::MatrixXd out = recorded.values.middleRows(first, n);  // extra columns (a fix's covariance) as recorded
  if (plan.simulated == "wheel_encoders") {
    const auto columns = SimulatedColumnsOf(recorded, robot).value();  // checked by PlanTwin
    for (std::size_t j = 0; j < columns.size(); ++j) {
      Eigen::VectorXd sum = Eigen::VectorXd::Zero(n);
      for (Eigen::Index i : columns[j]) sum += simulated.values.col(i);
      const auto c = static_cast<Eigen::Index>(j);
      out.col(c) = sum / static_cast<double>(columns[j].size()) + Eigen::VectorXd::Constant(n, out(0, c));
    }
  } else if (plan.simulated == "mocap") {
    const recording::Mounting m = recorded.info.mounting.value_or(recording::Mounting{});
    for (Eigen::Index k = 0; k < n; ++k) {
      const Eigen::Quaterniond q_world_body(simulated.values(k, 6), simulated.values(k, 3), simulated.values(k, 4),
                                            simulated.values(k, 5));
      const Eigen::Vector3d p = simulated.values.row(k).head<3>().transpose() + q_world_body * m.p_body_sensor;
      const Eigen::Quaterniond q = q_world_body * m.q_body_sensor;
      out.row(k) << p.transpose(), q.x(), q.y(), q.z(), q.w();
    }
  } else if (plan.simulated == "odometry") {
    // O's twist as the stream's frame moves: v_S = R^T (v_O + omega x p), omega_S = R^T omega_O.
    const recording::Mounting m = recorded.info.mounting.value_or(recording::Mounting{});
    const Eigen::Matrix3d R_T = m.q_body_sensor.toRotationMatrix().transpose();
    for (Eigen::Index k = 0; k < n; ++k) {
      const Eigen::Vector3d v = simulated.values.row(k).head<3>().transpose();
      const Eigen::Vector3d omega = simulated.values.row(k).segment<3>(3).transpose();
      out.row(k).head<6>() << (R_T * (v + omega.cross(m.p_body_sensor))).transpose(), (R_T * omega).transpose();
    }
  } else {
    out.leftCols(simulated.values.cols()) = simulated.values;
  }
  return out;
}

// Replaces the simulated streams by the twin's: the recorded streams' layout at the simulated values.
void AssembleTwin(const Recording& real, const Plan& plan, Simulation* sim) {
  std::vector<Stream> twin;
  for (const TwinStream& t : plan.streams) {
    const Stream& recorded = real.streams[t.recorded];
    const bool encoders = t.simulated == "wheel_encoders";  // the scenario names its encoder stream
    const Stream* simulated = sim->recording.Find(encoders ? plan.scenario.sensors.wheel_encoders->name : t.simulated);
    Stream s;
    s.info = recorded.info;
    s.t = simulated->t;
    s.values = TwinValues(recorded, *simulated, t, plan.scenario.robot);
    twin.push_back(std::move(s));
  }
  sim->recording.streams = std::move(twin);
  sim->stats.left_out = plan.left_out;
}

// The drive taken from readings, through the scenario's effects on those readings back to the true drive: divided by
// odometry_scale_error's scale (the odometry reads that many times the motion), and an Ackermann vehicle's front
// wheels turned steering_offset's offset further than the nominal calibration reads the steering sensor. The drive
// tires' slip (longitudinal_slip, slope_slip) depends on the twin's own traction: the simulator undoes it as it
// drives (sim/replay_schedule.h).
void UndoReadingEffects(const Scenario& scenario, DriveInputs* in) {
  const double scale = EffectParameter(scenario.effects, "odometry_scale_error", "scale", 1.0);
  if (in->kind == DriveInputs::Kind::kAckermann) {
    in->values.col(0) /= scale;
    in->values.col(1).array() += EffectParameter(scenario.effects, "steering_offset", "offset_rad", 0.0);
  } else {
    in->values /= scale;
  }
  in->angles_rad /= scale;
  in->travel_m /= scale;
}

}  // namespace

Result<Simulation> Replay(const Scenario& nominal, const Recording& real, const ReplayOptions& options) {
  auto drive = DriveInputsFrom(real, nominal);
  if (!drive.ok()) return drive.status();
  const DriveInputs& inputs = drive.value();
  const Time from = options.from_s ? Time::FromSeconds(*options.from_s) : inputs.t.front();
  const Time to = options.to_s ? Time::FromSeconds(*options.to_s) : inputs.t.back();
  if (!(from < to) || from >= inputs.t.back() || to <= inputs.t.front()) {
    return Status::Error("the replay window [" + FormatSeconds(from) + ", " + FormatSeconds(to) +
                         "] s is empty or outside the drive inputs' span [" + FormatSeconds(inputs.t.front()) + ", " +
                         FormatSeconds(inputs.t.back()) + "] s");
  }
  Plan plan = PlanTwin(nominal, real, from, to);
  FitSensors(real, &plan);
  ReplayStart start;
  if (options.start) {
    start = *options.start;
  } else {
    auto found = ReplayStartOf(nominal, real, from.seconds());
    if (!found.ok()) return found.status();
    start = found.value();
  }
  plan.scenario.robot.start_position_m = start.p_m;
  plan.scenario.robot.start_heading_rad = start.yaw_rad;
  plan.scenario.duration_s = SecondsBetween(from, to);
  if (real.origin) plan.scenario.origin = *real.origin;

  auto schedule = std::make_shared<ReplaySchedule>();
  schedule->t0 = from;
  schedule->drive = inputs;
  schedule->stamps = plan.stamps;
  SimulateOptions simulate;
  simulate.noise = false;
  simulate.progress = options.progress;
  simulate.replay = schedule;
  auto run = Simulate(plan.scenario, simulate);
  if (!run.ok()) return run.status();
  Simulation out = std::move(run).value();
  AssembleTwin(real, plan, &out);
  out.recording.provenance.description += "; the noise-free replay of a recording driven by its " + inputs.source;
  out.truth.replay = recording::ReplayNote{inputs.source, start.source};
  return out;
}

Result<ReplayStart> ReplayStartOf(const Scenario& nominal, const Recording& real, std::optional<double> from_s) {
  auto drive = DriveInputsFrom(real, nominal);
  if (!drive.ok()) return drive.status();
  const Time from = from_s ? Time::FromSeconds(*from_s) : drive.value().t.front();
  if (auto pose = StartFromPose(real, from)) return *pose;
  const Stream* track = PositionStream(real, from);
  const ReplayStart scenario_start{nominal.robot.start_position_m, nominal.robot.start_heading_rad,
                                   "the scenario's start"};
  if (!track) return scenario_start;
  const ReplayStart start = StartFromPositions(real, nominal, *track, from).value_or(scenario_start);
  // The refining replay: the nominal scenario as believed over the first kStartAlignS.
  Scenario base = nominal;
  base.effects.clear();
  ReplayOptions first;
  first.from_s = from.seconds();
  first.to_s = std::min(from.seconds() + kStartAlignS, drive.value().t.back().seconds());
  first.start = start;
  if (!(*first.from_s < *first.to_s)) return start;
  auto twin = Replay(base, real, first);
  if (!twin.ok()) return Status::Error("the replay that aligns the start: " + twin.status().message());
  return AlignedStart(real, *track, twin.value().recording, start);
}

Result<std::vector<int>> MatchWheelColumns(const std::vector<std::string>& recorded_columns,
                                           const std::vector<std::string>& model_columns) {
  std::vector<int> match;
  for (const std::string& wheel : model_columns) {
    auto it = std::find(recorded_columns.begin(), recorded_columns.end(), wheel);
    for (const char* side : {"left", "right"})
      if (it == recorded_columns.end() && EndsWith(wheel, side))
        it = std::find(recorded_columns.begin(), recorded_columns.end(), side);
    if (it == recorded_columns.end())
      return Status::Error("no recorded column for the model's wheel '" + wheel +
                           "' (recorded: " + Join(recorded_columns) + "; model: " + Join(model_columns) + ")");
    match.push_back(static_cast<int>(it - recorded_columns.begin()));
  }
  return match;
}

Result<DriveInputs> DriveInputsFrom(const Recording& real, const Scenario& nominal) {
  const bool ackermann = nominal.robot.kind == "ackermann";
  std::string note;
  Found inputs = FromInputsStream(real, ackermann, &note);
  const bool commands = inputs.ok() && inputs.value();
  if (inputs.ok() && !inputs.value())
    inputs = ackermann ? FromAckermannOdometer(real, nominal) : FromWheelEncoders(real, nominal.robot);
  if (inputs.ok() && !inputs.value() && !ackermann) inputs = FromOdometry(real);
  if (!inputs.ok()) return inputs.status();
  if (!inputs.value())
    return Status::Error("no drive input: a replay of robot kind " + nominal.robot.kind + " needs " +
                         NeededInputs(ackermann) + note);
  if (!commands) UndoReadingEffects(nominal, &*inputs.value());
  return std::move(*inputs.value());
}

}  // namespace roamlab::sim
