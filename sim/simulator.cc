#include "sim/simulator.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <fstream>
#include <sstream>
#include <utility>

#include <GeographicLib/LocalCartesian.hpp>

#include "common/check.h"
#include "common/interrupt.h"
#include "frontend/laser_scan.h"
#include "frontend/scan_matching_stream.h"
#include "sim/ackermann.h"
#include "sim/internal/scenario_effects.h"
#include "sim/internal/simulation_metadata.h"
#include "sim/internal/stream_clock.h"
#include "sim/laser.h"
#include "sim/mujoco_model.h"
#include "sim/noise.h"
#include "sim/rolling_radius.h"
#include "sim/sensors.h"
#include "sim/simulated_camera.h"
#include "sim/terrain.h"
#include "sim/wheeled_robot.h"

namespace roamlab::sim {
namespace {

using frontend::LaserScanRow;
using internal::Clock;
using internal::HasEffect;
using internal::MakeStream;
using internal::TireDeformations;
using recording::StreamType;

// Fraction of the lead-in spent at rest before the set-points ramp up.
constexpr double kLeadInRestFraction = 0.25;
// Drop height of the tires above the ground when the vehicle is placed [m].
constexpr double kPlacementClearanceM = 0.01;
// The vehicle must stay this far inside the heightfield [m].
constexpr double kTerrainMarginM = 2.0;
// Below this cosine between O's z axis and the world's up the vehicle has rolled over (about 70 deg).
constexpr double kRolloverCosine = 0.34;
constexpr double kPi = 3.14159265358979323846;
// The robot's camera for visual odometry (models/diffdrive.xml).
constexpr const char* kCameraName = "camera";

std::string OneLine(std::string text) {
  for (char& c : text)
    if (c == '\n' || c == '\r') c = ' ';
  return text;
}

std::string FormatTime(std::int64_t t_ns) { return FormatSeconds(Time::FromNanoseconds(t_ns)) + " s"; }

// Nominal geometry is reported to the micrometre: enough, and free of floating-point noise from the model's frames.
double Micrometres(double x) { return std::round(x * 1e6) / 1e6; }

}  // namespace

// One run of one scenario: Setup() once, then Run() once.
class Simulator::Impl {
 public:
  Impl(const Scenario& scenario, const SimulateOptions& options)
      : scenario_(scenario),
        options_(options),
        seed_(options.seed.value_or(scenario.seed)),
        where_(scenario.source_file.empty() ? std::string("scenario") : scenario.source_file),
        model_where_(scenario.robot.model_xml.empty() ? scenario.robot.model_file : std::string("robot.model_xml")) {}

  Result<Simulation> Run() {
    const auto wall_start = std::chrono::steady_clock::now();
    TakeMujocoWarnings();
    try {
      if (Status s = Loop(); !s.ok()) return s;
    } catch (const MujocoError& e) {
      return Status::Error(model_where_ + ": MuJoCo error at t = " + FormatTime(t_ns_) + ": " + OneLine(e.what()));
    }
    Finish();
    if (!options_.replay) out_.stats.faults = ApplyFaults(scenario_.faults, seed_, &out_.recording);
    out_.stats.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    out_.stats.realtime_factor = out_.stats.wall_s > 0.0 ? out_.stats.simulated_s / out_.stats.wall_s : 0.0;
    out_.stats.warnings = TakeMujocoWarnings();
    return std::move(out_);
  }

  // The platform geometry the recording states: nominal, measured on the bound model (to the micrometre).
  std::map<std::string, double> PlatformGeometry() const {
    if (ackermann_)
      return {{"wheelbase_m", wheelbase_m_},
              {"track_m", Micrometres(vehicle_.rear_track_m())},
              {"wheel_radius_m", Micrometres(vehicle_.wheel_radius_m())}};
    std::map<std::string, double> geometry;
    const std::map<std::string, double> measured =
        scenario_.robot.per_wheel_geometry ? wheeled_.PerWheelGeometry(WheelNames()) : wheeled_.PlatformGeometry();
    // Angles to the microradian, directions exact (+-1): the same rounding.
    for (const auto& [key, value] : measured) geometry[key] = Micrometres(value);
    for (const auto& [key, value] : scenario_.robot.stated_geometry) geometry[key] = value;
    return geometry;
  }
  double VehicleMassKg() const { return ackermann_ ? vehicle_.mass_kg() : 0.0; }
  double PhysicsStepS() const { return static_cast<double>(step_ns_) * 1e-9; }

  // Compiles the world, binds the vehicle, sets up clocks, streams and noise, and places the vehicle.
  Status Setup() {
    if (Status s = CompileWorld(); !s.ok()) return s;
    if (Status s = BindRobot(); !s.ok()) return s;
    if (Status s = SetupClocks(); !s.ok()) return s;
    if (Status s = SetupEffects(); !s.ok()) return s;
    SetupStreams();
    PlaceRobot();
    return Status::Ok();
  }

 private:
  // The world: the robot's MJCF plus the terrain (plus the static world model, if any), compiled through the VFS;
  // then the heightfield samples and the wheel mounting changes.
  Status CompileWorld() {
    // The robot's MJCF text.
    std::string robot_xml = scenario_.robot.model_xml;
    if (robot_xml.empty()) {
      std::ifstream file(scenario_.robot.model_file, std::ios::binary);
      if (!file) return Status::Error(where_ + ": robot.model: cannot open '" + scenario_.robot.model_file + "'");
      std::ostringstream content;
      content << file.rdbuf();
      robot_xml = content.str();
    }

    // The world: robot plus terrain (plus the static world model, if any), compiled through the VFS; then the
    // heightfield samples.
    terrain_ = Terrain::Make(scenario_.terrain, scenario_.robot.start_position_m);
    std::map<std::string, std::string> files{{"robot.xml", robot_xml}};
    std::string world_xml = "<mujoco model=\"roamlab_world\">\n<include file=\"robot.xml\"/>\n" + terrain_.Mjcf();
    if (!scenario_.world_model_file.empty()) {
      std::ifstream file(scenario_.world_model_file, std::ios::binary);
      if (!file) return Status::Error(where_ + ": world.model: cannot open '" + scenario_.world_model_file + "'");
      std::ostringstream content;
      content << file.rdbuf();
      files["room.xml"] = content.str();
      world_xml += "<include file=\"room.xml\"/>\n";
    }
    files["world.xml"] = world_xml + "</mujoco>\n";
    auto model = LoadModelFromFiles("world.xml", files, model_where_);
    if (!model.ok()) return model.status();
    model_ = std::move(model).value();
    if (Status s = terrain_.Fill(model_.get()); !s.ok()) return Status::Error(model_where_ + ": " + s.message());
    if (!ackermann_) {
      if (Status st = WheeledRobot::ChangeMounting(model_.get(), scenario_.robot.wheel_mounting, where_); !st.ok())
        return st;
    }
    data_ = MakeData(model_.get());
    return Status::Ok();
  }

