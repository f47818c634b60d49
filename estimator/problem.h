// Builds the hyper-graph from a recording and an estimator configuration (seed 000, Section III-B).
//
// Each sample of the master stream creates a pose node; its odometric factor joins it to the next pose, and the next
// pose's initial guess is that factor's prediction (eq. 7) at the current parameter values. Every other measurement
// attaches to the pose(s) nearest its time stamp as soon as they exist: one pose (GPS, magnetometer, absolute pose),
// the pair of poses whose interval contains it (gyroscope, velocity sensors), or three poses centred on the nearest
// (accelerometer). Measurements may arrive out of order; one older than the oldest pose still in the graph is
// counted as too late, never silently dropped. Which poses a model's samples join, its error's dimension and its
// noise come from its definition in the error-model registry (model_registry.h); a user model's factors come from
// its bound model, the built-in models' from this builder.
//
// Relative motion (model relative_motion). A sample of a velocity stream stamped at t that stands for the mean
// velocity over [t_a, t_b] = [t - T/2, t + T/2] (the scan matcher between two scans, the visual odometry between two
// frames) attaches to the poses k_a and k_b nearest t_a and t_b (k_b > k_a), once a pose at or after t_b exists: the
// odometer's error (eqs. 5-8) with the velocity held over dt = t(k_b) - t(k_a). Between those poses the master stream
// still gives the shape of the motion; the sample constrains the displacement and rotation across the whole interval
// (a relative-pose constraint). With the master poses nearest the ends, the interval differs from [t_a, t_b] by up to
// half a master period at each end; holding the measured velocity over dt keeps the constraint exact for a constant
// velocity. A sample whose pose k_a has already left the window is too late (or outside, before the first pose).
//
// IMU master (a gyroscope stream as master; config.h PosesConfig). Poses sit on a grid from the IMU's first sample,
// 1 / poses.rate_hz apart (at every IMU sample without a rate), over the IMU's span. Each gyroscope sample attaches to
// the pose pair whose interval holds it and each accelerometer sample to the three poses centred on the nearest, as
// for any master; the other streams attach as usual. Initial guess: the first pose's orientation is gravity-aligned
// (the accelerometer's mean over the first second turned onto the world's up) with its yaw from the magnetometer's
// mean over that second (against options.field_world) when there is one, else zero; every later orientation
// integrates the gyroscope at the current bias, scale and misalignment, holding each sample's rate until the next.
// Positions extrapolate the last two poses' velocity (zero at the start). AlignToAbsoluteFixes then, with a GPS,
// places every pose at the fixes linearly interpolated in time and, without a magnetometer, turns the yaw to the GPS
// track (the body's x axis along the direction of travel). Without an absolute sensor every pose gets a weak position
// prior (poses.position_sigma_m) about the origin, and without a magnetometer either the first pose's rotation about
// its z axis is held by a tight prior (the yaw gauge).
//
// Parameters are variables named "<stream>.<slot>" unless the configuration maps a slot to another name (shared
// parameters, e.g. one IMU misalignment for gyroscope, accelerometer and magnetometer). A time-varying parameter
// (random walk or Gauss-Markov) has one instance per pose, joined by process factors; with process.interval_s, one
// instance per interval instead: a pose starts a new instance (stamped with its time) when it comes at least
// interval_s after the current instance's stamp, and otherwise shares the current one (PoseNode::instances then holds
// the same variable for consecutive poses). The process factor joining two instances spans their stamps' difference.
#pragma once

#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "common/time.h"
#include "estimator/config.h"
#include "estimator/graph.h"
#include "estimator/id_table.h"
#include "recording/recording.h"

