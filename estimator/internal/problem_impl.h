// The private state of ProblemBuilder (problem.h), shared by problem.cc (adding measurements) and problem_streams.cc
// (ProblemBuilder::Create: binding the configuration to the recording).
#pragma once

#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "estimator/config.h"
#include "estimator/model_registry.h"
#include "estimator/models/ackermann_velocity.h"
#include "estimator/models/enu.h"
#include "estimator/problem.h"
#include "recording/recording.h"

namespace roamlab::estimator {

namespace internal {

// How a stream's samples attach to the poses: the master stream creates them; the others attach to one pose, to the
// pair or triple around their time stamp, or to the poses an interval apart (relative_motion).
enum class Attachment { kMaster, kOnePose, kPair, kTriple, kInterval };

}  // namespace internal

// A configured stream bound to its recording data.
struct StreamBinding {
  std::string name;
  StreamConfig config;
  const ModelSpec* spec = nullptr;
  const ErrorModelDefinition* definition = nullptr;   // the registered model (spec is its spec)
  std::shared_ptr<const BoundErrorModel> user_model;  // a user model's bound model (model_registry.h); null: built-in
  internal::Attachment attachment = internal::Attachment::kOnePose;
  const recording::Stream* primary = nullptr;
  const recording::Stream* steering = nullptr;  // ackermann
  int column = 0;                               // first column used in the primary stream
  bool right_then_left = false;                 // differential_drive: columns named [right, left] (else left, right)
  std::vector<std::string> slot_parameters;     // parameter name per model slot
  Eigen::MatrixXd noise_covariance;
  double row_covariance_scale = 0.0;  // odometer, relative_motion: weight of the rows' own covariance
  double interval_s = 0.0;            // relative_motion: T
  double wheelbase_m = 0.0;
  AckermannVelocityError::Options ackermann;  // ackermann: options contact_height_m, pitch_lever_m, front_slip_velocity
  Eigen::Vector3d field_world = Eigen::Vector3d::Zero();
  const recording::Stream* specific_force = nullptr;             // magnetometer, ackermann: inputs.specific_force
  int specific_force_column = 0;                                 // its first accelerometer column
  double drive_nm_per_mps2 = 0.0;                                // magnetometer: options.drive_nm_per_mps2
  Eigen::Vector3d forward_in_sensor = Eigen::Vector3d::UnitX();  // ackermann: options.forward_in_sensor (unit)
  // gyroscope, accelerometer, magnetometer: the slot time_offset_s (its index), and whether the samples take the
  // time-offset model (models/imu_time_offset.h): when the parameter is free or not zero.
  int time_offset_slot = -1;
  bool time_offset = false;
  std::deque<MeasurementRef> pending;
  std::vector<bool> frozen;  // per row of the primary source: repeats the first row of a frozen run (not measured)
};

// The IMU master's state (problem_imu.cc): the grid of pose times and the gyroscope's integration since the newest
// pose.
struct ImuMasterState {
  int accelerometer = -1;       // stream index of the first accelerometer stream
  int magnetometer = -1;        // stream index of the first magnetometer stream (-1: none)
  Time first_t;                 // the first IMU sample: the grid's origin
  std::int64_t next_index = 1;  // next grid pose: first_t + next_index / rate_hz
  Time cursor;                  // integrated up to here
  Eigen::Quaterniond delta = Eigen::Quaterniond::Identity();  // q_pose^-1 q(cursor), from the newest pose
  Eigen::Vector3d omega_body = Eigen::Vector3d::Zero();       // the held body rate [rad/s] of the last sample
};

struct ProblemBuilder::Impl {
  EstimatorConfig config;
  std::vector<StreamBinding> streams;
  int master = -1;
  std::optional<EnuConverter> enu;
  std::map<std::string, Manifold> parameter_manifold;
  std::map<std::string, ParameterConfig> parameter_config;
  std::map<std::string, Eigen::VectorXd> parameter_initial;
  std::optional<MeasurementRef> last_master;
  std::optional<ImuMasterState> imu;  // set when the master is a gyroscope stream
};

}  // namespace roamlab::estimator