  // Binds the Ackermann vehicle or the wheeled robot to the compiled model and applies the effects that change it.
  Status BindRobot() {
    if (ackermann_) {
      auto vehicle = AckermannVehicle::Bind(model_.get(), model_where_);
      if (!vehicle.ok()) return vehicle.status();
      vehicle_ = vehicle.value();
      // A misaligned rear axle changes the bound model (the driver and the platform geometry stay nominal).
      if (HasEffect(scenario_, "axle_misalignment"))
        vehicle_.TurnRearAxle(model_.get(),
                              EffectParameter(scenario_.effects, "axle_misalignment", "yaw_deg", 0.0) * kPi / 180.0);
      // Softer tires: the contact time constant, hence the cornering compliance, grows.
      if (HasEffect(scenario_, "lateral_slip")) {
        const double scale = EffectParameter(scenario_.effects, "lateral_slip", "contact_time_scale", 1.0);
        if (Status st = vehicle_.SoftenTires(model_.get(), scale, model_where_); !st.ok()) return st;
      }
      // The rear tires' free-rolling travel per radian on the changed model: the speed reading's true gain.
      auto rolling = MeasureRearRollingRadius(model_.get(), vehicle_, scenario_.robot.speed_controller, model_where_);
      if (!rolling.ok()) return rolling.status();
      rear_rolling_radius_m_ = rolling.value();
      controller_.emplace(scenario_.robot.speed_controller);
      odom_site_ = vehicle_.odom_site();
    } else {
      auto robot = WheeledRobot::Bind(model_.get(), scenario_.robot.kind, model_where_);
      if (!robot.ok()) return robot.status();
      wheeled_ = robot.value();
      // The wheel effects change the bound model, so that the platform geometry and the driver stay nominal.
      if (HasEffect(scenario_, "track_width_error")) {
        const double error_m = EffectParameter(scenario_.effects, "track_width_error", "track_error_m", 0.0);
        if (Status st = wheeled_.ChangeTrack(model_.get(), error_m, where_); !st.ok()) return st;
      }
      if (HasEffect(scenario_, "skid_steer_track")) {
        const double ratio = EffectParameter(scenario_.effects, "skid_steer_track", "track_ratio", 1.0);
        if (auto moved = wheeled_.ScaleEffectiveTrack(model_.get(), ratio, where_); !moved.ok()) return moved.status();
      }
      if (HasEffect(scenario_, "axle_misalignment")) {
        WheelMountingChange change;
        change.wheel = static_cast<int>(EffectParameter(scenario_.effects, "axle_misalignment", "wheel", 0.0));
        change.yaw_rad = EffectParameter(scenario_.effects, "axle_misalignment", "yaw_deg", 0.0) * kPi / 180.0;
        if (Status st = WheeledRobot::ChangeMounting(model_.get(), {change}, where_); !st.ok()) return st;
      }
      if (Status st = wheeled_.MoveWheels(model_.get(), scenario_.robot.wheel_offset, where_); !st.ok()) return st;
      if (Status st = wheeled_.Deform(model_.get(), TireDeformations(scenario_), where_); !st.ok()) return st;
      if (Status st = MeasureRollingRadii(); !st.ok()) return st;
      if (Status st = BindEncoderColumns(); !st.ok()) return st;
      odom_site_ = wheeled_.odom_site();
      if (scenario_.sensors.laser && wheeled_.laser_site() < 0)
        return Status::Error(model_where_ + ": sensors.laser needs a site 'laser' on the robot");
      if (scenario_.sensors.camera && IdOf(model_.get(), mjOBJ_CAMERA, kCameraName) < 0)
        return Status::Error(model_where_ + ": sensors.camera needs a camera '" + std::string(kCameraName) +
                             "' on the robot");
      if (scenario_.sensors.camera && scenario_.sensors.camera->store_images && options_.image_directory.empty())
        return Status::Error(where_ + ": sensors.camera.store_images: no recording directory to store images in");
    }

    return Status::Ok();
  }

  // Roller wheels: their true radius is the travel per radian, measured on the changed model from the start pose.
  Status MeasureRollingRadii() {
    if (!wheeled_.HasRollers()) return Status::Ok();
    auto radii =
        sim::MeasureRollingRadii(model_.get(), wheeled_, scenario_.robot.start_position_m.x(),
                                 scenario_.robot.start_position_m.y(), scenario_.robot.start_heading_rad, model_where_);
    if (!radii.ok()) return radii.status();
    wheeled_.SetRollingRadii(radii.value());
    return Status::Ok();
  }

  // The encoder stream's columns (robot.encoder_columns, else every wheel under the kind's names) and the checks of
  // robot.geometry_keys and robot.geometry against the bound model.
  Status BindEncoderColumns() {
    const RobotOptions& robot = scenario_.robot;
    const int wheels = static_cast<int>(wheeled_.wheels().size());
    encoder_columns_.clear();
    if (robot.encoder_columns.empty()) {
      const std::vector<std::string> names = wheeled_.EncoderColumns();
      for (int i = 0; i < wheels; ++i) encoder_columns_.push_back({i, names[static_cast<std::size_t>(i)]});
    }
    for (std::size_t k = 0; k < robot.encoder_columns.size(); ++k) {
      if (robot.encoder_columns[k].wheel >= wheels)
        return Status::Error(where_ + ": robot.encoder_columns[" + std::to_string(k) + "].wheel: the " + robot.kind +
                             " robot has wheels 0 to " + std::to_string(wheels - 1));
      encoder_columns_.push_back(robot.encoder_columns[k]);
    }
    if (robot.per_wheel_geometry && static_cast<int>(encoder_columns_.size()) != wheels)
      return Status::Error(where_ + ": robot.geometry_keys: per_wheel needs every wheel in robot.encoder_columns");
    if (!robot.per_wheel_geometry && !wheeled_.NominalLayout())
      return Status::Error(where_ + ": robot.geometry_keys: the " + robot.kind +
                           " model's wheels are off the layout the nominal keys describe: use per_wheel");
    const std::map<std::string, double> measured =
        robot.per_wheel_geometry ? wheeled_.PerWheelGeometry(WheelNames()) : wheeled_.PlatformGeometry();
    for (const auto& [key, value] : robot.stated_geometry)
      if (measured.count(key) > 0)
        return Status::Error(where_ + ": robot.geometry." + key + ": measured on the model; it cannot be stated");
    return Status::Ok();
  }

  // The encoder column name of each wheel ("" for a wheel without an encoder).
  std::vector<std::string> WheelNames() const {
    std::vector<std::string> names(wheeled_.wheels().size());
    for (const EncoderColumn& c : encoder_columns_) names[static_cast<std::size_t>(c.wheel)] = c.name;
    return names;
  }

  // The physics step, the duration, the lead-in and every stream's clock (every period a whole number of steps).
  Status SetupClocks() {
    step_ns_ = std::llround(model_->opt.timestep * 1e9);
    if (step_ns_ <= 0) return Status::Error(model_where_ + ": the timestep must be positive");
    end_ns_ = std::llround(scenario_.duration_s * 1e9);
    end_ns_ -= end_ns_ % step_ns_;
    lead_in_ns_ = std::llround(scenario_.driver.lead_in_s * 1e9 / static_cast<double>(step_ns_)) * step_ns_;
    const auto clock = [this](double rate_hz, const std::string& key, Clock* out) {
      out->period_ns = std::llround(1e9 / rate_hz);
      if (out->period_ns % step_ns_ != 0 || out->period_ns == 0) {
        std::ostringstream message;
        message << where_ << ": " << key << ": " << rate_hz << " Hz is not a whole number of physics steps of "
                << static_cast<double>(step_ns_) * 1e-6 << " ms (the model's timestep)";
        return Status::Error(message.str());
      }
      out->samples = static_cast<std::size_t>(end_ns_ / out->period_ns) + 1;
      return Status::Ok();
    };
    const SensorOptions& sensors = scenario_.sensors;
    if (Status s = clock(scenario_.ground_truth_rate_hz, "ground_truth_rate_hz", &truth_clock_); !s.ok()) return s;
    if (sensors.imu) {
      if (Status s = clock(sensors.imu->rate_hz, "sensors.imu.rate_hz", &imu_clock_); !s.ok()) return s;
      imu_.q_body_imu = sensors.imu->misalignment.normalized();
      imu_.p_body_imu = sensors.imu->lever_arm_m;
      gyro_noise_.SetCorrelation(sensors.imu->noise_correlation_s, 1e-9 * static_cast<double>(imu_clock_.period_ns));
      accel_noise_.SetCorrelation(sensors.imu->noise_correlation_s, 1e-9 * static_cast<double>(imu_clock_.period_ns));
    }
    if (sensors.magnetometer) {
      if (Status s = clock(sensors.magnetometer->rate_hz, "sensors.magnetometer.rate_hz", &mag_clock_); !s.ok())
        return s;
      magnetometer_.A = sensors.magnetometer->A;
      magnetometer_.b = sensors.magnetometer->b;
      magnetometer_.field_world = sensors.magnetometer->field_world;
      mag_noise_.SetCorrelation(sensors.magnetometer->noise_correlation_s,
                                1e-9 * static_cast<double>(mag_clock_.period_ns));
    }
    if (sensors.gps) {
      if (Status s = clock(sensors.gps->rate_hz, "sensors.gps.rate_hz", &gps_clock_); !s.ok()) return s;
      gps_noise_.SetCorrelation(sensors.gps->noise_correlation_s, 1e-9 * static_cast<double>(gps_clock_.period_ns));
    }
    if (sensors.mocap) {
      if (Status s = clock(sensors.mocap->rate_hz, "sensors.mocap.rate_hz", &mocap_clock_); !s.ok()) return s;
      const double period_s = 1e-9 * static_cast<double>(mocap_clock_.period_ns);
      mocap_position_noise_.SetCorrelation(sensors.mocap->noise_correlation_s, period_s);
      mocap_orientation_noise_.SetCorrelation(sensors.mocap->noise_correlation_s, period_s);
    }
    if (sensors.odometer) {
      if (Status s = clock(sensors.odometer->rate_hz, "sensors.odometer.rate_hz", &odometer_clock_); !s.ok()) return s;
      const double period_s = 1e-9 * static_cast<double>(odometer_clock_.period_ns);
      speed_noise_.SetCorrelation(sensors.odometer->noise_correlation_s, period_s);
      steering_noise_.SetCorrelation(sensors.odometer->noise_correlation_s, period_s);
    }
    if (sensors.wheel_encoders) {
      if (Status s = clock(sensors.wheel_encoders->rate_hz, "sensors.wheel_encoders.rate_hz", &encoder_clock_); !s.ok())
        return s;
    }
    if (sensors.laser) {
      if (Status s = clock(sensors.laser->rate_hz, "sensors.laser.rate_hz", &laser_clock_); !s.ok()) return s;
      const LaserOptions& l = *sensors.laser;
      const double fov = l.fov_deg * kPi / 180.0;
      scan_geometry_.beams = l.beams;
      scan_geometry_.first_angle_rad = -0.5 * fov;
      scan_geometry_.increment_rad = fov / (l.beams - 1);
      scan_geometry_.min_range_m = l.min_range_m;
      scan_geometry_.max_range_m = l.max_range_m;
    }
    if (ackermann_) wheelbase_m_ = Micrometres(vehicle_.wheelbase_m());
    return ScheduleClocks();
  }