namespace roamlab::estimator {

// One sample of one configured stream.
struct MeasurementRef {
  Time t;
  int stream = 0;  // index into ProblemBuilder::stream_names()
  int row = 0;     // row of the stream's primary source
};

struct PoseNode {
  Time t;
  VariableId id = -1;
  std::map<std::string, VariableId> instances;  // time-varying parameters at this pose (under a process.interval_s
                                                // shared by the consecutive poses of one interval)
};

struct StreamCounts {
  int attached = 0;
  int rejected = 0;  // switched off by the chi-square gate
  int too_late = 0;  // older than the oldest pose in the graph
  int outside = 0;   // no pose around its time stamp (before the first or after the last master sample)
  // What the input checks found in the stream's primary source (recording/stream_health.h):
  int duplicates = 0;  // rows identical to the one before, dropped by the recording reader
  int gaps = 0;        // gaps longer than recording::kGapPeriods periods (an outage, a clock jump)
  int frozen = 0;      // rows repeating the first row of a frozen run (a stuck sensor), left out of Measurements()
};

struct StreamBinding;  // a configured stream bound to its recording data (problem.cc)

class ProblemBuilder {
 public:
  // Validates the configuration against the recording: streams exist with the right types, parameter sizes match
  // their slots, names are consistent. Errors name the configuration file and the stream or parameter.
  static Result<std::unique_ptr<ProblemBuilder>> Create(const EstimatorConfig& config,
                                                        const recording::Recording& recording);
  ~ProblemBuilder();

  // Every sample of every configured stream, in time order (ties: master first, then stream order), but for the rows
  // of a frozen sensor (StreamCounts::frozen).
  std::vector<MeasurementRef> Measurements() const;

  // Adds one measurement; see the class comment.
  void Add(const MeasurementRef& measurement);
  // Counts every measurement still waiting as outside (call when the recording ends).
  void Finish();

  Graph& graph() { return graph_; }
  const Graph& graph() const { return graph_; }
  const std::deque<PoseNode>& poses() const { return poses_; }
  const std::vector<std::string>& stream_names() const { return stream_names_; }
  const std::map<std::string, StreamCounts>& counts() const { return counts_; }
  StreamCounts& mutable_counts(const std::string& stream) { return counts_[stream]; }

  // Constant parameters by name (time-varying ones live in PoseNode::instances).
  const std::map<std::string, VariableId>& parameters() const { return parameters_; }
  bool IsTimeVarying(const std::string& parameter) const;
  // Parameters that the configuration declares free.
  std::vector<std::string> FreeParameterNames() const;

  // Stream that produced a factor (by factor id); -1 for process and prior factors.
  int StreamOfFactor(FactorId id) const;
  // The same for every measurement factor added, by id.
  const IdTable<int>& factor_streams() const { return stream_of_factor_; }
  // Chi-square dimension of a stream's factors.
  int ResidualDim(const std::string& stream) const;
  // Whether the outlier gate tests and may reject or hold out the factors of stream index `stream`
  // (StreamConfig::gated; false for -1, the process and prior factors).
  bool StreamGated(int stream) const;

  // A factor of a cumulative wheel master stream (differential, tricycle, omni and mecanum drives), whose readings
  // are wheel angles summed since the start: the factor joining the poses of rows row_begin < row_end holds the mean
  // rates over that span, the difference of the two rows' readings. An outlier in one reading bends both factors
  // that share it, in opposite directions; a bridge over the rows around it (BridgeCumulativeRun) leaves it out.
  struct CumulativeSpan {
    int stream = 0;
    int row_begin = 0;
    int row_end = 0;
    bool bridge = false;    // made by BridgeCumulativeRun
    bool replaced = false;  // switched off for good, in favour of a bridge over it
  };
  // By factor id; entries whose factors have left the graph are dropped with their poses (PopOldestPose).
  const std::map<FactorId, CumulativeSpan>& cumulative_spans() const { return cumulative_spans_; }
  // Replaces consecutive spans of one stream (each ending at the row and pose where the next begins), as if the
  // readings of the rows inside had not been recorded: one active factor over the whole span (the run's noise and
  // loss) instead, the run's factors switched off and marked replaced. The stream's rejected count grows by the
  // run's active factors less one. Returns the bridge's id; nullopt (nothing changed) when the run does not chain.
  std::optional<FactorId> BridgeCumulativeRun(const std::vector<FactorId>& run);
  // The factor that BridgeCumulativeRun would add, not added (to test it first).
  std::optional<FactorEntry> CumulativeBridge(const std::vector<FactorId>& run) const;
  // Whether the reading of row `row` of cumulative stream `stream` is a spike, told from the readings alone: its
  // whitened squared distance from a quadratic in time through its neighbours exceeds `threshold(wheels)`, while the
  // neighbours kept fit within it. The neighbours: up to 5 rows either side (none after `last_row`), the fewest of them
  // left out (at most 4) for the rest to fit; each wheel's reading noise is the stream's wheel-rate noise times the
  // sample interval over sqrt(2). False where fewer than two neighbours either side remain.
  bool IsCumulativeSpike(int stream, int row, int last_row, const std::function<double(int)>& threshold) const;

