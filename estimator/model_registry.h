// The error-model registry: every `model:` of an estimator configuration (config.h) names a model registered here.
// The built-in models (gps, odometer, ackermann, ...) are registered before the first lookup; a program adds its own
// with RegisterErrorModel, before it parses a configuration that names them, and EST.yaml uses them by name like
// any built-in model. docs/library.md walks through one (a range to a beacon, examples/consumer/).
//
// A definition gives
//   - spec: what the configuration parser reads for a stream of the model (config.h ModelSpec): its source roles,
//     noise keys, parameter slots with their manifolds and default values, option keys and input roles. The parser
//     refuses any other key and reads every option as a list of numbers (StreamConfig::options);
//   - attachment: which poses a sample's factor joins (the pose nearest its stamp, the two around it, or three);
//   - residual_dim: the dimension of the factor's error (the chi-square gate's degrees of freedom);
//   - absolute: whether the model places the poses in the world frame (then the first pose gets no gauge prior);
//   - noise_covariance: the covariance of the factor's noise input from the configured noise (default: diagonal,
//     the squares of the noise keys in the spec's order, one per noise component);
//   - bind (user models): called once per configured stream when the estimator builds its problem, with the
//     recording stream of the stream's first source role; it checks the stream (type, columns) and reads the options,
//     and returns the bound model that makes the factor of each sample, or an error message (the builder prefixes
//     the configuration file and stream name). The built-in models have no bind: the builder (problem.cc) makes their
//     factors, with what they need beyond a sample (steering, specific force, wheel geometry, time offsets); except
//     non_holonomic (models/non_holonomic.h), which needs nothing beyond its poses and binds as a user model does.
//
// A bound model's factor joins the sample's poses (oldest first) and then the model's slots in the spec's order, and
// its error has residual_dim entries and its noise as many components as the noise covariance's size; the graph
// checks both (graph.h). Error models are functors wrapped by MakeFactor (factor.h). A user model cannot be a master
// stream (spec.odometric must be false) and cannot use the relative_motion interval attachment.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "common/time.h"
#include "estimator/config.h"
#include "estimator/factor.h"
#include "recording/recording.h"

namespace roamlab::estimator {

// Which poses a sample's factor joins: the pose nearest its stamp, the two poses whose interval holds it, the three
// centred on the nearest, or (relative_motion only) the poses nearest the ends of its interval (problem.h).
enum class ModelAttachment { kOnePose, kPair, kTriple, kInterval };

// One sample of a stream with a user model.
struct ModelSample {
  Time t;
  Eigen::RowVectorXd values;     // its row of the primary recording stream
  std::vector<Time> pose_times;  // the poses the factor joins, oldest first (1, 2 or 3 by attachment)
};

// A user model bound to one configured stream: the factor of each of its samples.
class BoundErrorModel {
 public:
  virtual ~BoundErrorModel() = default;
  // The factor of one sample (the header comment); nullptr: the sample gives none and is counted as outside.
  virtual std::unique_ptr<Factor> MakeFactor(const ModelSample& sample) const = 0;
};

// What bind sees of a configured stream.
struct ModelBindContext {
  const std::string& stream;              // the configured stream's name
  const StreamConfig& config;             // its sources, noise and options, checked against the spec's keys
  const recording::Recording& recording;  // the whole recording (other sources, platform geometry)
  const recording::Stream& primary;       // the recording stream of the first source role
};

struct ErrorModelDefinition {
  ModelSpec spec;
  ModelAttachment attachment = ModelAttachment::kOnePose;
  int residual_dim = 0;
  bool absolute = false;
  std::function<Eigen::MatrixXd(const StreamConfig&)> noise_covariance;                   // optional
  std::function<Result<std::unique_ptr<BoundErrorModel>>(const ModelBindContext&)> bind;  // null for built-ins
};

// Registers a user model under definition.spec.name. Errors: the name is empty or taken (built-in models included),
// no bind, no noise key, residual_dim < 1, an odometric spec or the interval attachment. Thread-safe.
Status RegisterErrorModel(ErrorModelDefinition definition);

// The definition registered under `name`; nullptr when none. The pointer stays valid for the program's life.
const ErrorModelDefinition* FindErrorModel(const std::string& name);

// Every registered model's name, sorted.
std::vector<std::string> ErrorModelNames();

}  // namespace roamlab::estimator