  // A replay's streams at the recording's stamps (sim/replay_schedule.h).
  Status ScheduleClocks() {
    if (!options_.replay) return Status::Ok();
    const ReplaySchedule& replay = *options_.replay;
    origin_ns_ = replay.t0.nanoseconds();
    const DriveInputs& drive = replay.drive;
    if (drive.t.empty() || drive.values.rows() != static_cast<Eigen::Index>(drive.t.size()))
      return Status::Error(where_ + ": the replay has no drive inputs");
    using Kind = DriveInputs::Kind;
    const Eigen::Index columns = drive.kind == Kind::kAckermann ? 2
                                 : drive.kind == Kind::kBodyVelocity
                                     ? 3
                                     : static_cast<Eigen::Index>(wheeled_.wheels().size());
    if (ackermann_ != (drive.kind == Kind::kAckermann) || drive.values.cols() != columns ||
        (drive.angles_rad.size() > 0 && drive.angles_rad.rows() != drive.values.rows()) ||
        (drive.angles_rad.size() > 0 && drive.angles_rad.cols() != columns) ||
        (drive.travel_m.size() > 0 && drive.travel_m.size() != drive.values.rows()))
      return Status::Error(where_ + ": the replay's drive inputs do not fit a robot of kind " + scenario_.robot.kind);
    const std::map<std::string, Clock*> clocks{{"imu", &imu_clock_},           {"magnetometer", &mag_clock_},
                                               {"gps", &gps_clock_},           {"rear_wheel", &odometer_clock_},
                                               {"steering", &odometer_clock_}, {"wheel_encoders", &encoder_clock_},
                                               {"mocap", &mocap_clock_},       {"odometry", &odometry_clock_}};
    for (const auto& [name, stamps] : replay.stamps) {
      const auto it = clocks.find(name);
      if (it == clocks.end()) return Status::Error(where_ + ": the replay schedules an unknown stream '" + name + "'");
      if (stamps.empty() || stamps.front() < replay.t0)
        return Status::Error(where_ + ": the replay's stream '" + name + "' has no stamps at or after its start");
      internal::Schedule(stamps, replay.t0, step_ns_, it->second);
    }
    return Status::Ok();
  }

  // The streams, laid out as tests/support/synthetic.h lays them out.
  void SetupStreams() {
    const SensorOptions& sensors = scenario_.sensors;
    if (sensors.imu) {
      imu_stream_ = MakeStream("imu", StreamType::kImu, sensors.imu->rate_hz, {"wx", "wy", "wz", "ax", "ay", "az"}, "",
                               imu_clock_);
      imu_stream_.info.mounting = recording::Mounting{};
      imu_stream_.info.noise = {{"gyro_sigma_radps", sensors.imu->gyro_sigma_radps},
                                {"accel_sigma_mps2", sensors.imu->accel_sigma_mps2}};
    }
    if (sensors.magnetometer) {
      mag_stream_ = MakeStream("magnetometer", StreamType::kMagnetometer, sensors.magnetometer->rate_hz,
                               {"mx", "my", "mz"}, "normalized", mag_clock_, origin());
      mag_stream_.info.mounting = recording::Mounting{};
      mag_stream_.info.noise = {{"sigma_normalized", sensors.magnetometer->sigma}};
    }
    if (sensors.gps) {
      gps_stream_ = MakeStream("gps", StreamType::kGps, sensors.gps->rate_hz, {"latitude", "longitude", "altitude"},
                               "deg", gps_clock_, origin());
      gps_stream_.info.mounting = recording::Mounting{};
      gps_stream_.info.noise = {{"sigma_m", sensors.gps->sigma_m}};
    }
    if (sensors.mocap) {
      mocap_stream_ = MakeStream("mocap", StreamType::kPose, sensors.mocap->rate_hz,
                                 {"x", "y", "z", "qx", "qy", "qz", "qw"}, "m", mocap_clock_, origin());
      mocap_stream_.info.noise = {{"position_m", sensors.mocap->position_sigma_m},
                                  {"orientation_rad", sensors.mocap->orientation_sigma_rad}};
    }
    if (sensors.wheel_encoders) {
      std::vector<std::string> columns;
      for (const EncoderColumn& c : encoder_columns_) columns.push_back(c.name);
      encoder_stream_ = MakeStream(sensors.wheel_encoders->name, StreamType::kWheelEncoders,
                                   sensors.wheel_encoders->rate_hz, columns, "rad", encoder_clock_, origin());
      encoder_stream_.info.attributes = {{"ticks_per_revolution", sensors.wheel_encoders->ticks_per_revolution}};
    }
    if (sensors.laser) {
      scan_matching_.emplace("scan_matching", sensors.laser->rate_hz);
      if (sensors.laser->store_scans) {
        laser_scan_stream_ =
            MakeStream("laser_scan", StreamType::kLaserScan, sensors.laser->rate_hz,
                       recording::LaserScanColumns(sensors.laser->beams), "rad,m", laser_clock_, origin());
      }
    }
    if (sensors.odometer) {
      wheel_stream_ = MakeStream("rear_wheel", StreamType::kWheelEncoders, sensors.odometer->rate_hz, {"rear"}, "m/s",
                                 odometer_clock_, origin());
      wheel_stream_.info.noise = {{"sigma_mps", sensors.odometer->speed_sigma_mps}};
      steering_stream_ = MakeStream("steering", StreamType::kSteering, sensors.odometer->rate_hz, {"angle"}, "rad",
                                    odometer_clock_, origin());
      steering_stream_.info.noise = {{"sigma_rad", sensors.odometer->steering_sigma_rad}};
    }
    if (odometry_clock_.scheduled() && !ackermann_) {
      odometry_stream_ = MakeStream("odometry", StreamType::kOdometry, 0.0,
                                    recording::FixedColumns(StreamType::kOdometry), "", odometry_clock_, origin());
      twist_from_rates_ = wheeled_.J_rates_twist().completeOrthogonalDecomposition().pseudoInverse();
    }
    local_.emplace(scenario_.origin.latitude_deg, scenario_.origin.longitude_deg, scenario_.origin.altitude_m);
    truth_.reserve(truth_clock_.samples);
  }

