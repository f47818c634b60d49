#include "eval/evaluate.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>

#include <GeographicLib/LocalCartesian.hpp>

#include "common/json.h"
#include "eval/visual_odometry.h"
#include "recording/truth.h"
#include "recording/wheel_kinematics.h"

namespace roamlab::eval {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string Join(const std::string& dir, const std::string& name) { return (fs::path(dir) / name).string(); }

bool IsFile(const std::string& path) {
  std::error_code ec;
  return fs::is_regular_file(path, ec);
}

bool IsAbsoluteSensor(recording::StreamType type) {
  return type == recording::StreamType::kGps || type == recording::StreamType::kPosition ||
         type == recording::StreamType::kPose;
}

// The last component of a directory path, trailing separators ignored.
std::string DirectoryName(const std::string& dir) {
  fs::path p = fs::path(dir).lexically_normal();
  if (p.filename().empty()) p = p.parent_path();
  const std::string name = p.filename().string();
  return name.empty() || name == "." ? dir : name;
}

json StatisticsJson(const ErrorStatistics& s) {
  return {{"rmse", Number(s.rmse)}, {"mean", Number(s.mean)}, {"median", Number(s.median)}, {"max", Number(s.max)}};
}

json RpeJson(const RelativePoseError& rpe) {
  return {{"pairs", rpe.translation_m.size()},
          {"trans_m", StatisticsJson(rpe.translation)},
          {"rot_deg", StatisticsJson(rpe.rotation)}};
}

// Index of each matched estimate pose in the covariance rows with the same stamp (-1 when there is none).
std::vector<long> MatchCovariances(const std::vector<Time>& t, const std::vector<StampedCovariance>& rows) {
  std::vector<long> index(t.size(), -1);
  std::size_t r = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    while (r < rows.size() && rows[r].t < t[i]) ++r;
    if (r < rows.size() && rows[r].t == t[i]) index[i] = static_cast<long>(r);
  }
  return index;
}

// Reads one optional input: absent is fine, present but broken is an error.
template <typename T, typename Reader>
Status ReadOptional(const std::string& path, Reader reader, std::optional<T>* out) {
  if (!IsFile(path)) return Status::Ok();
  Result<T> result = reader(path);
  if (!result.ok()) return result.status();
  *out = std::move(result).value();
  return Status::Ok();
}

}  // namespace

std::string EvaluateOptions::Validate() const {
  if (estimate_dir.empty()) return "the estimate directory is not set";
  if (recording_dir.empty()) return "the recording directory is not set";
  if (!std::isfinite(max_time_difference_s) || max_time_difference_s < 0.0)
    return "max_time_difference_s must be finite and >= 0";
  if (!std::isfinite(rpe_delta_s) || rpe_delta_s <= 0.0) return "rpe_delta_s must be finite and > 0";
  if (!std::isfinite(rpe_distance_m) || rpe_distance_m <= 0.0) return "rpe_distance_m must be finite and > 0";
  if (!std::isfinite(nees_t0_s) || nees_t0_s < 0.0) return "nees_t0_s must be finite and >= 0";
  return "";
}

AlignmentKind DefaultAlignment(const recording::Recording& recording) {
  for (const recording::Stream& stream : recording.streams)
    if (IsAbsoluteSensor(stream.info.type)) return AlignmentKind::kNone;
  return AlignmentKind::kSe3;
}

std::vector<PositionFixes> AbsoluteFixes(const recording::Recording& recording) {
  std::vector<PositionFixes> fixes;
  for (const recording::Stream& stream : recording.streams) {
    if (!IsAbsoluteSensor(stream.info.type) || stream.values.rows() == 0) continue;
    PositionFixes f;
    f.name = stream.info.name;
    f.t = stream.t;
    if (stream.info.type == recording::StreamType::kGps) {
      // latitude, longitude [deg], altitude [m] -> ENU at the origin (the reader guarantees an origin with gps).
      const recording::GeodeticOrigin origin = recording.origin.value_or(recording::GeodeticOrigin{});
      const GeographicLib::LocalCartesian enu(origin.latitude_deg, origin.longitude_deg, origin.altitude_m);
      f.label = "GPS fixes (" + stream.info.name + ")";
      for (Eigen::Index i = 0; i < stream.values.rows(); ++i) {
        Eigen::Vector3d p;
        enu.Forward(stream.values(i, 0), stream.values(i, 1), stream.values(i, 2), p.x(), p.y(), p.z());
        f.p_world.push_back(p);
      }
    } else {
      // position and pose streams start with x y z in W.
      f.label = "position fixes (" + stream.info.name + ")";
      for (Eigen::Index i = 0; i < stream.values.rows(); ++i)
        f.p_world.emplace_back(stream.values(i, 0), stream.values(i, 1), stream.values(i, 2));
    }
    fixes.push_back(std::move(f));
  }
  return fixes;
}

