#include "estimator/model_registry.h"

#include <algorithm>
#include <limits>
#include <map>
#include <mutex>
#include <utility>

#include "estimator/models/non_holonomic.h"

namespace roamlab::estimator {
namespace {

Eigen::VectorXd Vec(std::initializer_list<double> v) {
  Eigen::VectorXd x(static_cast<int>(v.size()));
  int i = 0;
  for (double d : v) x[i++] = d;
  return x;
}

SlotSpec ScalarSlot(const std::string& name, double value) { return {name, Manifold::Euclidean(1), Vec({value})}; }
SlotSpec Vector3Slot(const std::string& name, double fill) {
  return {name, Manifold::Euclidean(3), Eigen::VectorXd::Constant(3, fill)};
}
SlotSpec RotationSlot(const std::string& name) { return {name, Manifold::UnitQuaternion(), Vec({1, 0, 0, 0})}; }
SlotSpec MatrixSlot(const std::string& name) {
  return {name, Manifold::Euclidean(9), Vec({1, 0, 0, 0, 1, 0, 0, 0, 1})};
}

// The built-in models' specs (config.h ModelSpec).
std::vector<ModelSpec> BuiltInSpecs() {
  // kv_over_L defaults to NaN: the builder replaces it with 1 / wheelbase (k_v = 1).
  return {
      // slip_per_mps2 and slope_slip_per_mps2: the driven tires' slip per m/s^2 of forward specific force (read from
      // inputs.specific_force, an imu or accelerometer stream, along options.forward_in_sensor) and of slope g
      // sin(pitch); disturbance: the speed, lateral and vertical rows' coloured disturbance [m/s], meant to be
      // time-varying; option front_slip_velocity 1: cornering_front is the front axle's side slip velocity per a_y
      // [s] instead of an angle (models/ackermann_velocity.h).
      {"ackermann",
       {"speed", "steering"},
       {"speed_mps", "steering_rad", "lateral_mps", "vertical_mps"},
       {ScalarSlot("kv_over_L", std::numeric_limits<double>::quiet_NaN()), ScalarSlot("k_theta", 1.0),
        ScalarSlot("k_gamma", 0.0), ScalarSlot("cornering_front", 0.0), ScalarSlot("cornering_rear", 0.0),
        ScalarSlot("thrust_angle", 0.0), ScalarSlot("slip_per_mps2", 0.0), ScalarSlot("slope_slip_per_mps2", 0.0),
        Vector3Slot("disturbance", 0.0)},
       {"wheelbase_m", "speed_column", "contact_height_m", "pitch_lever_m", "forward_in_sensor", "front_slip_velocity"},
       true,
       {"specific_force"}},
      {"ackermann_seed",
       {"speed", "steering"},
       {"speed_mps", "steering_rad", "lateral_mps", "vertical_mps", "roll_rate_radps", "pitch_rate_radps"},
       {ScalarSlot("kv_over_L", std::numeric_limits<double>::quiet_NaN()), ScalarSlot("k_theta", 1.0),
        ScalarSlot("k_gamma", 0.0)},
       {"wheelbase_m", "speed_column"},
       true,
       {}},
      // Wheel radii and baseline default to NaN: the builder takes them from the recording's platform geometry.
      // right_left_ratio multiplies radius_right; deformation_left/right are the tires' second harmonic (a, b) [m]
      // (models/differential_drive.h).
      {"differential_drive",
       {""},
       {"wheel_radps", "lateral_mps", "vertical_mps", "tilt_radps"},
       {ScalarSlot("radius_left", std::numeric_limits<double>::quiet_NaN()),
        ScalarSlot("radius_right", std::numeric_limits<double>::quiet_NaN()),
        ScalarSlot("baseline", std::numeric_limits<double>::quiet_NaN()),
        ScalarSlot("right_left_ratio", 1.0),
        {"deformation_left", Manifold::Euclidean(2), Vec({0.0, 0.0})},
        {"deformation_right", Manifold::Euclidean(2), Vec({0.0, 0.0})}},
       {},
       true,
       {}},
      // Omni and mecanum wheel radii and geometry: NaN too, taken from the platform geometry.
      {"omni3_drive",
       {""},
       {"wheel_radps", "vertical_mps", "tilt_radps"},
       {ScalarSlot("radius_0", std::numeric_limits<double>::quiet_NaN()),
        ScalarSlot("radius_1", std::numeric_limits<double>::quiet_NaN()),
        ScalarSlot("radius_2", std::numeric_limits<double>::quiet_NaN()),
        ScalarSlot("distance", std::numeric_limits<double>::quiet_NaN())},
       {},
       true,
       {}},
      {"mecanum_drive",
       {""},
       {"wheel_radps", "vertical_mps", "tilt_radps"},
       {ScalarSlot("radius_0", std::numeric_limits<double>::quiet_NaN()),
        ScalarSlot("radius_1", std::numeric_limits<double>::quiet_NaN()),
        ScalarSlot("radius_2", std::numeric_limits<double>::quiet_NaN()),
        ScalarSlot("radius_3", std::numeric_limits<double>::quiet_NaN()),
        ScalarSlot("lx_plus_ly", std::numeric_limits<double>::quiet_NaN())},
       {},
       true,
       {}},
      // Four-wheel omni (X layout): radii and the wheelbase + track sum, NaN: from the platform geometry
      // (models/omni4_drive.h).
      {"omni4_drive",
       {""},
       {"wheel_radps", "vertical_mps", "tilt_radps"},
       {ScalarSlot("radius_0", std::numeric_limits<double>::quiet_NaN()),
        ScalarSlot("radius_1", std::numeric_limits<double>::quiet_NaN()),
        ScalarSlot("radius_2", std::numeric_limits<double>::quiet_NaN()),
        ScalarSlot("radius_3", std::numeric_limits<double>::quiet_NaN()),
        ScalarSlot("wheelbase_plus_track", std::numeric_limits<double>::quiet_NaN())},
       {},
       true,
       {}},
      // Tricycle: the front wheel's encoder and its steering angle; radius and wheel_to_axle NaN (from the platform
      // geometry), steering_offset from geometry.steering_offset_rad when present, else 0 (models/tricycle_drive.h).
      {"tricycle_drive",
       {"wheel", "steering"},
       {"wheel_radps", "steering_rad", "lateral_mps", "vertical_mps", "tilt_radps"},
       {ScalarSlot("radius", std::numeric_limits<double>::quiet_NaN()),
        ScalarSlot("wheel_to_axle", std::numeric_limits<double>::quiet_NaN()), ScalarSlot("steering_offset", 0.0)},
       {},
       true,
       {}},
      {"odometer",
       {""},
       {"linear_mps", "angular_radps"},
       {Vector3Slot("lever_arm", 0.0), RotationSlot("misalignment")},
       {"row_covariance_scale"},
       true,
       {}},
      // The odometer's eqs. 5-8 over the sample's whole interval: see problem.h (relative motion).
      {"relative_motion",
       {""},
       {"linear_mps", "angular_radps"},
       {Vector3Slot("lever_arm", 0.0), RotationSlot("misalignment")},
       {"interval_s", "row_covariance_scale"},
       false,
       {}},
      // time_offset_s: the IMU clock's offset [s], the reading stamped t taken at t - time_offset_s
      // (models/imu_time_offset.h); share one parameter between the IMU's streams (e.g. imu.time_offset_s).
      {"gyroscope",
       {""},
       {"sigma_radps"},
       {RotationSlot("misalignment"), Vector3Slot("bias", 0.0), Vector3Slot("scale", 1.0),
        ScalarSlot("time_offset_s", 0.0)},
       {},
       false,
       {}},
      {"accelerometer",
       {""},
       {"sigma_mps2"},
       {RotationSlot("misalignment"), Vector3Slot("lever_arm", 0.0), Vector3Slot("bias", 0.0),
        Vector3Slot("scale", 1.0), ScalarSlot("time_offset_s", 0.0)},
       {},
       false,
       {}},
      // b_per_drive_nm: the motor interference per N m of drive torque, estimated from the forward specific force read
      // from inputs.specific_force (an imu or accelerometer stream) times options.drive_nm_per_mps2
      // (models/magnetometer.h).
      {"magnetometer",
       {""},
       {"sigma"},
       {RotationSlot("misalignment"), MatrixSlot("A"), Vector3Slot("b", 0.0), Vector3Slot("b_per_drive_nm", 0.0),
        ScalarSlot("time_offset_s", 0.0)},
       {"field_world", "drive_nm_per_mps2"},
       false,
       {"specific_force"}},
      // bias: the fixes' slow error in W [m], meant to be a Gauss-Markov process (models/gps.h).
      {"gps", {""}, {"sigma_m"}, {Vector3Slot("lever_arm", 0.0), Vector3Slot("bias", 0.0)}, {}, false, {}},
      {"absolute_pose",
       {""},
       {"position_m", "orientation_rad"},
       {Vector3Slot("lever_arm", 0.0), RotationSlot("misalignment")},
       {},
       false,
       {}},
      {"linear_velocity",
       {""},
       {"sigma_mps"},
       {Vector3Slot("lever_arm", 0.0), RotationSlot("misalignment")},
       {},
       false,
       {}},
  };
}

// A diagonal noise covariance: each noise key's sigma squared, repeated as often as given.
std::function<Eigen::MatrixXd(const StreamConfig&)> RepeatedNoise(std::vector<std::pair<std::string, int>> keys) {
  return [keys = std::move(keys)](const StreamConfig& config) {
    int n = 0;
    for (const auto& [key, count] : keys) n += count;
    Eigen::VectorXd sigma(n);
    int i = 0;
    for (const auto& [key, count] : keys) {
      sigma.segment(i, count).setConstant(config.noise.at(key));
      i += count;
    }
    return Eigen::MatrixXd(sigma.cwiseAbs2().asDiagonal());
  };
}

// The default noise covariance: the noise keys' sigmas squared, in the spec's order.
Eigen::MatrixXd DiagonalNoise(const ModelSpec& spec, const StreamConfig& config) {
  Eigen::VectorXd sigma(static_cast<int>(spec.noise_keys.size()));
  for (std::size_t i = 0; i < spec.noise_keys.size(); ++i)
    sigma[static_cast<int>(i)] = config.noise.at(spec.noise_keys[i]);
  return sigma.cwiseAbs2().asDiagonal();
}

// The built-in models: their specs with how their samples attach, their error's dimension, whether they are absolute
// and their noise covariance (by the noise input's components).
std::vector<ErrorModelDefinition> BuiltInModels() {
  using A = ModelAttachment;
  struct Traits {
    A attachment;
    int residual_dim;
    bool absolute;
    std::vector<std::pair<std::string, int>> noise;  // empty: DiagonalNoise
  };
  const std::map<std::string, Traits> traits = {
      {"ackermann", {A::kPair, 4, false, {}}},
      {"ackermann_seed", {A::kPair, 6, false, {}}},
      {"differential_drive",
       {A::kPair, 6, false, {{"wheel_radps", 2}, {"lateral_mps", 1}, {"vertical_mps", 1}, {"tilt_radps", 2}}}},
      {"omni3_drive", {A::kPair, 6, false, {{"wheel_radps", 3}, {"vertical_mps", 1}, {"tilt_radps", 2}}}},
      {"mecanum_drive", {A::kPair, 7, false, {{"wheel_radps", 4}, {"vertical_mps", 1}, {"tilt_radps", 2}}}},
      {"omni4_drive", {A::kPair, 7, false, {{"wheel_radps", 4}, {"vertical_mps", 1}, {"tilt_radps", 2}}}},
      {"tricycle_drive",
       {A::kPair,
        6,
        false,
        {{"wheel_radps", 1}, {"steering_rad", 1}, {"lateral_mps", 1}, {"vertical_mps", 1}, {"tilt_radps", 2}}}},
      {"odometer", {A::kPair, 6, false, {{"linear_mps", 3}, {"angular_radps", 3}}}},
      {"relative_motion", {A::kInterval, 6, false, {{"linear_mps", 3}, {"angular_radps", 3}}}},
      {"gyroscope", {A::kPair, 3, false, {{"sigma_radps", 3}}}},
      {"accelerometer", {A::kTriple, 3, false, {{"sigma_mps2", 3}}}},
      {"magnetometer", {A::kOnePose, 3, false, {{"sigma", 3}}}},
      {"gps", {A::kOnePose, 3, true, {{"sigma_m", 3}}}},
      {"absolute_pose", {A::kOnePose, 6, true, {{"position_m", 3}, {"orientation_rad", 3}}}},
      {"linear_velocity", {A::kPair, 3, false, {{"sigma_mps", 3}}}},
  };
  std::vector<ErrorModelDefinition> models;
  for (ModelSpec& spec : BuiltInSpecs()) {
    const Traits& t = traits.at(spec.name);
    ErrorModelDefinition d;
    d.spec = std::move(spec);
    d.attachment = t.attachment;
    d.residual_dim = t.residual_dim;
    d.absolute = t.absolute;
    if (!t.noise.empty()) d.noise_covariance = RepeatedNoise(t.noise);
    models.push_back(std::move(d));
  }
  // Built from its own definition (models/non_holonomic.h): it reads no values, so it binds like a user model.
  models.push_back(NonHolonomicModel());
  return models;
}

// The registry: the built-in models, then the user's. Definitions are never removed, so pointers to them stay valid.
class Registry {
 public:
  static Registry& Get() {
    static Registry registry;
    return registry;
  }
  Status Add(ErrorModelDefinition definition) {
    const std::lock_guard<std::mutex> lock(mutex_);
    const std::string name = definition.spec.name;
    if (models_.count(name)) return Status::Error("error model '" + name + "' is already registered");
    Insert(std::move(definition));
    return Status::Ok();
  }
  const ErrorModelDefinition* Find(const std::string& name) const {
    const std::lock_guard<std::mutex> lock(mutex_);
    const auto it = models_.find(name);
    return it == models_.end() ? nullptr : it->second.get();
  }
  std::vector<std::string> Names() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    std::vector<std::string> names;
    for (const auto& [name, definition] : models_) names.push_back(name);
    return names;
  }