  // The vehicle at rest at the start pose.
  void PlaceRobot() {
    if (ackermann_) {
      vehicle_.Place(model_.get(), data_.get(), terrain_, scenario_.robot.start_position_m.x(),
                     scenario_.robot.start_position_m.y(), scenario_.robot.start_heading_rad, kPlacementClearanceM);
    } else {
      wheeled_.Place(model_.get(), data_.get(), scenario_.robot.start_position_m.x(),
                     scenario_.robot.start_position_m.y(), scenario_.robot.start_heading_rad, kPlacementClearanceM);
      if (scenario_.sensors.laser) laser_mounting_ = SiteInOdom(wheeled_.laser_site());
    }
  }

  // The set-points at t_ns (Ackermann: speed [m/s], handlebar [rad] and 0; body velocity: v_x [m/s], omega_z
  // [rad/s] and v_y [m/s]): the profiles from t = 0, the lead-in's rest and ramp before.
  std::array<double, 3> SetPoints(std::int64_t t_ns) const {
    if (options_.replay) {
      const DriveInputs::Kind kind = options_.replay->drive.kind;
      if (kind == DriveInputs::Kind::kWheelRates) return {0.0, 0.0, 0.0};  // ReplayWheelRates drives
      const Eigen::VectorXd u = ReplayInputs(t_ns);
      if (kind == DriveInputs::Kind::kBodyVelocity) return {u[0], u[2], u[1]};
      return {u[0], u[1], 0.0};
    }
    const DriverOptions& driver = scenario_.driver;
    const Profile& first = ackermann_ ? driver.speed_mps : driver.linear_mps;
    const Profile& second = ackermann_ ? driver.handlebar_rad : driver.angular_radps;
    const Profile none;  // no terms: 0
    const Profile& third = ackermann_ ? none : driver.lateral_mps;
    if (t_ns >= 0) {
      const double t = static_cast<double>(t_ns) * 1e-9;
      return {first.Evaluate(t), second.Evaluate(t), third.Evaluate(t)};
    }
    const double phase = static_cast<double>(t_ns + lead_in_ns_) / static_cast<double>(lead_in_ns_);
    const double ramp = std::clamp((phase - kLeadInRestFraction) / (1.0 - kLeadInRestFraction), 0.0, 1.0);
    return {ramp * first.Evaluate(0.0), ramp * second.Evaluate(0.0), ramp * third.Evaluate(0.0)};
  }

  // The recording time whose drive inputs hold at simulation time t_ns >= 0: t0 + t_ns, plus drive_time_offset's
  // shift (inputs stamped late are read that much later) and its drift (the drive's clock running drift_ppm faster
  // than the others since t = 0).
  Time DriveStamp(std::int64_t t_ns) const {
    const auto drift_ns = std::llround(drive_drift_ * static_cast<double>(t_ns));
    return Time::FromNanoseconds(origin_ns_ + t_ns + drive_shift_ns_ + drift_ns);
  }

  // A replay's drive inputs at t_ns: the recording's from t = 0, rest before (sim/replay_schedule.h). The rates and
  // speeds among them are per unit of the drive's clock, so a drifting clock scales them by 1 + drift; the handlebar
  // angle is not a rate.
  Eigen::VectorXd ReplayInputs(std::int64_t t_ns) const {
    const DriveInputs& drive = options_.replay->drive;
    if (t_ns < 0) return Eigen::VectorXd::Zero(drive.values.cols());
    Eigen::VectorXd u = drive.At(DriveStamp(t_ns));
    if (drive.kind == DriveInputs::Kind::kAckermann)
      u[0] *= 1.0 + drive_drift_;
    else
      u *= 1.0 + drive_drift_;
    return u;
  }

  // A replay's wheel-rate targets at t_ns: the measured rates, plus the tracking of the measured angles.
  Eigen::VectorXd ReplayWheelRates(std::int64_t t_ns) {
    Eigen::VectorXd rates = ReplayInputs(t_ns);
    const DriveInputs& drive = options_.replay->drive;
    if (t_ns < 0 || drive.angles_rad.size() == 0) return rates;
    const auto wheels = static_cast<Eigen::Index>(wheeled_.wheels().size());
    Eigen::VectorXd twin_angles(wheels);
    for (Eigen::Index i = 0; i < wheels; ++i) twin_angles[i] = wheeled_.WheelAngle(data_.get(), static_cast<int>(i));
    if (replay_angles_at_start_.size() == 0) {
      replay_angles_at_start_ = twin_angles;
      measured_angles_at_start_ = drive.AnglesAt(DriveStamp(0));
    }
    const Eigen::VectorXd measured = drive.AnglesAt(DriveStamp(t_ns)) - measured_angles_at_start_;
    return rates + (measured - (twin_angles - replay_angles_at_start_)) / kAngleTrackingS;
  }

  // A replay's correction of the Ackermann speed set-point [m/s] that tracks the measured travel; advances the twin's
  // travel by its rear-wheel speed over the coming step. 0 without a replay of measured speeds.
  double ReplayTravelCorrection(double rear_speed_mps, double dt_s) {
    if (!options_.replay || options_.replay->drive.travel_m.size() == 0 || t_ns_ < 0) return 0.0;
    const DriveInputs& drive = options_.replay->drive;
    const double measured_m = drive.TravelAt(DriveStamp(t_ns_)) - drive.TravelAt(DriveStamp(0));
    const double correction = (measured_m - replay_travel_m_) / kAngleTrackingS;
    replay_travel_m_ += rear_speed_mps * dt_s;
    return correction;
  }

  // What the rear-wheel speed sensor reads per unit of the twin's rear-wheel speed (the drive tires' slip and growth at
  // the last odometer sample) in a replay of measured speeds, whose set-points are readings; 1 otherwise.
  double ReplaySpeedReadingFactor() const {
    if (!options_.replay || options_.replay->drive.travel_m.size() == 0) return 1.0;
    return speed_reading_factor_;
  }

  // Pose of a robot site in O, measured at the current state (the robot is rigid between them).
  recording::Mounting SiteInOdom(int site) const {
    const FrameKinematics odom = ReadSiteKinematics(model_.get(), data_.get(), odom_site_);
    const FrameKinematics sensor = ReadSiteKinematics(model_.get(), data_.get(), site);
    recording::Mounting m;
    const Eigen::Vector3d p = odom.q_world_body.conjugate() * (sensor.p_world_body - odom.p_world_body);
    m.p_body_sensor = p.unaryExpr([](double x) { return Micrometres(x); });
    m.q_body_sensor = (odom.q_world_body.conjugate() * sensor.q_world_body).normalized();
    return m;
  }