namespace {

// What an evaluation reads: the recording with its ground truth, the estimate's trajectory, and the optional
// covariance.csv, calibration.json and truth.yaml.
struct Inputs {
  recording::Recording recording;
  Trajectory estimate;
  std::optional<std::vector<StampedCovariance>> covariances;
  std::optional<std::map<std::string, ParameterEstimate>> calibration;
  std::optional<recording::Truth> true_values;
  std::string truth_path, trajectory_path, covariance_path, calibration_path;
  const Trajectory& truth() const { return *recording.ground_truth; }
};

Result<Inputs> ReadInputs(const EvaluateOptions& options) {
  Inputs in;
  // Recording and its ground truth.
  recording::ReadOptions read;
  read.load_ground_truth = true;
  Result<recording::Recording> rec = recording::ReadRecording(options.recording_dir, read);
  if (!rec.ok()) return rec.status();
  in.recording = std::move(rec).value();
  in.truth_path = Join(options.recording_dir, "ground_truth.tum");
  if (!in.recording.ground_truth)
    return Status::Error(in.truth_path + ": missing; evaluation needs the ground-truth trajectory");
  if (in.truth().empty()) return Status::Error(in.truth_path + ": no poses");

  // The estimate: trajectory (required), covariance and calibration (optional).
  in.trajectory_path = Join(options.estimate_dir, "trajectory.tum");
  if (!IsFile(in.trajectory_path))
    return Status::Error(in.trajectory_path + ": missing; the estimate needs a trajectory");
  Result<Trajectory> estimate = ReadTum(in.trajectory_path);
  if (!estimate.ok()) return estimate.status();
  in.estimate = std::move(estimate).value();
  if (in.estimate.empty()) return Status::Error(in.trajectory_path + ": no poses");
  in.covariance_path = Join(options.estimate_dir, "covariance.csv");
  if (Status s = ReadOptional(in.covariance_path, ReadPositionCovariances, &in.covariances); !s.ok()) return s;
  in.calibration_path = Join(options.estimate_dir, "calibration.json");
  if (Status s = ReadOptional(in.calibration_path, ReadCalibrationEstimates, &in.calibration); !s.ok()) return s;
  if (in.calibration && IsFile(Join(options.recording_dir, "truth.yaml"))) {
    Result<recording::Truth> t = recording::ReadTruth(options.recording_dir);
    if (!t.ok()) return t.status();
    in.true_values = std::move(t).value();
  }
  return in;
}

// The estimate's poses matched to the truth by time; an error when none matches.
Result<MatchedTrajectories> Associate(const Inputs& in, const EvaluateOptions& options, json* m) {
  AssociationOptions association_options;
  association_options.max_time_difference_s = options.max_time_difference_s;
  const Association association = AssociateByTime(in.estimate, in.truth(), association_options);
  if (association.matched() == 0) {
    char tolerance[32];
    std::snprintf(tolerance, sizeof tolerance, "%g", options.max_time_difference_s);
    return Status::Error(in.trajectory_path + ": no pose within " + tolerance + " s of a pose of " + in.truth_path);
  }
  (*m)["association"] = {{"estimate_poses", association.estimate_size},
                         {"reference_poses", association.reference_size},
                         {"matched", association.matched()},
                         {"tolerance_s", options.max_time_difference_s},
                         {"max_time_difference_s", association.max_time_difference_s}};
  return SelectMatched(in.estimate, in.truth(), association);
}

// Why the alignment is what it is.
std::string AlignmentReason(const EvaluateOptions& options, AlignmentKind alignment) {
  if (options.alignment) return "requested";
  if (alignment == AlignmentKind::kNone)
    return "the recording has an absolute sensor: the estimate shares its world frame";
  return "no absolute sensor in the recording: the estimate's world frame is its own";
}

// Alignment and ATE, then RPE by step and by distance (independent of the alignment). Returns the ATE; `rpe_step`
// and `step` receive the RPE by step and its pose step.
AbsoluteTrajectoryError Accuracy(const Inputs& in, const MatchedTrajectories& matched, const EvaluateOptions& options,
                                 Evaluation* ev, RelativePoseError* rpe_step, std::size_t* step) {
  ev->alignment = options.alignment.value_or(DefaultAlignment(in.recording));
  const AbsoluteTrajectoryError ate = ComputeAte(matched.estimate, matched.reference, ev->alignment);
  *step = StepForDuration(matched.estimate, options.rpe_delta_s);
  *rpe_step = RpeByStep(matched.estimate, matched.reference, *step);
  const RelativePoseError rpe_distance = RpeByDistance(matched.estimate, matched.reference, options.rpe_distance_m);

  json& m = ev->metrics;
  const Eigen::Quaterniond& q = ate.alignment.q_ref_est;
  m["alignment"] = {
      {"kind", AlignmentKindName(ev->alignment)},
      {"reason", AlignmentReason(options, ev->alignment)},
      {"q_ref_est_wxyz", {q.w(), q.x(), q.y(), q.z()}},
      {"p_ref_est_m", {ate.alignment.p_ref_est.x(), ate.alignment.p_ref_est.y(), ate.alignment.p_ref_est.z()}}};
  m["ate_m"] = Number(ate.statistics.rmse);
  m["ate"] = {{"poses", ate.statistics.count},
              {"rmse_m", Number(ate.statistics.rmse)},
              {"mean_m", Number(ate.statistics.mean)},
              {"median_m", Number(ate.statistics.median)},
              {"max_m", Number(ate.statistics.max)}};
  m["rpe_trans_m"] = Number(rpe_step->translation.rmse);
  m["rpe_rot_deg"] = Number(rpe_step->rotation.rmse);
  m["rpe"] = RpeJson(*rpe_step);
  m["rpe"]["delta_poses"] = *step;
  m["rpe"]["delta_s"] = options.rpe_delta_s;
  m["rpe_distance"] = RpeJson(rpe_distance);
  m["rpe_distance"]["distance_m"] = options.rpe_distance_m;
  return ate;
}

// Velocities of wheeled robots: the fused estimate and the encoders alone against the truth (seed Fig. 6).
void Velocities(const Inputs& in, const MatchedTrajectories& matched, const RelativePoseError& rpe_step,
                std::size_t step, const EvaluateOptions& options, Evaluation* ev) {
  if (!recording::IsWheeledPlatform(in.recording.platform.kind)) return;
  Result<EncoderOdometry> encoders = EncoderOnlyOdometry(in.recording);
  if (!encoders.ok()) return;
  const Trajectory& truth = in.truth();
  AssociationOptions association_options;
  association_options.max_time_difference_s = options.max_time_difference_s;
  Evaluation::Velocity v;
  v.fused = CompareVelocities(TrajectoryVelocities(in.estimate), truth, options.max_time_difference_s);
  v.encoders_only = CompareVelocities(encoders.value().twists, truth, options.max_time_difference_s);
  const Association encoder_association = AssociateByTime(encoders.value().dead_reckoning, truth, association_options);
  const MatchedTrajectories encoder_matched =
      SelectMatched(encoders.value().dead_reckoning, truth, encoder_association);
  const RelativePoseError rpe_encoders = RpeByStep(encoder_matched.estimate, encoder_matched.reference,
                                                   StepForDuration(encoder_matched.estimate, options.rpe_delta_s));
  const auto series = [&truth](const RelativePoseError& rpe, const Trajectory& poses, std::vector<double>* t,
                               std::vector<double>* rot) {
    for (std::size_t n = 0; n < rpe.first.size(); ++n) {
      t->push_back(SecondsBetween(truth.front().t, poses[rpe.first[n]].t));
      rot->push_back(rpe.rotation_deg[n]);
    }
  };
  series(rpe_step, matched.estimate, &v.rpe_t_fused_s, &v.rpe_rot_fused_deg);
  series(rpe_encoders, encoder_matched.estimate, &v.rpe_t_encoders_s, &v.rpe_rot_encoders_deg);
  ev->metrics["velocity"] = {{"fused", VelocityJson(v.fused, rpe_step.rotation.rmse)},
                             {"encoders_only", VelocityJson(v.encoders_only, rpe_encoders.rotation.rmse)},
                             {"rpe_delta_poses", step}};
  ev->velocity = std::move(v);
}

// Visual odometry streams against the truth, independently of the estimate (per-pair errors).
void VisualOdometry(const Inputs& in, json* m) {
  for (const recording::Stream& stream : in.recording.streams) {
    if (stream.info.type != recording::StreamType::kVisualOdometry) continue;
    if (const auto vo = CompareVisualOdometry(stream, in.truth()))
      (*m)["visual_odometry"][stream.info.name] = VisualOdometryJson(*vo);
  }
}

// NEES of each matched pose that has a covariance row, in the aligned frame.
Status Consistency(const Inputs& in, const Eigen::Quaterniond& q_ref_est, const EvaluateOptions& options,
                   Evaluation* ev) {
  if (!in.covariances) return Status::Ok();
  const std::vector<long> row = MatchCovariances(ev->matched_t, *in.covariances);
  const Eigen::Matrix3d r = q_ref_est.toRotationMatrix();
  std::vector<Time> nees_t;
  std::vector<double> nees_values;
  std::size_t without_row = 0;
  std::size_t not_positive_definite = 0;
  for (std::size_t i = 0; i < ev->matched_t.size(); ++i) {
    if (row[i] < 0) {
      ++without_row;
      ev->sigma_world.push_back(Eigen::Vector3d::Constant(kNaN));
      continue;
    }
    const Eigen::Matrix3d sigma = r * (*in.covariances)[row[i]].covariance_world * r.transpose();
    ev->sigma_world.push_back(sigma.diagonal().cwiseMax(0.0).cwiseSqrt());
    // eq. 16 with the error O - O_hat; its sign does not matter in the quadratic form.
    const double nees = PositionNees(ev->error_world[i], sigma);
    if (std::isnan(nees)) {
      ++not_positive_definite;
      continue;
    }
    nees_t.push_back(ev->matched_t[i]);
    nees_values.push_back(nees);
  }
  if (nees_values.empty())
    return Status::Error(in.covariance_path + ": no usable covariance at the stamps of the matched poses of " +
                         in.trajectory_path);
  ev->nees = AggregateNees(nees_t, {nees_values}, 3, options.nees_t0_s);
  double sum = 0.0;
  for (double v : nees_values) sum += v;
  json& m = ev->metrics;
  m["nees_mean"] = Number(sum / static_cast<double>(nees_values.size()));
  m["nees"] = {{"poses", nees_values.size()},
               {"without_covariance", without_row},
               {"not_positive_definite", not_positive_definite},
               {"dof", 3},
               {"band_single_run", {ev->nees->band.lo, ev->nees->band.hi}},
               {"t0_s", options.nees_t0_s},
               {"fraction_in_band", Number(ev->nees->fraction_in_band)}};
  return Status::Ok();
}

// The parameter table: calibration.json against truth.yaml.
Status Parameters(const Inputs& in, json* m) {
  if (!in.calibration) return Status::Ok();
  std::vector<std::string> without_truth;
  const std::map<std::string, std::vector<double>> none;
  Result<std::vector<ParameterComparison>> rows =
      CompareParameters(in.true_values ? in.true_values->calibration : none, *in.calibration, &without_truth);
  if (!rows.ok()) return Status::Error(in.calibration_path + ": " + rows.status().message());
  (*m)["parameters"] = ParameterTableJson(rows.value());
  (*m)["parameters_without_truth"] = without_truth;
  return Status::Ok();
}

}  // namespace