 private:
  Registry() {
    for (ErrorModelDefinition& d : BuiltInModels()) Insert(std::move(d));
  }
  void Insert(ErrorModelDefinition definition) {
    if (!definition.noise_covariance) {
      definition.noise_covariance = [spec = definition.spec](const StreamConfig& config) {
        return DiagonalNoise(spec, config);
      };
    }
    const std::string name = definition.spec.name;
    models_.emplace(name, std::make_unique<ErrorModelDefinition>(std::move(definition)));
  }
  mutable std::mutex mutex_;
  std::map<std::string, std::unique_ptr<ErrorModelDefinition>> models_;
};

}  // namespace

Status RegisterErrorModel(ErrorModelDefinition definition) {
  const ModelSpec& spec = definition.spec;
  const std::string what = "error model '" + spec.name + "'";
  if (spec.name.empty()) return Status::Error("an error model needs a name");
  if (!definition.bind) return Status::Error(what + ": no bind function");
  if (spec.noise_keys.empty()) return Status::Error(what + ": no noise key");
  if (spec.source_roles.empty()) return Status::Error(what + ": no source role");
  if (definition.residual_dim < 1) return Status::Error(what + ": residual_dim must be at least 1");
  if (spec.odometric) return Status::Error(what + ": a user model cannot be odometric (a master stream)");
  if (definition.attachment == ModelAttachment::kInterval)
    return Status::Error(what + ": the interval attachment is relative_motion's only");
  return Registry::Get().Add(std::move(definition));
}

const ErrorModelDefinition* FindErrorModel(const std::string& name) { return Registry::Get().Find(name); }

std::vector<std::string> ErrorModelNames() { return Registry::Get().Names(); }

const ModelSpec* FindModelSpec(const std::string& model) {
  const ErrorModelDefinition* definition = FindErrorModel(model);
  return definition == nullptr ? nullptr : &definition->spec;
}

}  // namespace roamlab::estimator