  // Effects (scenario.h): time shifts move the instants at which samples are taken; the others change the synthesis.
  Status SetupEffects() {
    const std::vector<EffectOptions>& effects = scenario_.effects;
    const auto steps = [this](double seconds, const std::string& key, std::int64_t* out) {
      const std::int64_t ns = std::llround(seconds * 1e9);
      if (ns % step_ns_ != 0)
        return Status::Error(where_ + ": " + key + ": " + std::to_string(seconds) +
                             " s is not a whole number of physics steps");
      *out = ns;
      return Status::Ok();
    };
    if (Status s = steps(EffectParameter(effects, "gps_latency", "latency_s", 0.0), "gps_latency.latency_s",
                         &gps_clock_.shift_ns);
        !s.ok())
      return s;
    if (Status s = steps(EffectParameter(effects, "imu_time_offset", "offset_s", 0.0), "imu_time_offset.offset_s",
                         &imu_clock_.shift_ns);
        !s.ok())
      return s;
    if (Status s = steps(EffectParameter(effects, "pose_time_offset", "offset_s", 0.0), "pose_time_offset.offset_s",
                         &mocap_clock_.shift_ns);
        !s.ok())
      return s;
    mag_clock_.shift_ns = imu_clock_.shift_ns;  // the magnetometer shares the IMU's clock
    const double drive_shift_s = EffectParameter(effects, "drive_time_offset", "offset_s", 0.0);
    if (drive_shift_s != 0.0 && !options_.replay)
      return Status::Error(where_ + ": drive_time_offset shifts a replay's recorded drive inputs; this run drives the "
                                    "scenario's own schedule");
    drive_shift_ns_ = std::llround(drive_shift_s * 1e9);
    drive_drift_ = EffectParameter(effects, "drive_time_offset", "drift_ppm", 0.0) * 1e-6;
    if (drive_drift_ != 0.0 && !options_.replay)
      return Status::Error(where_ + ": drive_time_offset's drift moves a replay's recorded drive inputs; this run "
                                    "drives the scenario's own schedule");
    // A sample taken after the end of the drive (negative shift) extends the physics past it.
    loop_end_ns_ = end_ns_ + std::max<std::int64_t>(
                                 0, -std::min({imu_clock_.shift_ns, gps_clock_.shift_ns, mocap_clock_.shift_ns}));
    // A replay's sample nearest a stamp may fall after the end.
    for (const Clock* c :
         {&imu_clock_, &mag_clock_, &gps_clock_, &mocap_clock_, &odometer_clock_, &encoder_clock_, &odometry_clock_})
      if (c->scheduled()) loop_end_ns_ = std::max(loop_end_ns_, c->LastSampleNs());
    steering_offset_rad_ = EffectParameter(effects, "steering_offset", "offset_rad", 0.0);
    for (int i = 0; i < 3; ++i) {
      const std::string axis(1, "xyz"[i]);
      gyro_scale_[i] = EffectParameter(effects, "gyro_scale_error", "scale_" + axis, 1.0);
      mag_per_nm_[i] = EffectParameter(effects, "magnetometer_motor_interference", "b_per_nm_" + axis, 0.0);
      gyro_bias_radps_[i] = EffectParameter(effects, "gyro_bias_drift", "initial_" + axis, 0.0);
      accel_scale_[i] = EffectParameter(effects, "accelerometer_scale_error", "scale_" + axis, 1.0);
    }
    gyro_bias_walk_ = EffectParameter(effects, "gyro_bias_drift", "random_walk", 0.0);
    multipath_sigma_m_ = EffectParameter(effects, "gps_multipath", "sigma_m", 0.0);
    multipath_correlation_s_ = EffectParameter(effects, "gps_multipath", "correlation_s", 5.0);
    // The Gauss-Markov error starts in its stationary distribution, N(0, sigma^2) per axis.
    multipath_m_ = multipath_noise_.Draw3(multipath_sigma_m_);
    tire_growth_per_mps2_ = EffectParameter(effects, "tire_growth", "growth_per_mps2", 0.0);
    slip_per_mps2_ = EffectParameter(effects, "longitudinal_slip", "slip_per_mps2", 0.0);
    slope_slip_per_mps2_ = EffectParameter(effects, "slope_slip", "slip_per_mps2", 0.0);
    odometry_scale_ = EffectParameter(effects, "odometry_scale_error", "scale", 1.0);
    for (const EffectOptions& e : effects) {
      recording::Effect truth{e.name, KnownEffects().at(e.name)};
      for (const auto& [name, value] : e.parameters) truth.parameters[name] = value;
      if (ackermann_ && e.name == "axle_misalignment") truth.parameters.erase("wheel");  // the rear axle
      out_.truth.effects.push_back(truth);
    }
    return Status::Ok();
  }

  Status Loop() {
    const mjModel* m = model_.get();
    mjData* d = data_.get();
    const double dt_s = static_cast<double>(step_ns_) * 1e-9;
    const long total_steps = static_cast<long>((end_ns_ + lead_in_ns_) / step_ns_);
    long done = 0;
    long next_progress = 0;
    // End of the lead-in's rest (the robot has settled on its wheels).
    const std::int64_t camera_start_ns =
        std::min<std::int64_t>(0, -lead_in_ns_ + std::llround(kLeadInRestFraction * static_cast<double>(lead_in_ns_)));
    for (t_ns_ = -lead_in_ns_; t_ns_ <= loop_end_ns_; t_ns_ += step_ns_) {
      // Driver and low-level control.
      const auto [first, second, third] = SetPoints(t_ns_);
      if (ackermann_) {
        const double measured = vehicle_.RearWheelRate(d) * vehicle_.wheel_radius_m();
        const double correction = ReplayTravelCorrection(ReplaySpeedReadingFactor() * measured, dt_s);
        drive_torque_nm_ = controller_->Update(first + correction, measured, dt_s);
        vehicle_.Apply(second, drive_torque_nm_, d);
      } else if (options_.replay && options_.replay->drive.kind == DriveInputs::Kind::kWheelRates) {
        wheeled_.ApplyWheelRates(ReplayWheelRates(t_ns_), d);
      } else {
        wheeled_.Apply(first, third, second, d);
      }

      if (scenario_.sensors.camera && camera_ == nullptr && t_ns_ >= camera_start_ns) {
        mj_forward(m, d);
        if (Status s = StartCamera(); !s.ok()) return s;
      }

      // Sensors due now, on the state at t completed by forward dynamics.
      if (AnyDue(t_ns_)) {
        mj_forward(m, d);
        mj_rnePostConstraint(m, d);
        if (Status s = Sample(t_ns_); !s.ok()) return s;
        if (CameraDue(t_ns_)) {
          const auto frame = camera_->Observe(Time::FromNanoseconds(t_ns_), d);
          if (!frame.ok()) return frame.status();
          while (CameraFrameNs(next_camera_frame_) <= t_ns_) ++next_camera_frame_;
        }
        if (options_.observer) options_.observer(Time::FromNanoseconds(t_ns_), m, d);
      }
      if (t_ns_ == loop_end_ns_) break;

      // One physics step.
      mj_step(m, d);
      ++done;
      if (InterruptRequested()) return InterruptedError();
      if (d->warning[mjWARN_BADQACC].number > 0) {
        return Status::Error(model_where_ + ": the simulation diverged at t = " + FormatTime(t_ns_) +
                             " (MuJoCo: bad acceleration)");
      }
      if (options_.progress && done >= next_progress) {
        options_.progress(static_cast<double>(done) / static_cast<double>(std::max(total_steps, 1L)));
        next_progress += std::max(total_steps / 100, 1L);
      }
    }
    out_.stats.physics_steps = done;
    out_.stats.simulated_s = static_cast<double>(end_ns_ + lead_in_ns_) * 1e-9;
    if (options_.progress) options_.progress(1.0);
    return Status::Ok();
  }

  bool AnyDue(std::int64_t t_ns) const {
    return truth_clock_.Due(t_ns) || imu_clock_.Due(t_ns) || mag_clock_.Due(t_ns) || gps_clock_.Due(t_ns) ||
           mocap_clock_.Due(t_ns) || odometer_clock_.Due(t_ns) || encoder_clock_.Due(t_ns) || laser_clock_.Due(t_ns) ||
           odometry_clock_.Due(t_ns) || CameraDue(t_ns);
  }

  // Camera frame k is due at the first step at or after k / rate_hz (rounded to the nanosecond, not accumulated):
  // the schedule SimulatedCamera::Observe keeps when its first call is at t = 0.
  std::int64_t CameraFrameNs(std::int64_t k) const {
    return std::llround(1e9 * static_cast<double>(k) / scenario_.sensors.camera->rate_hz);
  }
  bool CameraDue(std::int64_t t_ns) const { return camera_ != nullptr && t_ns >= CameraFrameNs(next_camera_frame_); }