  // Absolute position fixes (GPS, absolute pose) as (pose, measured position in W), for initial alignment.
  const std::vector<std::pair<VariableId, Eigen::Vector3d>>& absolute_fixes() const { return absolute_fixes_; }
  bool has_absolute_sensor() const { return has_absolute_sensor_; }

  // Removes the oldest pose's bookkeeping after the graph variable has been marginalized by the caller.
  void PopOldestPose();

  // Rigidly moves every pose (rotation about z and translation) to best fit the absolute fixes: the initial guess for a
  // dead-reckoned trajectory. The rotation: from the measured orientations when an absolute pose stream gives them
  // (the circular mean of the yaw differences), else from the positions when they span at least 1 m (2-D
  // Procrustes), else none.
  void AlignToAbsoluteFixes();

  // The initial guess of an IMU misalignment q_body_imu that is free and shared by a gyroscope and an accelerometer
  // stream, from the motion of the (dead-reckoned, aligned) poses: Wahba's problem on body-frame vectors paired with
  // the IMU's readings. Call after Finish() and AlignToAbsoluteFixes(). Writes the value into the parameter and
  // returns it; std::nullopt (nothing changed) when no such parameter exists or the motion does not excite two axes.
  std::optional<Eigen::Quaterniond> AlignImuToMotion();

 private:
  struct Impl;
  explicit ProblemBuilder(std::unique_ptr<Impl> impl);
  void AddMasterSample(const MeasurementRef& m);
  // The IMU master (problem_imu.cc; the class comment): integrates one gyroscope sample, creating the grid poses it
  // passes; false for a sample not after the last one (counted as too late).
  bool AddImuMasterSample(const MeasurementRef& m);
  void CreateImuPose(Time t);
  Eigen::Quaterniond InitialImuOrientation(Time t0) const;
  Eigen::Vector3d ImuBodyRate(const MeasurementRef& m) const;
  void AlignImuMasterToFixes();
  void AttachPending();
  // Attaches one measurement if its poses exist; returns false to keep it waiting.
  bool TryAttach(const MeasurementRef& m);
  // Where a sample of stream s (not relative_motion) attaches: at pose index *k (the first of its pair, the middle of
  // its triple), not yet (its poses do not exist), or nowhere (before the first pose or the first triple: counted as
  // outside).
  enum class Placement { kAttach, kWait, kOutside };
  Placement PlaceSample(const MeasurementRef& m, const StreamBinding& s, std::size_t* k);
  // TryAttach for a user model (model_registry.h) at pose index k (PlaceSample's).
  bool AttachUserSample(const MeasurementRef& m, std::size_t k);
  // TryAttach for relative_motion (the class comment).
  bool TryAttachInterval(const MeasurementRef& m);
  // The noise covariance of one sample: the configured one, plus the row's own when the stream is set to use it.
  static Eigen::MatrixXd SampleNoiseCovariance(const StreamBinding& s, const Eigen::RowVectorXd& row);
  VariableId CreatePose(Time t, const Eigen::VectorXd& value);
  // The variable of a parameter at pose index k (the instance, when time-varying).
  VariableId ParameterAt(const std::string& name, std::size_t k) const;
  // Index of the pose nearest to t.
  std::size_t NearestPose(Time t) const;
  std::unique_ptr<Impl> impl_;

  Graph graph_;
  std::deque<PoseNode> poses_;
  std::vector<std::string> stream_names_;
  std::map<std::string, StreamCounts> counts_;
  std::map<std::string, VariableId> parameters_;
  std::vector<std::pair<VariableId, Eigen::Vector3d>> absolute_fixes_;
  // Absolute orientation fixes (absolute pose): the pose, its misalignment q_body_sensor variable, the measured
  // q_world_sensor.
  struct OrientationFix {
    VariableId pose;
    VariableId misalignment;
    Eigen::Quaterniond q_world_sensor;
  };
  std::vector<OrientationFix> orientation_fixes_;
  bool has_absolute_sensor_ = false;
  bool popped_any_ = false;
  IdTable<int> stream_of_factor_;
  std::map<FactorId, CumulativeSpan> cumulative_spans_;
};

}  // namespace roamlab::estimator
