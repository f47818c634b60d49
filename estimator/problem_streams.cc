// ProblemBuilder::Create (problem.h): binds each configured stream to its recording stream(s), checks their types and
// options, and sets up the parameters (their manifolds, initial values, flags and variables).
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "estimator/internal/problem_impl.h"
#include "estimator/marginalization.h"
#include "recording/stream_health.h"

namespace roamlab::estimator {

using internal::Attachment;
using recording::StreamType;

namespace {

// Per row of `stream`: whether it repeats the first row of one of `health`'s frozen runs.
std::vector<bool> FrozenRows(const recording::Stream& stream, const recording::StreamHealth& health) {
  std::vector<bool> frozen(stream.t.size(), false);
  for (const recording::FrozenRun& run : health.frozen) {
    const auto first = std::lower_bound(stream.t.begin(), stream.t.end(), run.first) - stream.t.begin();
    for (auto row = first + 1; row < first + run.rows; ++row) frozen[static_cast<std::size_t>(row)] = true;
  }
  return frozen;
}

Attachment AttachmentOf(const ErrorModelDefinition& model, bool master) {
  if (master) return Attachment::kMaster;
  switch (model.attachment) {
    case ModelAttachment::kOnePose:
      return Attachment::kOnePose;
    case ModelAttachment::kPair:
      return Attachment::kPair;
    case ModelAttachment::kTriple:
      return Attachment::kTriple;
    case ModelAttachment::kInterval:
      return Attachment::kInterval;
  }
  return Attachment::kOnePose;
}

Status Error(const EstimatorConfig& c, const std::string& message) {
  return Status::Error(c.source_file + ": " + message);
}

bool TypeIn(StreamType t, std::initializer_list<StreamType> allowed) {
  return std::find(allowed.begin(), allowed.end(), t) != allowed.end();
}

// Binds the stream's inputs.specific_force (an imu or accelerometer stream), when configured; false when it is not.
Result<bool> BindSpecificForce(const EstimatorConfig& config, const recording::Recording& rec, StreamBinding* b) {
  const auto it = b->config.inputs.find("specific_force");
  if (it == b->config.inputs.end()) return false;
  b->specific_force = rec.Find(it->second);
  if (b->specific_force == nullptr ||
      !TypeIn(b->specific_force->info.type, {StreamType::kImu, StreamType::kAccelerometer}))
    return Error(config, "stream '" + b->name + "': inputs.specific_force '" + it->second +
                             "' is missing or not an imu or accelerometer stream");
  if (b->specific_force->t.empty())
    return Error(config, "stream '" + b->name + "': inputs.specific_force '" + it->second + "' is empty");
  b->specific_force_column = b->specific_force->info.type == StreamType::kImu ? 3 : 0;
  return true;
}

// The speed and steering sources of an Ackermann stream, its wheelbase and the options of models/ackermann_velocity.h.
Status BindAckermann(const EstimatorConfig& config, const recording::Recording& rec, const std::string& bad_type,
                     StreamBinding* b) {
  const std::string& name = b->name;
  const StreamConfig& sc = b->config;
  const std::string& source = sc.sources.at("speed");
  const StreamType type = b->primary->info.type;
  if (type != StreamType::kWheelEncoders) return Error(config, bad_type);
  if (b->primary->info.units != "m/s")
    return Error(config, "stream '" + name + "': ackermann speed source '" + source + "' must be in m/s");
  b->steering = rec.Find(sc.sources.at("steering"));
  if (b->steering == nullptr || b->steering->info.type != StreamType::kSteering)
    return Error(config, "stream '" + name + "': steering source '" + sc.sources.at("steering") +
                             "' is missing or not a steering stream");
  if (sc.options.count("speed_column")) b->column = static_cast<int>(sc.options.at("speed_column").at(0));
  if (b->column < 0 || b->column >= b->primary->values.cols())
    return Error(config, "stream '" + name + "': speed_column out of range");
  if (sc.options.count("wheelbase_m")) {
    b->wheelbase_m = sc.options.at("wheelbase_m").at(0);
  } else if (rec.platform.geometry.count("wheelbase_m")) {
    b->wheelbase_m = rec.platform.geometry.at("wheelbase_m");
  } else {
    return Error(config, "stream '" + name + "': no wheelbase_m in options or in the recording's platform");
  }
  if (!(b->wheelbase_m > 0.0)) return Error(config, "stream '" + name + "': wheelbase_m must be positive");
  if (sc.options.count("contact_height_m")) b->ackermann.contact_height_m = sc.options.at("contact_height_m").at(0);
  if (sc.options.count("pitch_lever_m")) b->ackermann.pitch_lever_m = sc.options.at("pitch_lever_m").at(0);
  if (!(std::abs(b->ackermann.contact_height_m) <= 10.0 && std::abs(b->ackermann.pitch_lever_m) <= 10.0))
    return Error(config, "stream '" + name + "': contact_height_m and pitch_lever_m must be within +-10 m");
  if (const auto f = sc.options.find("front_slip_velocity"); f != sc.options.end()) {
    if (f->second.size() != 1 || !(f->second[0] == 0.0 || f->second[0] == 1.0))
      return Error(config, "stream '" + name + "': front_slip_velocity must be 0 or 1");
    b->ackermann.front_slip_velocity = f->second[0] == 1.0;
  }
  // The longitudinal slip's input (models/ackermann_velocity.h): the specific force along O's x, which is
  // options.forward_in_sensor in the accelerometer's frame.
  const Result<bool> input = BindSpecificForce(config, rec, b);
  if (!input.ok()) return input.status();
  if (input.value()) {
    const auto f = sc.options.find("forward_in_sensor");
    if (f == sc.options.end() || f->second.size() != 3 ||
        !(Eigen::Vector3d(f->second[0], f->second[1], f->second[2]).norm() > 0.5))
      return Error(config, "stream '" + name +
                               "': inputs.specific_force needs options.forward_in_sensor: "
                               "[x, y, z], O's forward axis in the accelerometer's frame (a unit vector)");
    b->forward_in_sensor = Eigen::Vector3d(f->second[0], f->second[1], f->second[2]).normalized();
  } else if (sc.options.count("forward_in_sensor")) {
    return Error(config, "stream '" + name + "': options.forward_in_sensor without inputs.specific_force");
  }
  return Status::Ok();
}

// The source types and options of the other models.
Status BindOtherModel(const EstimatorConfig& config, const recording::Recording& rec, const std::string& bad_type,
                      bool has_enu, StreamBinding* b) {
  const std::string& name = b->name;
  const StreamConfig& sc = b->config;
  const std::string& m = sc.model;
  const std::string& source = b->primary->info.name;
  const StreamType type = b->primary->info.type;
  if (m == "gyroscope") {
    if (!TypeIn(type, {StreamType::kImu, StreamType::kGyroscope})) return Error(config, bad_type);
  } else if (m == "accelerometer") {
    if (!TypeIn(type, {StreamType::kImu, StreamType::kAccelerometer})) return Error(config, bad_type);
    if (type == StreamType::kImu) b->column = 3;
  } else if (m == "magnetometer") {
    if (type != StreamType::kMagnetometer) return Error(config, bad_type);
    if (!sc.options.count("field_world") || sc.options.at("field_world").size() != 3)
      return Error(config, "stream '" + name + "': magnetometer needs options.field_world: [east, north, up]");
    const auto& f = sc.options.at("field_world");
    b->field_world = Eigen::Vector3d(f[0], f[1], f[2]);
    // The motor interference's proxy (models/magnetometer.h): the accelerometer's specific force, with c.
    const Result<bool> input = BindSpecificForce(config, rec, b);
    if (!input.ok()) return input.status();
    if (input.value()) {
      if (!sc.options.count("drive_nm_per_mps2") || sc.options.at("drive_nm_per_mps2").size() != 1 ||
          !std::isfinite(sc.options.at("drive_nm_per_mps2")[0]))
        return Error(config, "stream '" + name +
                                 "': inputs.specific_force needs options.drive_nm_per_mps2: [c], "
                                 "the drive torque per wheel per m/s^2 of forward specific force");
      b->drive_nm_per_mps2 = sc.options.at("drive_nm_per_mps2")[0];
    } else if (sc.options.count("drive_nm_per_mps2")) {
      return Error(config, "stream '" + name + "': options.drive_nm_per_mps2 without inputs.specific_force");
    }
  } else if (m == "gps") {
    if (!TypeIn(type, {StreamType::kGps, StreamType::kPosition})) return Error(config, bad_type);
    if (type == StreamType::kGps && !has_enu) return Error(config, "stream '" + name + "': gps without origin");
  } else if (m == "absolute_pose") {
    if (type != StreamType::kPose) return Error(config, bad_type);
  } else if (m == "differential_drive") {
    if (type != StreamType::kWheelEncoders) return Error(config, bad_type);
    if (b->primary->info.units != "rad" || b->primary->values.cols() != 2)
      return Error(config, "stream '" + name + "': differential_drive source '" + source +
                               "' must hold two cumulative wheel angles (left, right) in rad or ticks");
    b->right_then_left = b->primary->info.columns == std::vector<std::string>{"right", "left"};
  } else if (m == "tricycle_drive") {
    if (type != StreamType::kWheelEncoders) return Error(config, bad_type);
    if (b->primary->info.units != "rad" || b->primary->values.cols() != 1)
      return Error(config, "stream '" + name + "': tricycle_drive wheel source '" + source +
                               "' must hold one cumulative wheel angle in rad");
    const std::string& steering = sc.sources.at("steering");
    b->steering = rec.Find(steering);
    if (b->steering == nullptr || b->steering->info.type != StreamType::kSteering || b->steering->t.empty())
      return Error(config, "stream '" + name + "': steering source '" + steering +
                               "' is missing, empty or not a steering stream");
  } else if (m == "omni3_drive" || m == "mecanum_drive" || m == "omni4_drive") {
    const int wheels = m == "omni3_drive" ? 3 : 4;
    if (type != StreamType::kWheelEncoders) return Error(config, bad_type);
    if (b->primary->info.units != "rad" || b->primary->values.cols() != wheels)
      return Error(config, "stream '" + name + "': " + m + " source '" + source + "' must hold " +
                               std::to_string(wheels) + " cumulative wheel angles in rad");
  } else if (m == "odometer" || m == "linear_velocity" || m == "relative_motion") {
    if (!TypeIn(type, {StreamType::kOdometry, StreamType::kVisualOdometry, StreamType::kScanMatching}))
      return Error(config, bad_type);
  }
  return Status::Ok();
}

// Options that read the rows' own covariance (odometer, relative_motion) and relative_motion's interval.
Status BindRowOptions(const EstimatorConfig& config, const std::string& source, StreamBinding* b) {
  const std::string& name = b->name;
  const StreamConfig& sc = b->config;
  const std::string& m = sc.model;
  if (sc.options.count("row_covariance_scale")) {
    const std::vector<double>& k = sc.options.at("row_covariance_scale");
    if (k.size() != 1 || !(k[0] > 0.0))
      return Error(config, "stream '" + name + "': options.row_covariance_scale must be one positive number");
    if (b->primary->values.cols() != 27)
      return Error(config, "stream '" + name +
                               "': options.row_covariance_scale needs the 21 covariance columns, "
                               "which recording stream '" +
                               source + "' lacks");
    b->row_covariance_scale = k[0];
  }
  if (m == "relative_motion") {
    if (sc.options.count("interval_s")) {
      const std::vector<double>& T = sc.options.at("interval_s");
      if (T.size() != 1 || !(T[0] > 0.0))
        return Error(config, "stream '" + name + "': options.interval_s must be one positive number [s]");
      b->interval_s = T[0];
    } else if (b->primary->info.rate_hz > 0.0) {
      b->interval_s = 1.0 / b->primary->info.rate_hz;
    } else {
      return Error(config,
                   "stream '" + name + "': recording stream '" + source + "' has no rate_hz; give options.interval_s");
    }
  }
  return Status::Ok();
}

// A configured stream bound to its recording stream(s), its types and options checked.
Result<StreamBinding> BindStream(const EstimatorConfig& config, const recording::Recording& rec,
                                 const std::string& name, const StreamConfig& sc, bool has_enu) {
  StreamBinding b;
  b.name = name;
  b.config = sc;
  b.definition = FindErrorModel(sc.model);
  if (b.definition == nullptr) return Error(config, "stream '" + name + "': unknown model '" + sc.model + "'");
  b.spec = &b.definition->spec;
  b.attachment = AttachmentOf(*b.definition, name == config.master);
  // The primary source: the first source role (ackermann's speed, tricycle_drive's wheel, "" for one source).
  const std::string& source = sc.sources.at(b.spec->source_roles.front());
  b.primary = rec.Find(source);
  if (b.primary == nullptr)
    return Error(config, "stream '" + name + "' reads recording stream '" + source + "', which the recording lacks");
  b.noise_covariance = b.definition->noise_covariance(sc);
  if (b.definition->bind) {
    Result<std::unique_ptr<BoundErrorModel>> bound = b.definition->bind({name, sc, rec, *b.primary});
    if (!bound.ok()) return Error(config, "stream '" + name + "': " + bound.status().message());
    if (bound.value() == nullptr) return Error(config, "stream '" + name + "': model " + sc.model + " bound nothing");
    b.user_model = std::move(bound).value();
    return b;
  }
  const bool ackermann = sc.model == "ackermann" || sc.model == "ackermann_seed";
  const StreamType type = b.primary->info.type;
  const std::string bad_type = "stream '" + name + "': recording stream '" + source + "' has type " +
                               recording::StreamTypeName(type) + ", which model " + sc.model + " cannot read";
  const Status bound =
      ackermann ? BindAckermann(config, rec, bad_type, &b) : BindOtherModel(config, rec, bad_type, has_enu, &b);
  if (!bound.ok()) return bound;
  const Status options = BindRowOptions(config, source, &b);
  if (!options.ok()) return options;
  return b;
}

// The parameter names of a stream's model slots, with consistent manifolds across streams, and their default initial
// values (the first stream that uses a parameter sets it).
Status AddSlotParameters(const EstimatorConfig& config, const recording::Recording& rec, StreamBinding* b,
                         std::map<std::string, Manifold>* parameter_manifold,
                         std::map<std::string, Eigen::VectorXd>* parameter_initial) {
  const std::string& name = b->name;
  const StreamConfig& sc = b->config;
  const std::string& m = sc.model;
  const bool ackermann = m == "ackermann" || m == "ackermann_seed";
  for (const SlotSpec& slot : b->spec->slots) {
    const auto it = sc.parameters.find(slot.name);
    const std::string pname = it != sc.parameters.end() ? it->second : name + "." + slot.name;
    b->slot_parameters.push_back(pname);
    const auto known = parameter_manifold->find(pname);
    if (known != parameter_manifold->end() && !(known->second == slot.manifold))
      return Error(config,
                   "parameter '" + pname + "' is used as " + known->second.Name() + " and as " + slot.manifold.Name());
    parameter_manifold->emplace(pname, slot.manifold);
    Eigen::VectorXd init = slot.default_value;
    if (ackermann && slot.name == "kv_over_L") init[0] = 1.0 / b->wheelbase_m;
    if (m == "tricycle_drive" && slot.name == "steering_offset") {
      const auto g = rec.platform.geometry.find("steering_offset_rad");
      if (g != rec.platform.geometry.end()) init[0] = g->second;
    }
    if ((m == "differential_drive" || m == "omni3_drive" || m == "mecanum_drive" || m == "omni4_drive" ||
         m == "tricycle_drive") &&
        std::isnan(init[0])) {
      // The geometry slots (default NaN): radii from wheel_radius_m; the other slot from its geometry key
      // (lx_plus_ly, wheelbase_plus_track: the sum of two keys).
      std::string key = "wheel_radius_m";
      if (slot.name == "baseline") key = "baseline_m";
      if (slot.name == "distance") key = "wheel_distance_m";
      if (slot.name == "lx_plus_ly") key = "half_length_m";
      if (slot.name == "wheelbase_plus_track") key = "wheelbase_m";
      if (slot.name == "wheel_to_axle") key = "wheel_to_axle_m";
      const auto g = rec.platform.geometry.find(key);
      if (g == rec.platform.geometry.end() && !(config.parameters.count(pname) && config.parameters.at(pname).value))
        return Error(config, "stream '" + name + "': no parameters." + pname + ".value and no " + key +
                                 " in the recording's platform");
      if (g != rec.platform.geometry.end()) init[0] = g->second;
      if ((slot.name == "lx_plus_ly" || slot.name == "wheelbase_plus_track") && g != rec.platform.geometry.end()) {
        const std::string second = slot.name == "lx_plus_ly" ? "half_width_m" : "track_m";
        const auto width = rec.platform.geometry.find(second);
        if (width == rec.platform.geometry.end())
          return Error(config, "stream '" + name + "': no " + second + " in the recording's platform");
        init[0] += width->second;
      }
    }
    parameter_initial->emplace(pname, init);
  }
  return Status::Ok();
}

// Parameter values and flags from the configuration.
Status ApplyParameterConfig(const EstimatorConfig& config, const std::map<std::string, Manifold>& parameter_manifold,
                            std::map<std::string, Eigen::VectorXd>* parameter_initial,
                            std::map<std::string, ParameterConfig>* parameter_config) {
  for (const auto& [pname, pc] : config.parameters) {
    const auto it = parameter_manifold.find(pname);
    if (it == parameter_manifold.end()) return Error(config, "parameter '" + pname + "' is not used by any stream");
    if (pc.value) {
      if (pc.value->size() != it->second.ambient_dim())
        return Error(config, "parameter '" + pname + "' needs " + std::to_string(it->second.ambient_dim()) +
                                 " values, got " + std::to_string(pc.value->size()));
      Eigen::VectorXd v = *pc.value;
      if (it->second.kind() == ManifoldKind::kQuaternion) {
        if (std::abs(v.norm() - 1.0) > 1e-3)
          return Error(config, "parameter '" + pname + "' is a quaternion [w, x, y, z] and must have unit norm");
        v.normalize();
      }
      (*parameter_initial)[pname] = v;
    }
    if (pc.prior_sigma &&
        (pc.process.type != ProcessConfig::Type::kConstant || pc.prior_sigma->size() != it->second.tangent_dim()))
      return Error(config, "parameter '" + pname + "': prior_sigma needs a constant parameter and " +
                               std::to_string(it->second.tangent_dim()) + " values (one per tangent component)");
    if (pc.process.type != ProcessConfig::Type::kConstant && it->second.kind() != ManifoldKind::kEuclidean)
      return Error(config, "parameter '" + pname + "': only vector parameters can be time-varying");
    if (pc.process.type != ProcessConfig::Type::kConstant && it->second.ambient_dim() != 3)
      return Error(config, "parameter '" + pname + "': time-varying parameters must be 3-vectors");
    (*parameter_config)[pname] = pc;
  }
  return Status::Ok();
}

// The IMU's time offset: the time-offset models only where it can matter (the parameter is free or not zero).
void BindTimeOffsets(const std::map<std::string, ParameterConfig>& parameter_config,
                     const std::map<std::string, Eigen::VectorXd>& parameter_initial,
                     std::vector<StreamBinding>* streams) {
  for (StreamBinding& b : *streams) {
    if (b.user_model) continue;  // a user model's factor takes every slot itself
    for (std::size_t i = 0; i < b.spec->slots.size(); ++i)
      if (b.spec->slots[i].name == "time_offset_s") b.time_offset_slot = static_cast<int>(i);
    if (b.time_offset_slot < 0) continue;
    const std::string& pname = b.slot_parameters[static_cast<std::size_t>(b.time_offset_slot)];
    const auto pc = parameter_config.find(pname);
    b.time_offset = (pc != parameter_config.end() && pc->second.free) || parameter_initial.at(pname)[0] != 0.0;
  }
}

// Every stage entry names a free parameter.
Status CheckStages(const EstimatorConfig& config, const std::map<std::string, ParameterConfig>& parameter_config) {
  for (const auto& stage : config.stages)
    for (const std::string& pname : stage) {
      const auto it = parameter_config.find(pname);
      if (it == parameter_config.end() || !it->second.free)
        return Error(config, "stage entry '" + pname + "' is not a free parameter");
    }
  return Status::Ok();
}

}  // namespace

Result<std::unique_ptr<ProblemBuilder>> ProblemBuilder::Create(const EstimatorConfig& config,
                                                               const recording::Recording& rec) {
  auto impl = std::make_unique<Impl>();
  impl->config = config;
  if (rec.origin) impl->enu.emplace(*rec.origin);

  // Bind every configured stream to its recording stream(s) and check the types; name its parameters.
  for (const auto& [name, sc] : config.streams) {
    Result<StreamBinding> b = BindStream(config, rec, name, sc, impl->enu.has_value());
    if (!b.ok()) return b.status();
    const Status slots =
        AddSlotParameters(config, rec, &b.value(), &impl->parameter_manifold, &impl->parameter_initial);
    if (!slots.ok()) return slots;
    impl->streams.push_back(std::move(b).value());
  }
  const Status parameters =
      ApplyParameterConfig(config, impl->parameter_manifold, &impl->parameter_initial, &impl->parameter_config);
  if (!parameters.ok()) return parameters;
  BindTimeOffsets(impl->parameter_config, impl->parameter_initial, &impl->streams);
  const Status stages = CheckStages(config, impl->parameter_config);
  if (!stages.ok()) return stages;

  auto builder = std::unique_ptr<ProblemBuilder>(new ProblemBuilder(std::move(impl)));
  Impl& im = *builder->impl_;
  for (std::size_t i = 0; i < im.streams.size(); ++i) {
    builder->stream_names_.push_back(im.streams[i].name);
    StreamCounts& counts = builder->counts_[im.streams[i].name];
    const recording::Stream& primary = *im.streams[i].primary;
    const recording::StreamHealth health = recording::CheckStreamHealth(primary);
    counts.duplicates = static_cast<int>(primary.duplicate_rows_dropped);
    counts.gaps = static_cast<int>(health.gaps.size());
    counts.frozen = health.FrozenRepeats();
    im.streams[i].frozen = FrozenRows(primary, health);
    if (im.streams[i].name == config.master) im.master = static_cast<int>(i);
    if (im.streams[i].definition->absolute) builder->has_absolute_sensor_ = true;
  }
  if (im.master >= 0 && im.streams[static_cast<std::size_t>(im.master)].config.model == "gyroscope") {
    im.imu.emplace();
    for (std::size_t i = 0; i < im.streams.size(); ++i) {
      const std::string& model = im.streams[i].config.model;
      if (model == "accelerometer" && im.imu->accelerometer < 0) im.imu->accelerometer = static_cast<int>(i);
      if (model == "magnetometer" && im.imu->magnetometer < 0) im.imu->magnetometer = static_cast<int>(i);
    }
    if (im.imu->accelerometer < 0)
      return Error(config, "master stream '" + config.master + "' is a gyroscope, which needs an accelerometer stream");
  }

  // Constant parameter variables (time-varying ones get instances per pose).
  for (const auto& [pname, manifold] : im.parameter_manifold) {
    if (builder->IsTimeVarying(pname)) continue;
    const auto pc = im.parameter_config.find(pname);
    const bool free = pc != im.parameter_config.end() && pc->second.free;
    const VariableId id =
        builder->graph_.AddVariable({pname, manifold, im.parameter_initial.at(pname), !free, std::nullopt});
    builder->parameters_[pname] = id;
    if (pc != im.parameter_config.end() && pc->second.prior_sigma) {
      // e = diag(1 / sigma) (x [-] x0), the components with an infinite sigma left out.
      const Eigen::VectorXd& sigma = *pc->second.prior_sigma;
      std::vector<int> rows;
      for (int i = 0; i < sigma.size(); ++i)
        if (std::isfinite(sigma[i])) rows.push_back(i);
      Eigen::MatrixXd J = Eigen::MatrixXd::Zero(static_cast<int>(rows.size()), sigma.size());
      for (std::size_t r = 0; r < rows.size(); ++r) J(static_cast<int>(r), rows[r]) = 1.0 / sigma[rows[r]];
      const int n = static_cast<int>(rows.size());
      if (n == 0) continue;
      builder->graph_.AddFactor(
          std::make_unique<LinearPriorFactor>(std::vector<Manifold>{manifold},
                                              std::vector<Eigen::VectorXd>{im.parameter_initial.at(pname)}, J,
                                              Eigen::VectorXd::Zero(n)),
          {id}, Eigen::MatrixXd::Identity(n, n), Loss::Trivial(), "prior", Time());
    }
  }
  return builder;
}

}  // namespace roamlab::estimator