  // The camera and its visual odometry, created once the robot rests on the floor (the end of the lead-in's rest), so
  // that the camera's height over the floor and its mounting are those of the settled robot. Mounting in O (the
  // stream's own reference is a body).
  Status StartCamera() {
    const CameraOptions& c = *scenario_.sensors.camera;
    SimulatedCameraOptions o;
    o.camera = kCameraName;
    o.rate_hz = c.rate_hz;
    o.render.width_px = c.width_px;
    o.render.height_px = c.height_px;
    if (c.store_images) o.image_directory = options_.image_directory;
    auto stream = SimulatedCamera::Create(model_.get(), data_.get(), o);
    if (!stream.ok()) return Status::Error(model_where_ + ": sensors.camera: " + stream.status().message());
    camera_ = std::move(stream).value();
    const FrameKinematics odom = ReadSiteKinematics(model_.get(), data_.get(), odom_site_);
    const CameraPose pose = CameraPoseInWorld(model_.get(), data_.get(), camera_->camera_id());
    const Eigen::Vector3d p = odom.q_world_body.conjugate() * (pose.p_world_camera_m - odom.p_world_body);
    camera_mounting_.p_body_sensor = p.unaryExpr([](double x) { return Micrometres(x); });
    camera_mounting_.q_body_sensor =
        (odom.q_world_body.conjugate() * Eigen::Quaterniond(pose.R_world_camera)).normalized();
    out_.stats.camera_height_m = camera_->vo_options().camera_height_m;
    return Status::Ok();
  }

  // Synthesizes every stream due at t_ns from the current (completed) state.
  Status Sample(std::int64_t t_ns) {
    const FrameKinematics body = ReadSiteKinematics(model_.get(), data_.get(), odom_site_);
    const SensorOptions& sensors = scenario_.sensors;

    if (truth_clock_.Due(t_ns)) {
      if (Status s = CheckVehicle(body, t_ns); !s.ok()) return s;
      StampedPose pose{Time::FromNanoseconds(origin_ns_ + t_ns), body.p_world_body, body.q_world_body};
      // Keep the quaternion sign continuous so that the TUM file has no jumps.
      if (!truth_.empty() && truth_.back().q_world_body.dot(pose.q_world_body) < 0.0)
        pose.q_world_body.coeffs() = -pose.q_world_body.coeffs();
      if (!truth_.empty()) out_.stats.distance_m += (pose.p_world_body - truth_.back().p_world_body).norm();
      truth_.push_back(pose);
      UpdateMotionStats(body);
    }
    if (imu_clock_.Due(t_ns)) {
      const Eigen::Vector3d gyro = gyro_scale_.cwiseProduct(GyroReading(body, imu_)) + gyro_bias_radps_ +
                                   gyro_noise_.Draw3(sensors.imu->gyro_sigma_radps);
      if (gyro_bias_walk_ > 0.0) {
        const double period_s = 1e-9 * static_cast<double>(imu_clock_.period_ns);
        gyro_bias_radps_ += gyro_bias_noise_.Draw3(gyro_bias_walk_ * std::sqrt(period_s));
      }
      const Eigen::Vector3d accel =
          accel_scale_.cwiseProduct(AccelReading(body, imu_)) + accel_noise_.Draw3(sensors.imu->accel_sigma_mps2);
      imu_stream_.values.row(imu_clock_.Row(t_ns)) << gyro.transpose(), accel.transpose();
    }
    if (mag_clock_.Due(t_ns)) {
      const Eigen::Vector3d z = MagnetometerReading(body, imu_.q_body_imu, magnetometer_) +
                                mag_per_nm_ * drive_torque_nm_ + mag_noise_.Draw3(sensors.magnetometer->sigma);
      mag_stream_.values.row(mag_clock_.Row(t_ns)) = z.transpose();
    }
    if (gps_clock_.Due(t_ns)) {
      const Eigen::Vector3d antenna =
          GpsAntennaWorld(body, sensors.gps->lever_arm_m) + multipath_m_ + gps_noise_.Draw3(sensors.gps->sigma_m);
      if (multipath_sigma_m_ > 0.0) {
        // gps_multipath: e(t_k+1) = a e(t_k) + sigma sqrt(1 - a^2) n keeps the stationary std sigma (scenario.h).
        const double a = std::exp(-1e-9 * static_cast<double>(gps_clock_.period_ns) / multipath_correlation_s_);
        multipath_m_ = a * multipath_m_ + multipath_noise_.Draw3(multipath_sigma_m_ * std::sqrt(1.0 - a * a));
      }
      double latitude = 0.0, longitude = 0.0, altitude = 0.0;
      local_->Reverse(antenna.x(), antenna.y(), antenna.z(), latitude, longitude, altitude);
      gps_stream_.values.row(gps_clock_.Row(t_ns)) << latitude, longitude, altitude;
    }
    if (mocap_clock_.Due(t_ns)) SampleMocap(body, t_ns);
    if (encoder_clock_.Due(t_ns)) {
      // Cumulative angle since t = 0 (times odometry_scale_error's scale), truncated to whole ticks (an incremental
      // encoder's count).
      const double tick_rad = 2.0 * kPi / sensors.wheel_encoders->ticks_per_revolution;
      const int columns = static_cast<int>(encoder_columns_.size());
      if (encoder_zero_rad_.empty()) {  // the first sample: t = 0, or a replay's first stamp
        for (const EncoderColumn& c : encoder_columns_)
          encoder_zero_rad_.push_back(wheeled_.WheelAngle(data_.get(), c.wheel));
      }
      for (int k = 0; k < columns; ++k) {
        const auto column = static_cast<std::size_t>(k);
        const double angle = odometry_scale_ * (wheeled_.WheelAngle(data_.get(), encoder_columns_[column].wheel) -
                                                encoder_zero_rad_[column]);
        encoder_stream_.values(encoder_clock_.Row(t_ns), k) = std::floor(angle / tick_rad) * tick_rad;
      }
    }
    if (laser_clock_.Due(t_ns)) SampleLaser(t_ns);
    if (odometry_clock_.Due(t_ns)) {
      // Wheel odometry: the twist the nominal kinematics gives for the wheels' rates (least squares), times
      // odometry_scale_error's scale.
      Eigen::VectorXd rates(static_cast<Eigen::Index>(wheeled_.wheels().size()));
      for (Eigen::Index i = 0; i < rates.size(); ++i) rates[i] = wheeled_.WheelRate(data_.get(), static_cast<int>(i));
      const Eigen::Vector3d twist = odometry_scale_ * (twist_from_rates_ * rates);  // v_x, v_y, omega_z
      odometry_stream_.values.row(odometry_clock_.Row(t_ns)) << twist[0], twist[1], 0.0, 0.0, 0.0, twist[2];
    }
    if (odometer_clock_.Due(t_ns)) {
      const OdometerOptions& odo = *sensors.odometer;
      // tire_growth: the rigid MuJoCo tire rolls at omega = v / r0; a tire of radius r0 (1 + c v^2) turns at
      // omega / (1 + c v^2) at the same ground speed v = r0 omega. longitudinal_slip and slope_slip: the driven tire
      // turns faster than it rolls by 1 + s_f f_x + s_p g sin(pitch) (f_x: O's true forward specific force; pitch:
      // O's forward axis above the horizontal). odometry_scale_error: the speed reads its scale times that.
      const double omega_radps = vehicle_.RearWheelRate(data_.get());
      const double v_mps = omega_radps * vehicle_.wheel_radius_m();
      const double g_mps2 = Eigen::Map<const Eigen::Vector3d>(model_->opt.gravity).norm();
      const double slip = 1.0 + slip_per_mps2_ * body.specific_force_body.x() +
                          slope_slip_per_mps2_ * g_mps2 * (body.q_world_body * Eigen::Vector3d::UnitX()).z();
      speed_reading_factor_ = slip / (1.0 + tire_growth_per_mps2_ * v_mps * v_mps);
      const double z_v =
          odometry_scale_ * SpeedReading(slip * omega_radps / (1.0 + tire_growth_per_mps2_ * v_mps * v_mps),
                                         vehicle_.wheel_radius_m(), odo.kv_over_L, wheelbase_m_) +
          speed_noise_.Draw(odo.speed_sigma_mps);
      const double z_theta =
          SteeringReading(vehicle_.SteeringAngle(data_.get()), odo.k_theta, odo.k_gamma + steering_offset_rad_) +
          steering_noise_.Draw(odo.steering_sigma_rad);
      wheel_stream_.values(odometer_clock_.Row(t_ns), 0) = z_v;
      steering_stream_.values(odometer_clock_.Row(t_ns), 0) = z_theta;
    }
    return Status::Ok();
  }

