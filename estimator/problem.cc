#include "estimator/problem.h"

#include <algorithm>
#include <bitset>
#include <cmath>
#include <cstddef>
#include <functional>
#include <limits>
#include <numeric>
#include <optional>
#include <set>
#include <vector>

#include "common/check.h"
#include "estimator/factor.h"
#include "estimator/geometry.h"
#include "estimator/internal/problem_impl.h"
#include "estimator/models/absolute_pose.h"
#include "estimator/models/accelerometer.h"
#include "estimator/models/ackermann_odometer.h"
#include "estimator/models/ackermann_velocity.h"
#include "estimator/models/differential_drive.h"
#include "estimator/models/enu.h"
#include "estimator/models/gps.h"
#include "estimator/models/gyroscope.h"
#include "estimator/models/imu_time_offset.h"
#include "estimator/models/linear_velocity.h"
#include "estimator/models/magnetometer.h"
#include "estimator/models/mecanum_drive.h"
#include "estimator/models/odometer.h"
#include "estimator/models/omni3_drive.h"
#include "estimator/models/omni4_drive.h"
#include "estimator/models/prior.h"
#include "estimator/models/process.h"
#include "estimator/models/tricycle_drive.h"

namespace roamlab::estimator {

using internal::Attachment;
using recording::StreamType;

namespace {

// The IMU's time-offset models (models/imu_time_offset.h) move each reading by the slope of its stream's readings
// within this many seconds on each side (at least the neighbouring sample on each side): over 2n + 1 samples the
// slope's noise, which biases the offset towards zero, falls as n^-1.5, while the line smooths the motion's content
// above about 0.5 Hz (the header's numbers).
constexpr double kReadingRateHalfWindow = 0.3;

// The bound on the body's angular rate that bridges a gyroscope gap (BridgeGyroscopeGap) [rad/s], per axis: above
// what a ground vehicle turns, rolls or pitches at, so that on the axes the master measures (yaw, for an odometer) it
// adds a few percent of their information at most.
constexpr double kGapBridgeRateSigma = 3.0;

// Which pairs (a_i, b_i) have lengths that agree: |a_i| - |b_i| within kLengthOutlierScale robust standard
// deviations (1.4826 times the median absolute deviation) of the median difference, or within 1e-9 of it when the
// spread is nil.
constexpr double kLengthOutlierScale = 5.0;
std::vector<bool> ConsistentLengths(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b) {
  std::vector<double> d(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) d[i] = a[i].norm() - b[i].norm();
  const auto median = [](std::vector<double> v) {
    if (v.empty()) return 0.0;
    const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
    std::nth_element(v.begin(), mid, v.end());
    return *mid;
  };
  const double centre = median(d);
  std::vector<double> deviation(d.size());
  for (std::size_t i = 0; i < d.size(); ++i) deviation[i] = std::abs(d[i] - centre);
  const double bound = std::max(kLengthOutlierScale * 1.4826 * median(deviation), 1e-9);
  std::vector<bool> kept(d.size());
  for (std::size_t i = 0; i < d.size(); ++i) kept[i] = deviation[i] <= bound;
  return kept;
}

}  // namespace

ProblemBuilder::ProblemBuilder(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ProblemBuilder::~ProblemBuilder() = default;

bool ProblemBuilder::IsTimeVarying(const std::string& parameter) const {
  const auto it = impl_->parameter_config.find(parameter);
  return it != impl_->parameter_config.end() && it->second.process.type != ProcessConfig::Type::kConstant;
}

std::vector<std::string> ProblemBuilder::FreeParameterNames() const {
  std::vector<std::string> names;
  for (const auto& [pname, pc] : impl_->parameter_config)
    if (pc.free) names.push_back(pname);
  return names;
}

int ProblemBuilder::StreamOfFactor(FactorId id) const {
  const int* stream = stream_of_factor_.Find(id);
  return stream == nullptr ? -1 : *stream;
}

bool ProblemBuilder::StreamGated(int stream) const {
  return stream >= 0 && impl_->streams[static_cast<std::size_t>(stream)].config.gated;
}

int ProblemBuilder::ResidualDim(const std::string& stream) const {
  for (const StreamBinding& s : impl_->streams)
    if (s.name == stream) return s.definition->residual_dim;
  return 0;
}

std::vector<MeasurementRef> ProblemBuilder::Measurements() const {
  std::vector<MeasurementRef> out;
  for (std::size_t i = 0; i < impl_->streams.size(); ++i) {
    const recording::Stream& s = *impl_->streams[i].primary;
    const std::vector<bool>& frozen = impl_->streams[i].frozen;
    for (std::size_t r = 0; r < s.t.size(); ++r)
      if (frozen.empty() || !frozen[r]) out.push_back({s.t[r], static_cast<int>(i), static_cast<int>(r)});
  }
  const int master = impl_->master;
  std::stable_sort(out.begin(), out.end(), [master](const MeasurementRef& a, const MeasurementRef& b) {
    if (a.t != b.t) return a.t < b.t;
    if ((a.stream == master) != (b.stream == master)) return a.stream == master;
    return a.stream < b.stream;
  });
  return out;
}

namespace {

// Steering angle at time t, linearly interpolated (exact when the streams share time stamps).
double SteeringAt(const recording::Stream& s, Time t) {
  const auto it = std::lower_bound(s.t.begin(), s.t.end(), t);
  if (it == s.t.end()) return s.values(static_cast<int>(s.t.size()) - 1, 0);
  const int i = static_cast<int>(it - s.t.begin());
  if (*it == t || i == 0) return s.values(i, 0);
  const double w = SecondsBetween(s.t[i - 1], t) / SecondsBetween(s.t[i - 1], s.t[i]);
  return (1.0 - w) * s.values(i - 1, 0) + w * s.values(i, 0);
}

// Mean wheel rates [rad/s] over [t_a, t_b] from the cumulative wheel angles of rows a < b; nullopt past the last row.
std::optional<Eigen::VectorXd> WheelRates(const recording::Stream& s, int row_a, int row_b) {
  if (row_b >= static_cast<int>(s.t.size())) return std::nullopt;
  const double dt = SecondsBetween(s.t[row_a], s.t[row_b]);
  return Eigen::VectorXd((s.values.row(row_b) - s.values.row(row_a)).transpose() / dt);
}

// The same over [t_row, t_row+1].
std::optional<Eigen::VectorXd> WheelRates(const recording::Stream& s, int row) { return WheelRates(s, row, row + 1); }

// A tricycle's steering angle over [t_a, t_b] of its wheel stream: the mean of the interval's ends.
double IntervalSteering(const StreamBinding& s, int row_a, int row_b) {
  return 0.5 * (SteeringAt(*s.steering, s.primary->t[row_a]) + SteeringAt(*s.steering, s.primary->t[row_b]));
}

// A differential drive's (left, right) wheel rates over [t_a, t_b], whatever the order of the stream's columns.
std::optional<Eigen::VectorXd> LeftRightRates(const StreamBinding& s, int row_a, int row_b) {
  std::optional<Eigen::VectorXd> rates = WheelRates(*s.primary, row_a, row_b);
  if (rates && s.right_then_left) std::swap((*rates)[0], (*rates)[1]);
  return rates;
}

// The (C, S) deformation harmonics of the left and right wheels over [t_a, t_b] (models/differential_drive.h).
std::pair<Eigen::Vector2d, Eigen::Vector2d> LeftRightHarmonics(const StreamBinding& s, int row_a, int row_b) {
  const Eigen::MatrixXd& angles = s.primary->values;
  const int left = s.right_then_left ? 1 : 0, right = 1 - left;
  return {DifferentialDriveError::DeformationHarmonics(angles(row_a, left), angles(row_b, left)),
          DifferentialDriveError::DeformationHarmonics(angles(row_a, right), angles(row_b, right))};
}

// The calibration slots that a cumulative wheel model's factor joins after its two poses (the first n of the
// stream's slots); 0 for a model whose readings are not cumulative wheel angles.
std::size_t CumulativeSlotCount(const std::string& model) {
  if (model == "differential_drive") return 6;
  if (model == "tricycle_drive") return 3;
  if (model == "omni3_drive") return 4;
  if (model == "omni4_drive" || model == "mecanum_drive") return 5;
  return 0;
}

// The factor of a cumulative wheel stream between its rows a < b, whose poses are dt_s apart: the mean wheel rates
// over the span; null past the last row.
std::unique_ptr<Factor> CumulativeFactor(const StreamBinding& s, int row_a, int row_b, double dt_s) {
  const std::string& model = s.config.model;
  if (model == "differential_drive") {
    const auto rates = LeftRightRates(s, row_a, row_b);
    if (!rates) return nullptr;
    const auto [harmonics_left, harmonics_right] = LeftRightHarmonics(s, row_a, row_b);
    return MakeFactor(DifferentialDriveError((*rates)[0], (*rates)[1], dt_s, harmonics_left, harmonics_right));
  }
  const auto rates = WheelRates(*s.primary, row_a, row_b);
  if (!rates) return nullptr;
  if (model == "tricycle_drive") return MakeFactor(TricycleDriveError((*rates)[0], IntervalSteering(s, row_a, row_b), dt_s));
  if (model == "omni3_drive") return MakeFactor(Omni3DriveError(*rates, dt_s));
  if (model == "omni4_drive") return MakeFactor(Omni4DriveError(*rates, dt_s));
  return MakeFactor(MecanumDriveError(*rates, dt_s));
}

// The specific force [m/s^2] of a stream's inputs.specific_force at time t: linear interpolation between the
// rows around t, the first or last row outside the stream's span.
Eigen::Vector3d SpecificForceAt(const StreamBinding& s, Time t) {
  const recording::Stream& f = *s.specific_force;
  const auto row = [&](std::size_t i) {
    return Eigen::Vector3d(f.values.row(static_cast<Eigen::Index>(i)).segment<3>(s.specific_force_column).transpose());
  };
  const auto it = std::lower_bound(f.t.begin(), f.t.end(), t);
  if (it == f.t.begin()) return row(0);
  if (it == f.t.end()) return row(f.t.size() - 1);
  const std::size_t i = static_cast<std::size_t>(it - f.t.begin());
  const double span = SecondsBetween(f.t[i - 1], f.t[i]);
  const double w = span > 0.0 ? SecondsBetween(f.t[i - 1], t) / span : 1.0;
  return (1.0 - w) * row(i - 1) + w * row(i);
}

// The rate [units / s] of a stream's three columns from `column` at row `row`: the slope of the least-squares line
// through the rows within kReadingRateHalfWindow of it, and at least the neighbouring row on each side that exists
// (models/imu_time_offset.h); zero for a single row.
Eigen::Vector3d ReadingRate(const recording::Stream& data, int column, int row) {
  const Time t = data.t[static_cast<std::size_t>(row)];
  const std::int64_t half_ns = std::llround(kReadingRateHalfWindow * 1e9);
  const auto first = std::lower_bound(data.t.begin(), data.t.end(), Time::FromNanoseconds(t.nanoseconds() - half_ns));
  const auto last = std::upper_bound(data.t.begin(), data.t.end(), Time::FromNanoseconds(t.nanoseconds() + half_ns));
  const int lo = std::min(static_cast<int>(first - data.t.begin()), std::max(row - 1, 0));
  const int hi =
      std::max(static_cast<int>(last - data.t.begin()) - 1, std::min(row + 1, static_cast<int>(data.t.size()) - 1));
  double mean_t = 0.0;
  Eigen::Vector3d mean_z = Eigen::Vector3d::Zero();
  for (int i = lo; i <= hi; ++i) {
    mean_t += SecondsBetween(t, data.t[static_cast<std::size_t>(i)]);
    mean_z += data.values.row(i).segment<3>(column).transpose();
  }
  mean_t /= hi - lo + 1;
  mean_z /= hi - lo + 1;
  double stt = 0.0;
  Eigen::Vector3d stz = Eigen::Vector3d::Zero();
  for (int i = lo; i <= hi; ++i) {
    const double dt = SecondsBetween(t, data.t[static_cast<std::size_t>(i)]) - mean_t;
    stt += dt * dt;
    stz += dt * (data.values.row(i).segment<3>(column).transpose() - mean_z);
  }
  return stt > 0.0 ? Eigen::Vector3d(stz / stt) : Eigen::Vector3d::Zero();
}

// Whether the stream has a measured row (not a frozen repeat) stamped in [a, b).
bool HasRowIn(const StreamBinding& s, Time a, Time b) {
  const std::vector<Time>& t = s.primary->t;
  for (auto it = std::lower_bound(t.begin(), t.end(), a); it != t.end() && *it < b; ++it)
    if (s.frozen.empty() || !s.frozen[static_cast<std::size_t>(it - t.begin())]) return true;
  return false;
}

// A master interval that no gyroscope row falls in (a dropout, or a frozen IMU's repeats left out) leaves the relative
// rotation of its poses to the master's rows, which constrain some of its axes only (an Ackermann or wheel odometer
// says little about roll and pitch rates): the newest pose would have directions no factor constrains, the update's
// solve would step along them at the damping's whim, and the gate would then test (and reject) the master's factor
// where nothing can check it, leaving a pose without information. The gap is bridged by what is known without the
// gyroscope: the body's rate over the interval is bounded, a zero-rate reading of the gyroscope's own model with the
// noise kGapBridgeRateSigma, far weaker than the master's rows on the axes they measure. Not a measurement: neither
// gated nor counted. Exempting the master's factor from the gate instead would leave the solve stepping along the free
// directions all the same, and knowing when a factor is the only check of a direction takes a marginal covariance per
// factor and update; the bridge states the one assumption it adds (the body turns slower than a few rad/s).
void BridgeGyroscopeGap(const std::vector<StreamBinding>& streams,
                        const std::function<VariableId(const std::string&)>& parameter, const PoseNode& from,
                        const PoseNode& to, Graph* graph) {
  for (const StreamBinding& s : streams) {
    if (s.config.model != "gyroscope" || s.user_model || HasRowIn(s, from.t, to.t)) continue;
    graph->AddFactor(MakeFactor(GyroscopeError(Eigen::Vector3d::Zero(), SecondsBetween(from.t, to.t))),
                     {from.id, to.id, parameter(s.slot_parameters[0]), parameter(s.slot_parameters[1]),
                      parameter(s.slot_parameters[2])},
                     Eigen::Matrix3d::Identity() * (kGapBridgeRateSigma * kGapBridgeRateSigma), Loss::Trivial(),
                     s.name + " gap bridge", to.t);
  }
}

}  // namespace

void ProblemBuilder::Add(const MeasurementRef& m) {
  Impl& im = *impl_;
  StreamBinding& s = im.streams[m.stream];
  if (!poses_.empty() && m.t < poses_.front().t && m.stream != im.master) {
    StreamCounts& c = counts_[s.name];
    ++(popped_any_ ? c.too_late : c.outside);
    return;
  }
  if (m.stream == im.master && im.imu) {
    if (AddImuMasterSample(m)) s.pending.push_back(m);
  } else if (m.stream == im.master) {
    AddMasterSample(m);
  } else {
    s.pending.push_back(m);
  }
  AttachPending();
}
std::size_t ProblemBuilder::NearestPose(Time t) const {
  const auto it =
      std::lower_bound(poses_.begin(), poses_.end(), t, [](const PoseNode& p, Time time) { return p.t < time; });
  if (it == poses_.end()) return poses_.size() - 1;
  const std::size_t i = static_cast<std::size_t>(it - poses_.begin());
  if (i == 0) return 0;
  return (t.nanoseconds() - poses_[i - 1].t.nanoseconds() < it->t.nanoseconds() - t.nanoseconds()) ? i - 1 : i;
}

VariableId ProblemBuilder::ParameterAt(const std::string& name, std::size_t k) const {
  const auto it = parameters_.find(name);
  if (it != parameters_.end()) return it->second;
  return poses_[k].instances.at(name);
}

VariableId ProblemBuilder::CreatePose(Time t, const Eigen::VectorXd& value) {
  Impl& im = *impl_;
  PoseNode node;
  node.t = t;
  node.id = graph_.AddVariable({"pose", Manifold::Pose(), value, false, t});
  // Time-varying parameter instances, joined to the previous instance by their process. With a spacing, a pose less
  // than interval_s after the current instance's first pose shares that instance (1 us of slack for stamps rounded
  // to the master period).
  for (const auto& [pname, pc] : im.parameter_config) {
    if (pc.process.type == ProcessConfig::Type::kConstant) continue;
    const bool first = poses_.empty();
    if (!first && pc.process.interval_s > 0.0) {
      const VariableId current = poses_.back().instances.at(pname);
      if (SecondsBetween(*graph_.variable(current).stamp, t) < pc.process.interval_s - 1e-6) {
        node.instances[pname] = current;
        continue;
      }
    }
    const Eigen::VectorXd init =
        first ? im.parameter_initial.at(pname) : graph_.variable(poses_.back().instances.at(pname)).value;
    const VariableId id = graph_.AddVariable({pname, Manifold::Euclidean(3), init, !pc.free, t});
    node.instances[pname] = id;
    const Eigen::Vector3d& sigma = pc.process.sigma;
    if (first) {
      // A Gauss-Markov process starts from its stationary distribution, N(0, sigma^2) (a random walk from anywhere).
      if (pc.process.type == ProcessConfig::Type::kGaussMarkov && pc.free) {
        graph_.AddFactor(MakeFactor(PriorError<Vector3Block>(Eigen::Vector3d::Zero())), {id},
                         Eigen::Matrix3d(sigma.array().square().matrix().asDiagonal()), Loss::Trivial(), pname, t);
      }
      continue;
    }
    const VariableId prev = poses_.back().instances.at(pname);
    const double dt = SecondsBetween(*graph_.variable(prev).stamp, t);
    if (pc.process.type == ProcessConfig::Type::kRandomWalk) {
      const RandomWalkError<3> process(dt);
      Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
      for (int i = 0; i < 3; ++i) covariance(i, i) = process.NoiseVariance(sigma[i]);
      graph_.AddFactor(MakeFactor(process), {prev, id}, covariance, Loss::Trivial(), pname, t);
    } else {
      const GaussMarkovError<3> process(dt, pc.process.tau_s);
      Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
      for (int i = 0; i < 3; ++i) covariance(i, i) = process.NoiseVariance(sigma[i], i);
      graph_.AddFactor(MakeFactor(process), {prev, id}, covariance, Loss::Trivial(), pname, t);
    }
  }
  poses_.push_back(node);
  return node.id;
}

void ProblemBuilder::AddMasterSample(const MeasurementRef& m) {
  Impl& im = *impl_;
  if (poses_.empty()) {
    CreatePose(m.t, Manifold::Pose().Identity());
    if (!has_absolute_sensor_) {
      // No absolute sensor: the first pose defines W (seed, Section III-A); a tight prior removes the gauge freedom.
      graph_.AddFactor(MakeFactor(PriorError<PoseBlock>(Manifold::Pose().Identity())), {poses_.front().id},
                       Eigen::MatrixXd::Identity(6, 6) * 1e-12, Loss::Trivial(), "prior", m.t);
    }
    im.last_master = m;  // counted when its odometric factor attaches to the next pose
    return;
  }
  if (!im.last_master || m.t <= im.last_master->t) {
    ++counts_[im.streams[m.stream].name].too_late;
    return;
  }
  // The odometric factor of the previous master sample joins the last pose and the new one; the new pose's initial
  // guess is the seed's eq. 7 prediction from that sample at the current parameter values.
  const VariableId prev = poses_.back().id;
  const MeasurementRef odo = *im.last_master;
  const double dt = SecondsBetween(odo.t, m.t);
  const StreamBinding& s = im.streams[odo.stream];
  const Eigen::RowVectorXd row = s.primary->values.row(odo.row);
  const auto value = [&](std::size_t slot) {
    return graph_.variable(ParameterAt(s.slot_parameters[slot], poses_.size() - 1)).value;
  };
  Eigen::Vector3d v_body = Eigen::Vector3d::Zero(), omega_body = Eigen::Vector3d::Zero();
  if (s.config.model == "ackermann" || s.config.model == "ackermann_seed") {
    const double kv_over_l = value(0)[0], k_theta = value(1)[0], k_gamma = value(2)[0];
    const double z_v = row[s.column];
    v_body.x() = kv_over_l * s.wheelbase_m * z_v;
    omega_body.z() = kv_over_l * z_v * std::tan(k_theta * SteeringAt(*s.steering, odo.t) + k_gamma);
  } else if (s.config.model == "differential_drive") {
    if (const auto rates = LeftRightRates(s, odo.row, odo.row + 1)) {
      DifferentialDriveError::BodyVelocity((*rates)[0], (*rates)[1], value(0)[0], value(1)[0] * value(3)[0],
                                           value(2)[0], &v_body, &omega_body);
    }
  } else if (s.config.model == "omni3_drive") {
    if (const auto rates = WheelRates(*s.primary, odo.row)) {
      Omni3DriveError::BodyVelocity(*rates, Eigen::Vector3d(value(0)[0], value(1)[0], value(2)[0]), value(3)[0],
                                    &v_body, &omega_body);
    }
  } else if (s.config.model == "omni4_drive") {
    if (const auto rates = WheelRates(*s.primary, odo.row)) {
      Omni4DriveError::BodyVelocity(*rates, Eigen::Vector4d(value(0)[0], value(1)[0], value(2)[0], value(3)[0]),
                                    value(4)[0], &v_body, &omega_body);
    }
  } else if (s.config.model == "tricycle_drive") {
    if (const auto rates = WheelRates(*s.primary, odo.row)) {
      TricycleDriveError::BodyVelocity((*rates)[0], IntervalSteering(s, odo.row, odo.row + 1), value(0)[0], value(1)[0], value(2)[0],
                                       &v_body, &omega_body);
    }
  } else if (s.config.model == "mecanum_drive") {
    if (const auto rates = WheelRates(*s.primary, odo.row)) {
      MecanumDriveError::BodyVelocity(*rates, Eigen::Vector4d(value(0)[0], value(1)[0], value(2)[0], value(3)[0]),
                                      value(4)[0], &v_body, &omega_body);
    }
  } else {
    const Eigen::VectorXd q = value(1);
    SensorToBodyVelocity<double>(row.head<3>().transpose(), row.segment<3>(3).transpose(),
                                 Eigen::Quaterniond(q[0], q[1], q[2], q[3]), value(0), &v_body, &omega_body);
  }
  const Pose<double> predicted =
      PredictPose<double>(PoseFromArray(graph_.variable(prev).value.data()), v_body, omega_body, dt);
  Eigen::VectorXd next_value(7);
  PoseToArray(predicted, next_value.data());
  CreatePose(m.t, next_value);
  im.last_master = m;
  TryAttach(odo);
  const std::size_t k = poses_.size() - 2;
  const auto parameter = [&](const std::string& name) { return ParameterAt(name, k); };
  BridgeGyroscopeGap(im.streams, parameter, poses_[k], poses_.back(), &graph_);
}

ProblemBuilder::Placement ProblemBuilder::PlaceSample(const MeasurementRef& m, const StreamBinding& s, std::size_t* k) {
  if (poses_.empty() || m.t > poses_.back().t) return Placement::kWait;
  if (m.t < poses_.front().t) {
    ++counts_[s.name].outside;
    return Placement::kOutside;
  }
  switch (s.attachment) {
    case Attachment::kMaster:
    case Attachment::kPair: {
      if (m.t >= poses_.back().t) return Placement::kWait;
      const auto it =
          std::upper_bound(poses_.begin(), poses_.end(), m.t, [](Time time, const PoseNode& p) { return time < p.t; });
      *k = static_cast<std::size_t>(it - poses_.begin()) - 1;
      break;
    }
    case Attachment::kTriple:
      *k = NearestPose(m.t);
      if (*k + 1 >= poses_.size()) return Placement::kWait;
      if (*k == 0) {
        ++counts_[s.name].outside;
        return Placement::kOutside;
      }
      break;
    case Attachment::kOnePose:
      *k = NearestPose(m.t);
      break;
    case Attachment::kInterval:
      break;
  }
  return Placement::kAttach;
}

bool ProblemBuilder::TryAttach(const MeasurementRef& m) {
  Impl& im = *impl_;
  StreamBinding& s = im.streams[m.stream];
  const recording::Stream& data = *s.primary;
  const Eigen::RowVectorXd row = data.values.row(m.row);
  const auto slot = [&](std::size_t i, std::size_t k) { return ParameterAt(s.slot_parameters[i], k); };
  const auto z3 = [&] { return Eigen::Vector3d(row.segment<3>(s.column).transpose()); };
  const auto reading_rate = [&] { return ReadingRate(data, s.column, m.row); };

  // Which poses: bail out (keep waiting) until they exist.
  if (s.attachment == Attachment::kInterval) return TryAttachInterval(m);
  std::size_t k = 0;
  switch (PlaceSample(m, s, &k)) {
    case Placement::kWait:
      return false;
    case Placement::kOutside:
      return true;
    case Placement::kAttach:
      break;
  }

  if (s.user_model) return AttachUserSample(m, k);

  // The factor, by model.
  const std::string& model = s.config.model;
  std::unique_ptr<Factor> factor;
  std::vector<VariableId> vars;
  bool cumulative = false;  // a span of a cumulative wheel master stream (cumulative_spans)
  const double dt = k + 1 < poses_.size() ? SecondsBetween(poses_[k].t, poses_[k + 1].t) : 0.0;
  if (model == "ackermann" || model == "ackermann_seed") {
    const double z_v = row[s.column];
    const double z_theta = SteeringAt(*s.steering, m.t);
    vars = {poses_[k].id, poses_[k + 1].id, slot(0, k), slot(1, k), slot(2, k)};
    if (model == "ackermann") {
      const double f_x = s.specific_force ? s.forward_in_sensor.dot(SpecificForceAt(s, m.t)) : 0.0;
      factor = MakeFactor(AckermannVelocityError(z_v, z_theta, s.wheelbase_m, dt, s.ackermann, f_x));
      vars.insert(vars.end(), {slot(3, k), slot(4, k), slot(5, k), slot(6, k), slot(7, k), slot(8, k)});
    } else {
      factor = MakeFactor(AckermannOdometerError(z_v, z_theta, s.wheelbase_m, dt));
    }
  } else if (const std::size_t slots = CumulativeSlotCount(model); slots > 0) {
    factor = CumulativeFactor(s, m.row, m.row + 1, dt);
    if (factor == nullptr) {
      ++counts_[s.name].outside;
      return true;
    }
    vars = {poses_[k].id, poses_[k + 1].id};
    for (std::size_t i = 0; i < slots; ++i) vars.push_back(slot(i, k));
    cumulative = s.attachment == Attachment::kMaster;
  } else if (model == "odometer") {
    factor = MakeFactor(OdometerError(row.head<6>().transpose(), dt));
    vars = {poses_[k].id, poses_[k + 1].id, slot(0, k), slot(1, k)};
    const FactorId id =
        graph_.AddFactor(std::move(factor), vars, SampleNoiseCovariance(s, row), s.config.loss, s.name, m.t);
    stream_of_factor_.Add(id, m.stream);
    ++counts_[s.name].attached;
    return true;
  } else if (model == "gyroscope") {
    if (s.time_offset) {
      factor = MakeFactor(GyroscopeTimeOffsetError(GyroscopeError(z3(), dt), reading_rate()));
    } else {
      factor = MakeFactor(GyroscopeError(z3(), dt));
    }
    vars = {poses_[k].id, poses_[k + 1].id, slot(0, k), slot(1, k), slot(2, k)};
  } else if (model == "linear_velocity") {
    factor = MakeFactor(LinearVelocityError(z3(), dt));
    vars = {poses_[k].id, poses_[k + 1].id, slot(0, k), slot(1, k)};
  } else if (model == "accelerometer") {
    AccelerometerError plain(z3(), SecondsBetween(poses_[k - 1].t, poses_[k].t),
                             SecondsBetween(poses_[k].t, poses_[k + 1].t));
    if (s.time_offset) {
      factor = MakeFactor(AccelerometerTimeOffsetError(std::move(plain), reading_rate()));
    } else {
      factor = MakeFactor(std::move(plain));
    }
    vars = {poses_[k - 1].id, poses_[k].id, poses_[k + 1].id, slot(0, k), slot(1, k), slot(2, k), slot(3, k)};
  } else if (model == "magnetometer") {
    const Eigen::Vector3d f_sensor = s.specific_force ? SpecificForceAt(s, m.t) : Eigen::Vector3d::Zero();
    MagnetometerError plain(z3(), s.field_world, f_sensor, s.drive_nm_per_mps2);
    if (s.time_offset) {
      factor = MakeFactor(MagnetometerTimeOffsetError(std::move(plain), reading_rate()));
    } else {
      factor = MakeFactor(std::move(plain));
    }
    vars = {poses_[k].id, slot(0, k), slot(1, k), slot(2, k), slot(3, k)};
  } else if (model == "gps") {
    Eigen::Vector3d z = z3();
    if (data.info.type == StreamType::kGps) z = im.enu->ToEnu(z[0], z[1], z[2]);
    factor = MakeFactor(GpsError(z));
    vars = {poses_[k].id, slot(0, k), slot(1, k)};
    absolute_fixes_.emplace_back(poses_[k].id, z);
  } else if (model == "absolute_pose") {
    const Eigen::Quaterniond q(row[6], row[3], row[4], row[5]);
    factor = MakeFactor(AbsolutePoseError(row.head<3>().transpose(), q.normalized()));
    vars = {poses_[k].id, slot(0, k), slot(1, k)};
    absolute_fixes_.emplace_back(poses_[k].id, row.head<3>().transpose());
    orientation_fixes_.push_back({poses_[k].id, slot(1, k), q.normalized()});
  }
  if (s.time_offset) vars.push_back(slot(static_cast<std::size_t>(s.time_offset_slot), k));
  const FactorId id = graph_.AddFactor(std::move(factor), vars, s.noise_covariance, s.config.loss, s.name, m.t);
  stream_of_factor_.Add(id, m.stream);
  if (cumulative) cumulative_spans_[id] = {m.stream, m.row, m.row + 1, false, false};
  ++counts_[s.name].attached;
  return true;
}

std::optional<FactorEntry> ProblemBuilder::CumulativeBridge(const std::vector<FactorId>& run) const {
  if (run.empty()) return std::nullopt;
  std::vector<const CumulativeSpan*> spans;
  for (std::size_t i = 0; i < run.size(); ++i) {
    const auto it = cumulative_spans_.find(run[i]);
    if (it == cumulative_spans_.end() || it->second.replaced || graph_.factors().count(run[i]) == 0)
      return std::nullopt;
    spans.push_back(&it->second);
    if (i > 0 && (spans[i]->stream != spans[0]->stream || spans[i]->row_begin != spans[i - 1]->row_end ||
                  graph_.factor(run[i]).variables[0] != graph_.factor(run[i - 1]).variables[1]))
      return std::nullopt;
  }
  const StreamBinding& s = impl_->streams[spans[0]->stream];
  const FactorEntry& first = graph_.factor(run.front());
  FactorEntry bridge;
  bridge.variables = first.variables;
  bridge.variables[1] = graph_.factor(run.back()).variables[1];
  const Variable& pose_a = graph_.variable(bridge.variables[0]);
  const Variable& pose_b = graph_.variable(bridge.variables[1]);
  if (!pose_a.stamp || !pose_b.stamp) return std::nullopt;
  bridge.factor = CumulativeFactor(s, spans.front()->row_begin, spans.back()->row_end,
                                   SecondsBetween(*pose_a.stamp, *pose_b.stamp));
  if (bridge.factor == nullptr) return std::nullopt;
  bridge.noise = first.noise;
  bridge.loss = first.loss;
  bridge.stream = first.stream;
  bridge.stamp = first.stamp;
  return bridge;
}

namespace {

// A spike's neighbours (ProblemBuilder::IsCumulativeSpike): up to 5 rows either side, at most 4 of them left out.
constexpr int kSpikeHalfWindow = 5;
constexpr int kSpikeMaxLeftOut = 4;

// Row j's readings' whitened squared distance from the quadratic `coeffs` in time about t0 (QuadraticFitDistances).
double WhitenedFromQuadratic(const recording::Stream& r, int j, Time t0, double rate_sigma,
                             const Eigen::MatrixXd& coeffs) {
  const double tau = SecondsBetween(t0, r.t[j]);
  const int a = std::max(j - 1, 0), b = std::min(j + 1, static_cast<int>(r.t.size()) - 1);
  const double sigma = rate_sigma * SecondsBetween(r.t[a], r.t[b]) / (b - a) / std::sqrt(2.0);
  const Eigen::RowVectorXd fit = coeffs.row(0) + tau * coeffs.row(1) + tau * tau * coeffs.row(2);
  return (r.values.row(j) - fit).squaredNorm() / (sigma * sigma);
}

// The readings of rows `rows` of a cumulative stream against the quadratic in time about `t0` fitted to them: each
// row's whitened squared distance, its reading's noise that of a span's wheel rate `rate_sigma` times the local
// sample interval over sqrt(2). Also the fit's coefficients (constant, slope, curvature; a column per wheel).
std::vector<double> QuadraticFitDistances(const recording::Stream& r, const std::vector<int>& rows, Time t0,
                                          double rate_sigma, Eigen::MatrixXd* coeffs) {
  Eigen::MatrixXd design(static_cast<Eigen::Index>(rows.size()), 3);
  Eigen::MatrixXd readings(static_cast<Eigen::Index>(rows.size()), r.values.cols());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const double tau = SecondsBetween(t0, r.t[rows[i]]);
    design.row(static_cast<Eigen::Index>(i)) << 1.0, tau, tau * tau;
    readings.row(static_cast<Eigen::Index>(i)) = r.values.row(rows[i]);
  }
  *coeffs = design.colPivHouseholderQr().solve(readings);
  std::vector<double> distances;
  for (std::size_t i = 0; i < rows.size(); ++i)
    distances.push_back(WhitenedFromQuadratic(r, rows[i], t0, rate_sigma, *coeffs));
  return distances;
}

}  // namespace

bool ProblemBuilder::IsCumulativeSpike(int stream, int row, int last_row,
                                       const std::function<double(int)>& threshold) const {
  const StreamBinding& s = impl_->streams[static_cast<std::size_t>(stream)];
  const recording::Stream& r = *s.primary;
  last_row = std::min(last_row, static_cast<int>(r.t.size()) - 1);
  if (row - 2 < 0 || row + 2 > last_row) return false;
  const double rate_sigma = std::sqrt(s.noise_covariance(0, 0));
  const double bound = threshold(static_cast<int>(r.values.cols()));
  std::vector<int> neighbours;
  for (int j = std::max(0, row - kSpikeHalfWindow); j <= std::min(last_row, row + kSpikeHalfWindow); ++j)
    if (j != row) neighbours.push_back(j);
  const int n = static_cast<int>(neighbours.size());
  // The fewest neighbours left out for the rest to fit within the bound (the best such fit), then the reading.
  for (int left_out = 0; left_out <= kSpikeMaxLeftOut; ++left_out) {
    double best_total = std::numeric_limits<double>::infinity(), best_reading = 0.0;
    for (unsigned mask = 0; mask < (1u << n); ++mask) {
      if (static_cast<int>(std::bitset<32>(mask).count()) != left_out) continue;
      std::vector<int> kept;
      for (int i = 0; i < n; ++i)
        if ((mask & (1u << i)) == 0) kept.push_back(neighbours[static_cast<std::size_t>(i)]);
      const auto before = std::count_if(kept.begin(), kept.end(), [&](int j) { return j < row; });
      if (before < 2 || static_cast<std::ptrdiff_t>(kept.size()) - before < 2) continue;
      Eigen::MatrixXd coeffs;
      const std::vector<double> d = QuadraticFitDistances(r, kept, r.t[row], rate_sigma, &coeffs);
      if (*std::max_element(d.begin(), d.end()) > bound) continue;
      const double total = std::accumulate(d.begin(), d.end(), 0.0);
      if (total < best_total) {
        best_total = total;
        best_reading = WhitenedFromQuadratic(r, row, r.t[row], rate_sigma, coeffs);
      }
    }
    if (best_total < std::numeric_limits<double>::infinity()) return best_reading > bound;
  }
  return false;
}

std::optional<FactorId> ProblemBuilder::BridgeCumulativeRun(const std::vector<FactorId>& run) {
  std::optional<FactorEntry> bridge = CumulativeBridge(run);
  if (!bridge) return std::nullopt;
  const CumulativeSpan& first = cumulative_spans_.at(run.front());
  const CumulativeSpan span{first.stream, first.row_begin, cumulative_spans_.at(run.back()).row_end, true, false};
  const FactorId id = graph_.AddFactor(std::move(bridge->factor), bridge->variables, bridge->noise->covariance,
                                       bridge->loss, bridge->stream, bridge->stamp);
  stream_of_factor_.Add(id, span.stream);
  cumulative_spans_[id] = span;
  int& rejected = counts_[bridge->stream].rejected;
  --rejected;
  for (const FactorId f : run) {
    FactorEntry& entry = graph_.mutable_factor(f);
    if (entry.active) ++rejected;
    entry.active = false;
    cumulative_spans_[f].replaced = true;
  }
  return id;
}

bool ProblemBuilder::AttachUserSample(const MeasurementRef& m, std::size_t k) {
  const StreamBinding& s = impl_->streams[m.stream];
  std::vector<std::size_t> pose_indices = {k};
  if (s.attachment == Attachment::kPair) pose_indices = {k, k + 1};
  if (s.attachment == Attachment::kTriple) pose_indices = {k - 1, k, k + 1};
  ModelSample sample{m.t, s.primary->values.row(m.row), {}};
  std::vector<VariableId> vars;
  for (const std::size_t i : pose_indices) {
    sample.pose_times.push_back(poses_[i].t);
    vars.push_back(poses_[i].id);
  }
  for (const std::string& pname : s.slot_parameters) vars.push_back(ParameterAt(pname, k));
  std::unique_ptr<Factor> factor = s.user_model->MakeFactor(sample);
  if (factor == nullptr) {
    ++counts_[s.name].outside;
    return true;
  }
  ROAMLAB_CHECK(factor->residual_dim() == s.definition->residual_dim,
                "model " << s.config.model << " of stream '" << s.name << "' made a factor of dimension "
                         << factor->residual_dim() << ", registered " << s.definition->residual_dim);
  const FactorId id = graph_.AddFactor(std::move(factor), vars, s.noise_covariance, s.config.loss, s.name, m.t);
  stream_of_factor_.Add(id, m.stream);
  ++counts_[s.name].attached;
  return true;
}

Eigen::MatrixXd ProblemBuilder::SampleNoiseCovariance(const StreamBinding& s, const Eigen::RowVectorXd& row) {
  if (!(s.row_covariance_scale > 0.0)) return s.noise_covariance;
  // The row's covariance of [v; omega] from its upper triangle (recording.h), added to the configured noise.
  Eigen::MatrixXd covariance = s.noise_covariance;
  int c = 6;
  for (int i = 0; i < 6; ++i)
    for (int j = i; j < 6; ++j) {
      covariance(i, j) += s.row_covariance_scale * row[c];
      if (j != i) covariance(j, i) += s.row_covariance_scale * row[c];
      ++c;
    }
  return covariance;
}

bool ProblemBuilder::TryAttachInterval(const MeasurementRef& m) {
  StreamBinding& s = impl_->streams[m.stream];
  if (poses_.empty()) return false;
  const std::int64_t half_ns = std::llround(0.5e9 * s.interval_s);
  const Time t_a = Time::FromNanoseconds(m.t.nanoseconds() - half_ns);
  const Time t_b = Time::FromNanoseconds(m.t.nanoseconds() + half_ns);
  // The pose nearest t_a must still be in the graph: t_a no earlier than half a master period before the oldest pose.
  if (t_a < poses_.front().t) {
    const bool near_front = poses_.size() >= 2 && 2 * (poses_.front().t.nanoseconds() - t_a.nanoseconds()) <=
                                                      poses_[1].t.nanoseconds() - poses_.front().t.nanoseconds();
    if (!near_front) {
      ++(popped_any_ ? counts_[s.name].too_late : counts_[s.name].outside);
      return true;
    }
  }
  // The pose nearest t_b is known once a pose at or after t_b exists.
  if (poses_.back().t < t_b) return false;
  const std::size_t a = NearestPose(t_a);
  std::size_t b = std::max(NearestPose(t_b), a + 1);
  if (b >= poses_.size()) return false;

  const Eigen::RowVectorXd row = s.primary->values.row(m.row);
  const double dt = SecondsBetween(poses_[a].t, poses_[b].t);
  const std::vector<VariableId> vars = {poses_[a].id, poses_[b].id, ParameterAt(s.slot_parameters[0], a),
                                        ParameterAt(s.slot_parameters[1], a)};
  const FactorId id = graph_.AddFactor(MakeFactor(OdometerError(row.head<6>().transpose(), dt)), vars,
                                       SampleNoiseCovariance(s, row), s.config.loss, s.name, m.t);
  stream_of_factor_.Add(id, m.stream);
  ++counts_[s.name].attached;
  return true;
}

void ProblemBuilder::AttachPending() {
  for (StreamBinding& s : impl_->streams) {
    for (auto it = s.pending.begin(); it != s.pending.end();) {
      if (TryAttach(*it)) {
        it = s.pending.erase(it);
      } else {
        ++it;
      }
    }
  }
}

void ProblemBuilder::Finish() {
  for (StreamBinding& s : impl_->streams) {
    counts_[s.name].outside += static_cast<int>(s.pending.size());
    s.pending.clear();
  }
  // The last master sample has no following pose: it is outside the graph.
  if (impl_->last_master) ++counts_[impl_->streams[impl_->master].name].outside;
  impl_->last_master.reset();
}

void ProblemBuilder::PopOldestPose() {
  poses_.pop_front();
  popped_any_ = true;
  // Forget the streams of factors that have left the graph, oldest first, so that a long online run keeps a bounded
  // map. (Not "below the oldest factor in the graph": a factor that never leaves, such as the calibration prior, would
  // keep every entry.)
  while (!stream_of_factor_.empty() && graph_.factors().count(stream_of_factor_.begin()->first) == 0)
    stream_of_factor_.Erase(stream_of_factor_.begin()->first);
  for (auto it = cumulative_spans_.begin(); it != cumulative_spans_.end();)
    it = graph_.factors().count(it->first) == 0 ? cumulative_spans_.erase(it) : std::next(it);
  absolute_fixes_.erase(std::remove_if(absolute_fixes_.begin(), absolute_fixes_.end(),
                                       [this](const auto& fix) { return !graph_.HasVariable(fix.first); }),
                        absolute_fixes_.end());
  orientation_fixes_.erase(std::remove_if(orientation_fixes_.begin(), orientation_fixes_.end(),
                                          [this](const OrientationFix& fix) { return !graph_.HasVariable(fix.pose); }),
                           orientation_fixes_.end());
}

void ProblemBuilder::AlignToAbsoluteFixes() {
  if (impl_->imu) {
    AlignImuMasterToFixes();
    return;
  }
  if (absolute_fixes_.size() < 2) return;
  // Centroids of the dead-reckoned positions and of the fixes.
  Eigen::Vector3d cp = Eigen::Vector3d::Zero(), cz = Eigen::Vector3d::Zero();
  for (const auto& [id, z] : absolute_fixes_) {
    cp += graph_.variable(id).value.head<3>();
    cz += z;
  }
  cp /= static_cast<double>(absolute_fixes_.size());
  cz /= static_cast<double>(absolute_fixes_.size());
  // Best yaw (2-D Procrustes) when the fixes span at least a metre.
  double dot = 0.0, cross = 0.0, span = 0.0;
  for (const auto& [id, z] : absolute_fixes_) {
    const Eigen::Vector2d a = (graph_.variable(id).value.head<3>() - cp).head<2>();
    const Eigen::Vector2d b = (z - cz).head<2>();
    dot += a.dot(b);
    cross += a.x() * b.y() - a.y() * b.x();
    span = std::max(span, b.norm());
  }
  double yaw = span >= 1.0 ? std::atan2(cross, dot) : 0.0;
  // Measured orientations, when there are any, fix the rotation whatever the span: the body's yaw they imply,
  // q_world_body = z_q q_body_sensor^-1, less the dead-reckoned yaw, averaged on the circle.
  double sin_sum = 0.0, cos_sum = 0.0;
  const auto yaw_of = [](const Eigen::Quaterniond& q) {
    const Eigen::Vector3d x = q * Eigen::Vector3d::UnitX();
    return std::atan2(x.y(), x.x());
  };
  for (const OrientationFix& fix : orientation_fixes_) {
    const Eigen::VectorXd& m = graph_.variable(fix.misalignment).value;
    const Eigen::Quaterniond q_body_sensor(m[0], m[1], m[2], m[3]);
    const Eigen::Quaterniond q_world_body = fix.q_world_sensor * q_body_sensor.normalized().conjugate();
    const double d = yaw_of(q_world_body) - yaw_of(PoseFromArray(graph_.variable(fix.pose).value.data()).q_world_body);
    sin_sum += std::sin(d);
    cos_sum += std::cos(d);
  }
  if (std::hypot(sin_sum, cos_sum) > 0.0) yaw = std::atan2(sin_sum, cos_sum);
  const Eigen::Quaterniond q_yaw(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
  for (const PoseNode& node : poses_) {
    Eigen::VectorXd& x = graph_.mutable_variable(node.id).value;
    Pose<double> p = PoseFromArray(x.data());
    p.p_world_body = q_yaw * (p.p_world_body - cp) + cz;
    p.q_world_body = (q_yaw * p.q_world_body).normalized();
    PoseToArray(p, x.data());
  }
}

namespace {

// Row of the sample of `stream` nearest to t (stream.t is strictly increasing and not empty).
std::size_t NearestRow(const recording::Stream& stream, Time t) {
  const auto it = std::lower_bound(stream.t.begin(), stream.t.end(), t);
  if (it == stream.t.begin()) return 0;
  if (it == stream.t.end()) return stream.t.size() - 1;
  const std::size_t i = static_cast<std::size_t>(it - stream.t.begin());
  return SecondsBetween(t, *it) < SecondsBetween(stream.t[i - 1], t) ? i : i - 1;
}

// Half the span of the poses whose motion each pair of AlignImuToMotion compares with the IMU's readings. Over one
// master interval the dead-reckoned acceleration is the encoders' quantization and the wheels' slip at reversals
// (an omni robot's square-wave drive: tens of m/s^2 against the IMU's few, in no fixed direction), and it dominates
// the fit; over 0.2 s either side both average out, and the body turns little enough (0.3 rad at 1.5 rad/s) that
// its rotation within the span leaves the direction of the mean unbiased.
constexpr double kAlignmentHalfSpan_s = 0.2;

// Weighted mean of the rows of `stream` (columns [column, column + 3)) with t_a < t < t_c: weight 1 with `tent`
// false, else the kernel of a second difference over poses at t_a, t_b, t_c (rising linearly from t_a to t_b,
// falling to t_c), whose mean acceleration it is. nullopt when no row lies there.
std::optional<Eigen::Vector3d> MeanReading(const recording::Stream& stream, int column, Time t_a, Time t_b, Time t_c,
                                           bool tent) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double weight = 0.0;
  for (auto it = std::upper_bound(stream.t.begin(), stream.t.end(), t_a); it != stream.t.end() && *it < t_c; ++it) {
    const double w = !tent ? 1.0
                     : *it <= t_b ? SecondsBetween(t_a, *it) / SecondsBetween(t_a, t_b)
                                  : SecondsBetween(*it, t_c) / SecondsBetween(t_b, t_c);
    sum += w * stream.values.row(it - stream.t.begin()).segment<3>(column).transpose();
    weight += w;
  }
  if (weight <= 0.0) return std::nullopt;
  return sum / weight;
}

}  // namespace

// The dead-reckoned poses know the body's motion in the plane: from three poses kAlignmentHalfSpan_s apart, the
// body-frame mean angular velocity omega^(O) [rad/s] and specific force f^(O) = R^T (a + g e_z) [m/s^2] (eqs. 13-14
// without lever arm; the poses are level, so hills show up as unexplained gravity components, averaging out over a
// drive). The IMU reads the same vectors in
// its own frame: omega^(S) = R_OS^T omega^(O), f^(S) = R_OS^T f^(O). Wahba's problem, max over R of
// sum_i w_i u_i^(O) . R u_i^(S), is solved by the SVD of B = sum_i w_i u_i^(O) u_i^(S)T: R = U diag(1, 1, d) V^T.
// Gravity fixes the body's z axis in the IMU frame; forward acceleration and the centripetal acceleration of turns
// both ways fix the rotation about it. Each pair is weighted by the inverse of its reading noise variance.
std::optional<Eigen::Quaterniond> ProblemBuilder::AlignImuToMotion() {
  Impl& im = *impl_;
  if (im.imu) return std::nullopt;  // the poses come from the IMU itself
  const StreamBinding* gyro = nullptr;
  const StreamBinding* accel = nullptr;
  for (const StreamBinding& s : im.streams) {
    if (s.config.model == "gyroscope" && gyro == nullptr) gyro = &s;
    if (s.config.model == "accelerometer" && accel == nullptr) accel = &s;
  }
  if (gyro == nullptr || accel == nullptr || gyro->slot_parameters[0] != accel->slot_parameters[0]) return std::nullopt;
  // An empty stream (read with a warning) has no sample to align with.
  if (gyro->primary->t.empty() || accel->primary->t.empty()) return std::nullopt;
  const std::string& name = gyro->slot_parameters[0];
  const auto config = im.parameter_config.find(name);
  if (config == im.parameter_config.end() || !config->second.free || IsTimeVarying(name)) return std::nullopt;
  if (poses_.size() < 3) return std::nullopt;

  const double gyro_weight = 1.0 / gyro->noise_covariance(0, 0);
  const double accel_weight = 1.0 / accel->noise_covariance(0, 0);
  const Eigen::Vector3d g_world(0.0, 0.0, kStandardGravity);
  // Pairs of body-frame vectors at each pose b with poses a and c about kAlignmentHalfSpan_s before and after it: the
  // poses' mean rate and (second difference) mean acceleration over [t_a, t_c], the IMU's readings averaged with the
  // same kernels; the readings nearest to b where the master's poses are sparser than the IMU's span.
  std::vector<Eigen::Vector3d> omega_body, omega_imu, f_body, f_imu;
  std::size_t i_a = 0, i_c = 0;
  for (std::size_t k = 1; k + 1 < poses_.size(); ++k) {
    const Time t_b = poses_[k].t;
    while (i_a + 1 < k && SecondsBetween(poses_[i_a + 1].t, t_b) >= kAlignmentHalfSpan_s) ++i_a;
    i_c = std::max(i_c, k + 1);
    while (i_c + 1 < poses_.size() && SecondsBetween(t_b, poses_[i_c].t) < kAlignmentHalfSpan_s) ++i_c;
    const Pose<double> a = PoseFromArray(graph_.variable(poses_[i_a].id).value.data());
    const Pose<double> b = PoseFromArray(graph_.variable(poses_[k].id).value.data());
    const Pose<double> c = PoseFromArray(graph_.variable(poses_[i_c].id).value.data());
    const Time t_a = poses_[i_a].t, t_c = poses_[i_c].t;
    const double dt_ab = SecondsBetween(t_a, t_b), dt_bc = SecondsBetween(t_b, t_c);
    const Eigen::Vector3d accel_world =
        2.0 * ((c.p_world_body - b.p_world_body) / dt_bc - (b.p_world_body - a.p_world_body) / dt_ab) / (dt_ab + dt_bc);
    f_body.push_back(b.q_world_body.conjugate() * (accel_world + g_world));
    omega_body.push_back(QuaternionLog<double>(a.q_world_body.conjugate() * c.q_world_body) / (dt_ab + dt_bc));
    const auto nearest = [&](const StreamBinding& s) -> Eigen::Vector3d {
      return s.primary->values.row(NearestRow(*s.primary, t_b)).segment<3>(s.column).transpose();
    };
    omega_imu.push_back(MeanReading(*gyro->primary, gyro->column, t_a, t_b, t_c, false).value_or(nearest(*gyro)));
    f_imu.push_back(MeanReading(*accel->primary, accel->column, t_a, t_b, t_c, true).value_or(nearest(*accel)));
  }
  // A rotation keeps a vector's length: a pair whose lengths disagree far beyond the spread of the others holds an
  // outlier (a master reading off by a few ticks puts a spike of tens of m/s^2 into the dead-reckoned acceleration
  // at its pose) and would turn the fit towards itself. Left out.
  const std::vector<bool> gyro_kept = ConsistentLengths(omega_body, omega_imu);
  const std::vector<bool> accel_kept = ConsistentLengths(f_body, f_imu);
  Eigen::Matrix3d B = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d horizontal = Eigen::Matrix3d::Zero();  // spread of the body-frame specific force off its mean axis
  double samples = 0.0;
  for (std::size_t i = 0; i < f_body.size(); ++i) {
    if (gyro_kept[i]) B += gyro_weight * omega_body[i] * omega_imu[i].transpose();
    if (!accel_kept[i]) continue;
    B += accel_weight * f_body[i] * f_imu[i].transpose();
    const Eigen::Vector2d f_xy = f_body[i].head<2>();
    horizontal.topLeftCorner<2, 2>() += f_xy * f_xy.transpose();
    samples += 1.0;
  }
  if (samples < 1.0) return std::nullopt;
  // Two axes are needed: gravity, and some horizontal acceleration (forward or sideways) in the body frame.
  if (horizontal.trace() / samples < 0.05 * 0.05) return std::nullopt;  // under 0.05 m/s^2 rms
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(B, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  const Eigen::Quaterniond q_body_imu(svd.matrixU() * D * svd.matrixV().transpose());
  Eigen::VectorXd& value = graph_.mutable_variable(parameters_.at(name)).value;
  value << q_body_imu.w(), q_body_imu.x(), q_body_imu.y(), q_body_imu.z();
  return q_body_imu.normalized();
}

}  // namespace roamlab::estimator
