#include "eval/evaluate.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>

#include <GeographicLib/LocalCartesian.hpp>

#include "common/atomic_file.h"
#include "common/check.h"
#include "common/json.h"
#include "eval/internal/evaluate_inputs.h"
#include "eval/report.h"
#include "eval/visual_odometry.h"
#include "recording/truth.h"
#include "recording/wheel_kinematics.h"

namespace roamlab::eval {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string Join(const std::string& dir, const std::string& name) { return (fs::path(dir) / name).string(); }

// {"rmse<suffix>", "mean<suffix>", "median<suffix>", "std<suffix>", "min<suffix>", "max<suffix>"}.
json StatisticsJson(const ErrorStatistics& s, const std::string& suffix = "") {
  return {{"rmse" + suffix, Number(s.rmse)}, {"mean" + suffix, Number(s.mean)}, {"median" + suffix, Number(s.median)},
          {"std" + suffix, Number(s.std)},   {"min" + suffix, Number(s.min)},   {"max" + suffix, Number(s.max)}};
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

}  // namespace

std::string EvaluateOptions::Validate() const {
  if (estimate_dir.empty()) return "the estimate is not set";
  if (recording_dir.empty() && reference_file.empty()) return "no reference: give a reference file or a recording";
  if (!reference_stream.empty() && recording_dir.empty()) return "a reference stream needs the recording";
  if (!reference_stream.empty() && !reference_file.empty())
    return "give a reference file or a reference stream, not both";
  if (!std::isfinite(time_offset_s)) return "time_offset_s must be finite";
  if (align_window_s && !(std::isfinite(align_window_s->first) && std::isfinite(align_window_s->second) &&
                          align_window_s->first <= align_window_s->second))
    return "the alignment window must be two finite times, start <= end";
  if (align_window_s && align_first_n > 0) return "align on the first N poses or on a window, not both";
  if (!std::isfinite(max_time_difference_s) || max_time_difference_s < 0.0)
    return "max_time_difference_s must be finite and >= 0";
  if (!std::isfinite(rpe_delta_s) || rpe_delta_s <= 0.0) return "rpe_delta_s must be finite and > 0";
  if (!std::isfinite(rpe_distance_m) || rpe_distance_m <= 0.0) return "rpe_distance_m must be finite and > 0";
  if (!std::isfinite(nees_t0_s) || nees_t0_s < 0.0) return "nees_t0_s must be finite and >= 0";
  return "";
}

AlignmentKind DefaultAlignment(const recording::Recording& recording) {
  for (const recording::Stream& stream : recording.streams)
    if (internal::IsAbsoluteSensor(stream.info.type)) return AlignmentKind::kNone;
  return AlignmentKind::kSe3;
}

std::vector<PositionFixes> AbsoluteFixes(const recording::Recording& recording) {
  std::vector<PositionFixes> fixes;
  for (const recording::Stream& stream : recording.streams) {
    if (!internal::IsAbsoluteSensor(stream.info.type) || stream.values.rows() == 0) continue;
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

using internal::Inputs;

// Pairs by index: pose i with pose i, as far as the shorter one goes.
Association AssociateByIndex(const Trajectory& estimate, const Trajectory& reference) {
  Association association;
  association.estimate_size = estimate.size();
  association.reference_size = reference.size();
  for (std::size_t i = 0; i < std::min(estimate.size(), reference.size()); ++i) {
    association.estimate_index.push_back(i);
    association.reference_index.push_back(i);
  }
  return association;
}

// The estimate's poses matched to the reference by time (by index when either has no time); an error when none match.
Result<MatchedTrajectories> Associate(const Inputs& in, const EvaluateOptions& options, json* m) {
  const bool by_index = !in.estimate_timed || !in.reference_timed;
  Association association;
  if (by_index) {
    association = AssociateByIndex(in.estimate, in.reference);
  } else {
    AssociationOptions association_options;
    association_options.max_time_difference_s = options.max_time_difference_s;
    association = AssociateByTime(in.estimate, in.reference, association_options);
  }
  if (association.matched() == 0) {
    char tolerance[96];
    std::snprintf(tolerance, sizeof tolerance, "%g s (time offset %g s)", options.max_time_difference_s,
                  options.time_offset_s);
    return Status::Error(in.trajectory_path + ": no pose within " + tolerance + " of a pose of " + in.reference_path +
                         " (estimate " + FormatSeconds(in.estimate.front().t) + " to " +
                         FormatSeconds(in.estimate.back().t) + " s, reference " +
                         FormatSeconds(in.reference.front().t) + " to " + FormatSeconds(in.reference.back().t) + " s)");
  }
  (*m)["association"] = {{"by", by_index ? "index" : "time"},
                         {"estimate_poses", association.estimate_size},
                         {"reference_poses", association.reference_size},
                         {"matched", association.matched()},
                         {"unmatched_estimate_poses", association.estimate_size - association.matched()},
                         {"tolerance_s", options.max_time_difference_s},
                         {"time_offset_s", options.time_offset_s},
                         {"max_time_difference_s", by_index ? json() : json(association.max_time_difference_s)}};
  return SelectMatched(in.estimate, in.reference, association);
}

AlignmentKind ChooseAlignment(const Inputs& in, const EvaluateOptions& options) {
  if (options.alignment) return *options.alignment;
  if (!in.recording) return AlignmentKind::kNone;
  return DefaultAlignment(*in.recording);
}

// Why the alignment is what it is.
std::string AlignmentReason(const Inputs& in, const EvaluateOptions& options, AlignmentKind alignment) {
  if (options.alignment) return "requested";
  if (!in.recording) return "plain files: no alignment unless requested";
  if (alignment == AlignmentKind::kNone)
    return "the recording has an absolute sensor: the estimate shares its world frame";
  return "no absolute sensor in the recording: the estimate's world frame is its own";
}

// The alignment on the matched poses selected by align_first_n or align_window_s; an error when none is selected.
Result<RigidTransform> Align(const MatchedTrajectories& matched, const Inputs& in, const EvaluateOptions& options,
                             AlignmentKind kind, std::size_t* used) {
  Trajectory estimate, reference;
  for (std::size_t i = 0; i < matched.estimate.size(); ++i) {
    if (options.align_first_n > 0 && i >= options.align_first_n) break;
    if (options.align_window_s) {
      const double t = SecondsBetween(in.reference.front().t, matched.reference[i].t);
      if (t < options.align_window_s->first || t > options.align_window_s->second) continue;
    }
    estimate.push_back(matched.estimate[i]);
    reference.push_back(matched.reference[i]);
  }
  *used = estimate.size();
  if (estimate.empty())
    return Status::Error(in.trajectory_path + ": no matched pose in the alignment window [" +
                         std::to_string(options.align_window_s->first) + ", " +
                         std::to_string(options.align_window_s->second) + "] s");
  return AlignTrajectories(estimate, reference, kind);
}

json AteJson(const AbsoluteTrajectoryError& ate, bool rotation, json* m) {
  (*m)["ate_m"] = Number(ate.statistics.rmse);
  (*m)["ate_rot_deg"] = rotation ? Number(ate.rotation.rmse) : json();
  (*m)["ate_rotation"] = rotation ? StatisticsJson(ate.rotation, "_deg") : json();
  (*m)["ate_axes"] = {{"x", StatisticsJson(ate.axis[0], "_m")},
                      {"y", StatisticsJson(ate.axis[1], "_m")},
                      {"z", StatisticsJson(ate.axis[2], "_m")},
                      {"horizontal", StatisticsJson(ate.horizontal, "_m")},
                      {"vertical", StatisticsJson(ate.vertical, "_m")}};
  json a = StatisticsJson(ate.statistics, "_m");
  a["poses"] = ate.statistics.count;
  return a;
}

// RPE by step and by distance on the aligned estimate (a rigid alignment does not change them, a scale does); null
// with a reason when the reference has no orientation.
void RelativeErrors(const Inputs& in, const MatchedTrajectories& matched, const Trajectory& aligned,
                    const EvaluateOptions& options, RelativePoseError* rpe_step, std::size_t* step, json* m) {
  *step = StepForDuration(matched.estimate, options.rpe_delta_s);
  if (!in.reference_has_orientation) {
    (*m)["rpe_trans_m"] = (*m)["rpe_rot_deg"] = json();
    (*m)["rpe"] = (*m)["rpe_distance"] = {{"skipped", "the reference has no orientation"}};
    return;
  }
  *rpe_step = RpeByStep(aligned, matched.reference, *step);
  const RelativePoseError rpe_distance = RpeByDistance(aligned, matched.reference, options.rpe_distance_m);
  (*m)["rpe_trans_m"] = Number(rpe_step->translation.rmse);
  (*m)["rpe_rot_deg"] = Number(rpe_step->rotation.rmse);
  (*m)["rpe"] = RpeJson(*rpe_step);
  (*m)["rpe"]["delta_poses"] = *step;
  (*m)["rpe"]["delta_s"] = options.rpe_delta_s;
  (*m)["rpe_distance"] = RpeJson(rpe_distance);
  (*m)["rpe_distance"]["distance_m"] = options.rpe_distance_m;
}

// Alignment and ATE, then RPE by step and by distance. Returns the ATE; `rpe_step` and `step` receive the RPE by step
// and its pose step.
Result<AbsoluteTrajectoryError> Accuracy(const Inputs& in, const MatchedTrajectories& matched,
                                         const EvaluateOptions& options, Evaluation* ev, RelativePoseError* rpe_step,
                                         std::size_t* step) {
  ev->alignment = ChooseAlignment(in, options);
  std::size_t used = 0;
  const Result<RigidTransform> alignment = Align(matched, in, options, ev->alignment, &used);
  if (!alignment.ok()) return alignment.status();
  const AbsoluteTrajectoryError ate = ComputeAte(matched.estimate, matched.reference, ev->alignment, alignment.value());
  json& m = ev->metrics;
  const Eigen::Quaterniond& q = ate.alignment.q_ref_est;
  m["alignment"] = {
      {"kind", AlignmentKindName(ev->alignment)},
      {"reason", AlignmentReason(in, options, ev->alignment)},
      {"q_ref_est_wxyz", {q.w(), q.x(), q.y(), q.z()}},
      {"p_ref_est_m", {ate.alignment.p_ref_est.x(), ate.alignment.p_ref_est.y(), ate.alignment.p_ref_est.z()}},
      {"scale", ate.alignment.scale},
      {"poses", used},
      {"first_n", options.align_first_n > 0 ? json(options.align_first_n) : json()},
      {"window_s",
       options.align_window_s ? json({options.align_window_s->first, options.align_window_s->second}) : json()}};
  m["ate"] = AteJson(ate, in.reference_has_orientation, &m);
  RelativeErrors(in, matched, ate.aligned_estimate, options, rpe_step, step, &m);
  return ate;
}

// Velocities of wheeled robots: the fused estimate and the encoders alone against the truth (seed Fig. 6).
void Velocities(const Inputs& in, const MatchedTrajectories& matched, const RelativePoseError& rpe_step,
                std::size_t step, const EvaluateOptions& options, Evaluation* ev) {
  if (!in.reference_is_ground_truth || !recording::IsWheeledPlatform(in.recording->platform.kind)) return;
  Result<EncoderOdometry> encoders = EncoderOnlyOdometry(*in.recording);
  if (!encoders.ok()) return;
  const Trajectory& truth = in.reference;
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
  if (!in.reference_is_ground_truth) return;
  for (const recording::Stream& stream : in.recording->streams) {
    if (stream.info.type != recording::StreamType::kVisualOdometry) continue;
    if (const auto vo = CompareVisualOdometry(stream, in.reference))
      (*m)["visual_odometry"][stream.info.name] = VisualOdometryJson(*vo);
  }
}

// NEES of each matched pose that has a covariance row, in the aligned frame (s R Sigma R^T s).
Status Consistency(const Inputs& in, const RigidTransform& alignment, const EvaluateOptions& options, Evaluation* ev) {
  if (!in.covariances) return Status::Ok();
  const std::vector<long> row = MatchCovariances(ev->matched_t, *in.covariances);
  const Eigen::Matrix3d r = alignment.scale * alignment.q_ref_est.toRotationMatrix();
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
  // Without an absolute sensor the position drifts unobserved: its covariance is relative to the first pose, and
  // the NEES against the truth grows without bound instead of testing consistency.
  if (in.recording && DefaultAlignment(*in.recording) != AlignmentKind::kNone)
    m["nees"]["warning"] = "the position is not observable from " + in.recording_dir +
                           "'s sensors (no gps, position or pose stream): the NEES does not test consistency";
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
  Result<Inputs> read = internal::ReadInputs(options);
  if (!read.ok()) return read.status();
  const Inputs& in = read.value();

  Evaluation ev;
  json& m = ev.metrics;
  m["estimate"] = options.estimate_dir;
  m["estimate_format"] = in.estimate_format;
  m["recording"] = options.recording_dir.empty() ? json() : json(options.recording_dir);
  m["reference"] = in.reference_json;
  Result<MatchedTrajectories> matched = Associate(in, options, &m);
  if (!matched.ok()) return matched.status();
  RelativePoseError rpe_step;
  std::size_t step = 0;
  const Result<AbsoluteTrajectoryError> accuracy = Accuracy(in, matched.value(), options, &ev, &rpe_step, &step);
  if (!accuracy.ok()) return accuracy.status();
  const AbsoluteTrajectoryError& ate = accuracy.value();
  Velocities(in, matched.value(), rpe_step, step, options, &ev);
  VisualOdometry(in, &m);

  // Figures' data: whole trajectories, matched errors; the reference stream is not drawn twice.
  ev.t_origin = in.reference.front().t;
  ev.reference = in.reference;
  ev.reference_label = in.reference_label;
  ev.reference_has_orientation = in.reference_has_orientation;
  ev.aligned_estimate = TransformTrajectory(ate.alignment, in.estimate);
  for (const StampedPose& pose : matched.value().estimate) ev.matched_t.push_back(pose.t);
  ev.error_world = ate.error_world;
  if (in.reference_has_orientation) ev.rotation_error_deg = ate.rotation_deg;
  if (in.recording)
    for (PositionFixes& f : AbsoluteFixes(*in.recording))
      if (f.name != in.reference_stream) ev.fixes.push_back(std::move(f));
  ev.estimate_name = in.estimate_name;
  ev.estimate_label = "estimate (" + in.estimate_name + ")";

  if (Status s = Consistency(in, ate.alignment, options, &ev); !s.ok()) return s;
  if (Status s = Parameters(in, &m); !s.ok()) return s;
  return ev;
}

namespace {

// OUT/metrics.json (the directory is created).
Status WriteMetrics(const json& metrics, const std::string& out_dir, WrittenEvaluation* written) {
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) return Status::Error(out_dir + ": cannot create the output directory: " + ec.message());
  written->metrics_path = Join(out_dir, "metrics.json");
  return WriteFileAtomic(written->metrics_path, metrics.dump(2) + "\n");
}

// The report's note when the figures were not asked for.
const char kPlotsOff[] = "Figures not drawn (plots off).";

// Runs gnuplot on each figure, or notes that it is missing.
Status DrawFigures(const std::string& out_dir, const std::vector<PlotFiles>& figures, WrittenEvaluation* written) {
  if (!GnuplotAvailable()) {
    written->note = "gnuplot not found: wrote the figures' data and scripts (*.gp) but no PNG";
    return Status::Ok();
  }
  for (const PlotFiles& f : figures) {
    if (Status s = RunGnuplot(out_dir, f.script); !s.ok()) return s;
    written->images.push_back(Join(out_dir, f.image));
  }
  return Status::Ok();
}

// One row of the comparison table.
json TableRow(const Evaluation& e) {
  const json& m = e.metrics;
  return {{"name", e.estimate_name},
          {"ate_m", m.value("ate_m", json())},
          {"ate_rot_deg", m.value("ate_rot_deg", json())},
          {"rpe_trans_m", m.value("rpe_trans_m", json())},
          {"rpe_rot_deg", m.value("rpe_rot_deg", json())},
          {"matched", m["association"]["matched"]}};
}

// The figures of one evaluation: data, scripts and, with gnuplot, the PNGs.
Status DrawEvaluationFigures(const Evaluation& evaluation, const std::string& out_dir, WrittenEvaluation* written) {
  // Figures: data and scripts, then gnuplot.
  std::vector<PlotFiles> figures;
  const std::string alignment = AlignmentKindName(evaluation.alignment);
  const std::string label = evaluation.estimate_label + ", alignment " + alignment;
  Result<PlotFiles> trajectory =
      WriteTrajectoryPlot(out_dir,
                          "Trajectory, top view: " + evaluation.reference_label + ", " + evaluation.estimate_label +
                              (evaluation.fixes.empty() ? std::string() : " and absolute fixes"),
                          evaluation.t_origin, {evaluation.reference_label, evaluation.reference},
                          {{label, evaluation.aligned_estimate}}, evaluation.fixes);
  if (!trajectory.ok()) return trajectory.status();
  figures.push_back(trajectory.value());
  char ate[64];
  std::snprintf(
      ate, sizeof ate, "%.3f",
      evaluation.metrics.value("ate_m", json()).is_number() ? evaluation.metrics["ate_m"].get<double>() : kNaN);
  Result<PlotFiles> error = WritePositionErrorPlot(
      out_dir,
      "Position error, " + evaluation.estimate_label + " - " + evaluation.reference_label + " (alignment " + alignment +
          ", ATE RMSE " + ate + " m)" + (evaluation.sigma_world.empty() ? ", no covariance" : ""),
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
  return DrawFigures(out_dir, figures, written);
}

// The overlaid figures of a comparison.
Status DrawComparisonFigures(const std::vector<Evaluation>& evaluations, const std::string& out_dir,
                             WrittenEvaluation* written) {
  const Evaluation& first = evaluations.front();
  std::vector<PlottedTrajectory> estimates;
  std::vector<ErrorSeries> series;
  for (const Evaluation& e : evaluations) {
    estimates.push_back({e.estimate_label + ", alignment " + AlignmentKindName(e.alignment), e.aligned_estimate});
    ErrorSeries s{e.estimate_label, e.matched_t, {}, e.rotation_error_deg};
    for (const Eigen::Vector3d& error : e.error_world) s.position_m.push_back(error.norm());
    series.push_back(std::move(s));
  }
  std::vector<PlotFiles> figures;
  Result<PlotFiles> trajectory = WriteTrajectoryPlot(
      out_dir,
      "Trajectory, top view: " + first.reference_label + " and " + std::to_string(evaluations.size()) + " estimates",
      first.t_origin, {first.reference_label, first.reference}, estimates, first.fixes);
  if (!trajectory.ok()) return trajectory.status();
  figures.push_back(trajectory.value());
  Result<PlotFiles> errors = WriteErrorOverTimePlot(
      out_dir, "Absolute error against " + first.reference_label + " after alignment", first.t_origin, series);
  if (!errors.ok()) return errors.status();
  figures.push_back(errors.value());
  return DrawFigures(out_dir, figures, written);
}

}  // namespace

Result<WrittenEvaluation> WriteEvaluation(const Evaluation& evaluation, const std::string& out_dir, bool plots) {
  WrittenEvaluation written;
  // metrics.json first: it must exist whatever happens to the figures.
  if (Status s = WriteMetrics(evaluation.metrics, out_dir, &written); !s.ok()) return s;
  if (plots) {
    if (Status s = DrawEvaluationFigures(evaluation, out_dir, &written); !s.ok()) return s;
  }
  written.report_path = Join(out_dir, "report.html");
  if (Status s = WriteEvaluationReport({evaluation.estimate_name, evaluation.metrics, written.images},
                                       plots ? written.note : kPlotsOff, written.report_path);
      !s.ok())
    return s;
  return written;
}

Result<WrittenEvaluation> WriteComparison(const std::vector<Evaluation>& evaluations, const std::string& out_dir,
                                          bool plots) {
  ROAMLAB_CHECK(!evaluations.empty(), "a comparison needs an evaluation");
  json m = {{"reference", evaluations.front().metrics["reference"]}, {"table", json::array()}};
  for (const Evaluation& e : evaluations) {
    ROAMLAB_CHECK(!m["estimates"].contains(e.estimate_name), "estimate names repeat: " << e.estimate_name);
    m["table"].push_back(TableRow(e));
    m["estimates"][e.estimate_name] = e.metrics;
  }
  WrittenEvaluation written;
  if (Status s = WriteMetrics(m, out_dir, &written); !s.ok()) return s;
  std::vector<ReportedEvaluation> reported;
  for (const Evaluation& e : evaluations) {
    const Result<WrittenEvaluation> one = WriteEvaluation(e, Join(out_dir, e.estimate_name), plots);
    if (!one.ok()) return one.status();
    if (!one.value().note.empty()) written.note = one.value().note;
    reported.push_back({e.estimate_name, e.metrics, one.value().images});
  }
  if (plots) {
    if (Status s = DrawComparisonFigures(evaluations, out_dir, &written); !s.ok()) return s;
  }
  written.report_path = Join(out_dir, "report.html");
  if (Status s = WriteComparisonReport(reported, written.images, plots ? written.note : kPlotsOff, written.report_path);
      !s.ok())
    return s;
  return written;
}

}  // namespace roamlab::eval