  // One motion-capture pose of O: position noise per axis, the orientation turned by a small rotation vector; the
  // quaternion's sign kept continuous.
  void SampleMocap(const FrameKinematics& body, std::int64_t t_ns) {
    const MocapOptions& o = *scenario_.sensors.mocap;
    const Eigen::Vector3d p = body.p_world_body + mocap_position_noise_.Draw3(o.position_sigma_m);
    const Eigen::Vector3d turn = mocap_orientation_noise_.Draw3(o.orientation_sigma_rad);
    Eigen::Quaterniond q = body.q_world_body;
    if (turn.norm() > 0.0) q = q * Eigen::Quaterniond(Eigen::AngleAxisd(turn.norm(), turn.normalized()));
    const Eigen::Index row = mocap_clock_.Row(t_ns);
    if (row > 0) {
      const Eigen::Vector4d previous = mocap_stream_.values.row(row - 1).tail<4>().transpose();
      if (previous.dot(q.coeffs()) < 0.0) q.coeffs() = -q.coeffs();
    }
    mocap_stream_.values.row(row) << p.transpose(), q.x(), q.y(), q.z(), q.w();
  }

  // One laser scan: ray casts plus range noise, stored when the scenario asks; the scan matcher's stream takes it
  // (frontend/scan_matching_stream.h).
  void SampleLaser(std::int64_t t_ns) {
    const LaserOptions& l = *scenario_.sensors.laser;
    std::vector<double> ranges = CastScan(model_.get(), data_.get(), wheeled_.laser_site(), scan_geometry_);
    for (double& r : ranges) {
      const double noise = laser_noise_.Draw(l.sigma_m);  // drawn for every beam, so returns never shift the stream
      if (std::isfinite(r)) r += noise;
    }
    if (l.store_scans) laser_scan_stream_.values.row(laser_clock_.Row(t_ns)) = LaserScanRow(scan_geometry_, ranges);
    scan_matching_->AddScan(Time::FromNanoseconds(t_ns), scan_geometry_, std::move(ranges));
  }

  // The drive must stay on the heightfield and upright.
  Status CheckVehicle(const FrameKinematics& body, std::int64_t t_ns) const {
    if (!terrain_.Contains(body.p_world_body.x(), body.p_world_body.y(), kTerrainMarginM)) {
      return Status::Error(where_ + ": the vehicle left the terrain at t = " + FormatTime(t_ns) +
                           " (enlarge world.terrain.size_m or change the drive)");
    }
    if ((body.q_world_body * Eigen::Vector3d::UnitZ()).z() < kRolloverCosine) {
      return Status::Error(where_ + ": the vehicle rolled over at t = " + FormatTime(t_ns) +
                           " (gentler driver profiles or terrain)");
    }
    return Status::Ok();
  }

  void UpdateMotionStats(const FrameKinematics& body) {
    SimulationStats& st = out_.stats;
    const Eigen::Matrix3d R = body.q_world_body.toRotationMatrix();
    st.max_abs_pitch_rad = std::max(st.max_abs_pitch_rad, std::abs(std::asin(std::clamp(-R(2, 0), -1.0, 1.0))));
    st.max_abs_roll_rad = std::max(st.max_abs_roll_rad, std::abs(std::atan2(R(2, 1), R(2, 2))));
    st.max_lateral_speed_mps = std::max(st.max_lateral_speed_mps, std::abs(body.v_body.y()));
    if (ackermann_) {
      const double rim = vehicle_.RearWheelRate(data_.get()) * vehicle_.wheel_radius_m();
      st.max_wheel_slip_mps = std::max(st.max_wheel_slip_mps, std::abs(rim - body.v_body.x()));
    } else {
      // Rim speed against the speed of the ground point below the wheel, along the direction the wheel is locked
      // in (the rolling direction for a standard or omni wheel), in rim units: r (omega_i - J_i twist).
      for (std::size_t i = 0; i < wheeled_.wheels().size(); ++i) {
        const WheelGeometry& w = wheeled_.wheels()[i];
        const Eigen::Vector2d v_point =
            body.v_body.head<2>() + body.omega_body.z() * Eigen::Vector2d(-w.p_body_m.y(), w.p_body_m.x());
        const double rim = wheeled_.WheelRate(data_.get(), static_cast<int>(i)) * w.radius_m;
        const double ground = w.locked_direction.dot(v_point) / w.locked_direction.dot(w.drive_direction);
        st.max_wheel_slip_mps = std::max(st.max_wheel_slip_mps, std::abs(rim - ground));
      }
    }
    min_height_ = std::min(min_height_, body.p_world_body.z());
    max_height_ = std::max(max_height_, body.p_world_body.z());
  }

  // Assembles the recording and the truth.
  void Finish() {
    const SensorOptions& sensors = scenario_.sensors;
    recording::Recording& rec = out_.recording;
    rec.platform.kind = scenario_.robot.kind;
    rec.platform.geometry = PlatformGeometry();
    rec.origin = scenario_.origin;
    rec.provenance = internal::SimulatedProvenance(scenario_, seed_, model_where_, options_.noise);
    internal::FillRepeatedRows(imu_clock_, &imu_stream_);
    internal::FillRepeatedRows(mag_clock_, &mag_stream_);
    internal::FillRepeatedRows(gps_clock_, &gps_stream_);
    internal::FillRepeatedRows(odometer_clock_, &wheel_stream_);
    internal::FillRepeatedRows(odometer_clock_, &steering_stream_);
    internal::FillRepeatedRows(encoder_clock_, &encoder_stream_);
    internal::FillRepeatedRows(mocap_clock_, &mocap_stream_);
    internal::FillRepeatedRows(odometry_clock_, &odometry_stream_);
    if (sensors.imu) rec.streams.push_back(std::move(imu_stream_));
    if (sensors.magnetometer) rec.streams.push_back(std::move(mag_stream_));
    if (sensors.gps) rec.streams.push_back(std::move(gps_stream_));
    if (sensors.mocap) rec.streams.push_back(std::move(mocap_stream_));
    if (sensors.odometer) {
      rec.streams.push_back(std::move(wheel_stream_));
      rec.streams.push_back(std::move(steering_stream_));
    }
    if (sensors.wheel_encoders) rec.streams.push_back(std::move(encoder_stream_));
    if (odometry_clock_.scheduled() && !ackermann_) rec.streams.push_back(std::move(odometry_stream_));
    if (sensors.laser) {
      recording::Stream scan_stream = scan_matching_->TakeStream();
      scan_stream.info.mounting = laser_mounting_;
      out_.stats.failed_scan_matches = scan_matching_->failed_matches();
      rec.streams.push_back(std::move(scan_stream));
      if (sensors.laser->store_scans) {
        laser_scan_stream_.info.mounting = laser_mounting_;
        rec.streams.push_back(std::move(laser_scan_stream_));
      }
    }
    if (camera_ != nullptr) {
      recording::Stream vo = camera_->TakeStream();
      vo.info.mounting = camera_mounting_;
      rec.streams.push_back(std::move(vo));
      if (auto images = camera_->TakeCameraStream()) {
        images->info.mounting = camera_mounting_;
        rec.streams.push_back(std::move(*images));
      }
      out_.stats.visual_odometry = camera_->counters();
    }
    rec.ground_truth = std::move(truth_);

    // True calibration.
    internal::TrueSensorFrames frames{imu_, magnetometer_, {}, laser_mounting_, std::nullopt};
    if (sensors.wheel_encoders) frames.wheels = wheeled_.TrueOdometerCalibration();
    if (ackermann_) frames.rear_rolling_over_radius = rear_rolling_radius_m_ / vehicle_.wheel_radius_m();
    if (camera_ != nullptr) frames.camera = camera_mounting_;
    out_.truth.calibration = internal::TrueCalibration(sensors, frames);
    out_.stats.terrain_relief_m = terrain_.Relief();
    out_.stats.path_height_range_m = max_height_ >= min_height_ ? max_height_ - min_height_ : 0.0;
  }

  const Scenario scenario_;
  const SimulateOptions options_;
  const std::uint64_t seed_;
  const std::string where_;        // the scenario, for messages
  const std::string model_where_;  // the robot model, for messages
  const bool ackermann_ = scenario_.robot.kind == "ackermann";