Result<Evaluation> Evaluate(const EvaluateOptions& options) {
  if (const std::string problem = options.Validate(); !problem.empty()) return Status::Error(problem);
  Result<Inputs> read = ReadInputs(options);
  if (!read.ok()) return read.status();
  const Inputs& in = read.value();

  Evaluation ev;
  json& m = ev.metrics;
  m["estimate"] = options.estimate_dir;
  m["recording"] = options.recording_dir;
  Result<MatchedTrajectories> matched = Associate(in, options, &m);
  if (!matched.ok()) return matched.status();
  RelativePoseError rpe_step;
  std::size_t step = 0;
  const AbsoluteTrajectoryError ate = Accuracy(in, matched.value(), options, &ev, &rpe_step, &step);
  Velocities(in, matched.value(), rpe_step, step, options, &ev);
  VisualOdometry(in, &m);

  // Figures' data: whole trajectories, matched errors.
  ev.t_origin = in.truth().front().t;
  ev.ground_truth = in.truth();
  ev.aligned_estimate = TransformTrajectory(ate.alignment, in.estimate);
  for (const StampedPose& pose : matched.value().estimate) ev.matched_t.push_back(pose.t);
  ev.error_world = ate.error_world;
  ev.fixes = AbsoluteFixes(in.recording);
  ev.estimate_label = "estimate (" + DirectoryName(options.estimate_dir) + ")";

  if (Status s = Consistency(in, ate.alignment.q_ref_est, options, &ev); !s.ok()) return s;
  if (Status s = Parameters(in, &m); !s.ok()) return s;
  return ev;
}