  Terrain terrain_;
  ModelPtr model_;
  DataPtr data_;
  AckermannVehicle vehicle_;
  double rear_rolling_radius_m_ = 0.0;  // the rear tires' free-rolling travel per radian (sim/rolling_radius.h)
  WheeledRobot wheeled_;
  int odom_site_ = -1;
  frontend::ScanGeometry scan_geometry_;
  recording::Mounting laser_mounting_;
  std::optional<frontend::ScanMatchingStream> scan_matching_;
  std::unique_ptr<SimulatedCamera> camera_;
  recording::Mounting camera_mounting_;
  std::int64_t next_camera_frame_ = 0;
  std::vector<EncoderColumn> encoder_columns_;  // the wheel_encoders stream's columns
  std::vector<double> encoder_zero_rad_;        // per column
  std::optional<SpeedController> controller_;
  std::optional<GeographicLib::LocalCartesian> local_;
  ImuCalibration imu_;
  MagnetometerCalibration magnetometer_;
  double wheelbase_m_ = 0.0;
  double drive_torque_nm_ = 0.0;  // per rear wheel, applied over the current step
  // Effects (scenario.h); neutral values when absent.
  double steering_offset_rad_ = 0.0;
  Eigen::Vector3d gyro_scale_ = Eigen::Vector3d::Ones();
  Eigen::Vector3d gyro_bias_radps_ = Eigen::Vector3d::Zero();  // gyro_bias_drift: the bias at the next sample
  double gyro_bias_walk_ = 0.0;                                // [rad/s/sqrt(s)]
  Eigen::Vector3d mag_per_nm_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_scale_ = Eigen::Vector3d::Ones();
  double multipath_sigma_m_ = 0.0;  // gps_multipath: stationary std per axis
  double multipath_correlation_s_ = 5.0;
  Eigen::Vector3d multipath_m_ = Eigen::Vector3d::Zero();  // the error of the next fix, ENU [m]
  double tire_growth_per_mps2_ = 0.0;                      // tire_growth's c [s^2/m^2]
  double slip_per_mps2_ = 0.0;                             // longitudinal_slip's s_f [s^2/m]
  double slope_slip_per_mps2_ = 0.0;                       // slope_slip's s_p [s^2/m]
  double speed_reading_factor_ = 1.0;                      // the speed sensor's slip and growth at its last sample
  double odometry_scale_ = 1.0;                            // odometry_scale_error: the odometry reads this times true

  std::int64_t step_ns_ = 0;
  std::int64_t end_ns_ = 0;
  std::int64_t lead_in_ns_ = 0;
  std::int64_t loop_end_ns_ = 0;  // end_ns_, or later when a sample is taken after the recording's end
  std::int64_t t_ns_ = 0;         // the current time, for messages
  std::int64_t origin_ns_ = 0;    // the recording time of t = 0 (a replay's t0)
  std::int64_t drive_shift_ns_ = 0;  // drive_time_offset: a replay reads its drive inputs this much later
  double drive_drift_ = 0.0;         // drive_time_offset's drift_ppm * 1e-6: and later still by this times t
  Eigen::VectorXd replay_angles_at_start_, measured_angles_at_start_;  // a replay's wheel angles at t = 0
  double replay_travel_m_ = 0.0;                                       // a replay's Ackermann travel since t = 0
  Time origin() const { return Time::FromNanoseconds(origin_ns_); }
  Clock truth_clock_, imu_clock_, mag_clock_, gps_clock_, mocap_clock_, odometer_clock_, encoder_clock_, laser_clock_,
      odometry_clock_;
  Eigen::MatrixXd twist_from_rates_;  // a replay's wheel odometry: 3 x wheels, the least-squares inverse of J

  GaussMarkovNoise gyro_noise_{seed_, NoiseSource::kGyro, options_.noise};
  GaussMarkovNoise accel_noise_{seed_, NoiseSource::kAccel, options_.noise};
  GaussMarkovNoise mag_noise_{seed_, NoiseSource::kMagnetometer, options_.noise};
  GaussMarkovNoise gps_noise_{seed_, NoiseSource::kGps, options_.noise};
  GaussMarkovNoise speed_noise_{seed_, NoiseSource::kSpeed, options_.noise};
  GaussMarkovNoise steering_noise_{seed_, NoiseSource::kSteering, options_.noise};
  NoiseStream laser_noise_{seed_, NoiseSource::kLaserRange, options_.noise};
  GaussMarkovNoise mocap_position_noise_{seed_, NoiseSource::kMocapPosition, options_.noise};
  GaussMarkovNoise mocap_orientation_noise_{seed_, NoiseSource::kMocapOrientation, options_.noise};
  NoiseStream gyro_bias_noise_{seed_, NoiseSource::kGyroBiasWalk};  // an effect, not sensor noise: always on
  NoiseStream multipath_noise_{seed_, NoiseSource::kGpsMultipath};  // likewise

  recording::Stream imu_stream_, mag_stream_, gps_stream_, mocap_stream_, wheel_stream_, steering_stream_,
      encoder_stream_, laser_scan_stream_, odometry_stream_;
  Trajectory truth_;
  double min_height_ = 1e300;
  double max_height_ = -1e300;
  Simulation out_;
};

Simulator::Simulator(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Simulator::~Simulator() = default;

Result<std::unique_ptr<Simulator>> Simulator::Create(const Scenario& scenario, const SimulateOptions& options) {
  if (const auto problem = scenario.Validate()) {
    const std::string where = scenario.source_file.empty() ? std::string("scenario") : scenario.source_file;
    return Status::Error(where + ": " + problem->key + ": " + problem->message);
  }
  InstallMujocoHandlers();
  auto impl = std::make_unique<Impl>(scenario, options);
  try {
    if (Status s = impl->Setup(); !s.ok()) return s;
  } catch (const MujocoError& e) {
    return Status::Error((scenario.robot.model_xml.empty() ? scenario.robot.model_file : "robot.model_xml") +
                         ": MuJoCo error: " + OneLine(e.what()));
  }
  return std::unique_ptr<Simulator>(new Simulator(std::move(impl)));
}

std::map<std::string, double> Simulator::PlatformGeometry() const {
  ROAMLAB_CHECK(impl_ != nullptr, "Simulator::PlatformGeometry called after Run");
  return impl_->PlatformGeometry();
}

double Simulator::VehicleMassKg() const {
  ROAMLAB_CHECK(impl_ != nullptr, "Simulator::VehicleMassKg called after Run");
  return impl_->VehicleMassKg();
}

double Simulator::PhysicsStepS() const {
  ROAMLAB_CHECK(impl_ != nullptr, "Simulator::PhysicsStepS called after Run");
  return impl_->PhysicsStepS();
}

namespace {

// The scenario's robot bound without its effects and camera (no renderer needed to measure the robot).
Result<std::unique_ptr<Simulator>> NominalSimulator(const Scenario& scenario) {
  Scenario nominal = scenario;
  nominal.effects.clear();
  nominal.sensors.camera.reset();
  return Simulator::Create(nominal);
}

}  // namespace

Result<std::map<std::string, double>> NominalPlatformGeometry(const Scenario& scenario) {
  auto simulator = NominalSimulator(scenario);
  if (!simulator.ok()) return simulator.status();
  return simulator.value()->PlatformGeometry();
}

Result<double> NominalVehicleMassKg(const Scenario& scenario) {
  auto simulator = NominalSimulator(scenario);
  if (!simulator.ok()) return simulator.status();
  return simulator.value()->VehicleMassKg();
}

Result<Simulation> Simulator::Run() {
  ROAMLAB_CHECK(impl_ != nullptr, "Simulator::Run called twice");
  auto result = impl_->Run();
  impl_.reset();
  return result;
}

Result<Simulation> Simulate(const Scenario& scenario, const SimulateOptions& options) {
  auto simulator = Simulator::Create(scenario, options);
  if (!simulator.ok()) return simulator.status();
  return simulator.value()->Run();
}

}  // namespace roamlab::sim