Result<WrittenEvaluation> WriteEvaluation(const Evaluation& evaluation, const std::string& out_dir, bool plots) {
  WrittenEvaluation written;
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) return Status::Error(out_dir + ": cannot create the output directory: " + ec.message());

  // metrics.json first: it must exist whatever happens to the figures.
  written.metrics_path = Join(out_dir, "metrics.json");
  {
    std::ofstream out(written.metrics_path);
    if (!out) return Status::Error(written.metrics_path + ": cannot write");
    out << evaluation.metrics.dump(2) << "\n";
    out.close();
    if (!out) return Status::Error(written.metrics_path + ": write failed");
  }
  if (!plots) return written;

  // Figures: data and scripts, then gnuplot.
  std::vector<PlotFiles> figures;
  const std::string alignment = AlignmentKindName(evaluation.alignment);
  const std::string label = evaluation.estimate_label + ", alignment " + alignment;
  Result<PlotFiles> trajectory = WriteTrajectoryPlot(
      out_dir,
      "Trajectory, top view: ground truth, " + evaluation.estimate_label +
          (evaluation.fixes.empty() ? std::string() : " and absolute fixes"),
      evaluation.t_origin, evaluation.ground_truth, evaluation.aligned_estimate, label, evaluation.fixes);
  if (!trajectory.ok()) return trajectory.status();
  figures.push_back(trajectory.value());
  char ate[64];
  std::snprintf(
      ate, sizeof ate, "%.3f",
      evaluation.metrics.value("ate_m", json()).is_number() ? evaluation.metrics["ate_m"].get<double>() : kNaN);
  Result<PlotFiles> error = WritePositionErrorPlot(
      out_dir,
      "Position error, " + evaluation.estimate_label + " - ground truth (alignment " + alignment + ", ATE RMSE " + ate +
          " m)" + (evaluation.sigma_world.empty() ? ", no covariance" : ""),
      evaluation.t_origin, evaluation.matched_t, evaluation.error_world, evaluation.sigma_world);
  if (!error.ok()) return error.status();
  figures.push_back(error.value());
  if (evaluation.nees) {
    Result<PlotFiles> nees = WriteNeesPlot(
        out_dir, "Position NEES per pose (eq. 16), " + evaluation.estimate_label + ", single run", *evaluation.nees);
    if (!nees.ok()) return nees.status();
    figures.push_back(nees.value());
  }
  if (evaluation.velocity) {
    const Evaluation::Velocity& v = *evaluation.velocity;
    Result<PlotFiles> velocity = WriteVelocityPlot(
        out_dir, "Velocities: ground truth, encoders' forward kinematics, " + evaluation.estimate_label,
        {v.fused.t_s, v.fused.truth, v.fused.estimate, v.encoders_only.t_s, v.encoders_only.estimate, v.rpe_t_fused_s,
         v.rpe_rot_fused_deg, v.rpe_t_encoders_s, v.rpe_rot_encoders_deg});
    if (!velocity.ok()) return velocity.status();
    figures.push_back(velocity.value());
  }
  if (!GnuplotAvailable()) {
    written.note = "gnuplot not found: wrote the figures' data and scripts (*.gp) but no PNG";
    return written;
  }
  for (const PlotFiles& f : figures) {
    if (Status s = RunGnuplot(out_dir, f.script); !s.ok()) return s;
    written.images.push_back(Join(out_dir, f.image));
  }
  return written;
}

}  // namespace roamlab::eval
