#include "experiment/odometry.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numeric>
#include <random>
#include <sstream>

#include "common/atomic_file.h"
#include "estimator/odometry/gaussian_process.h"
#include "estimator/odometry/parametric.h"
#include "estimator/odometry/robust_linear.h"
#include "estimator/odometry/training_data.h"
#include "estimator/odometry/trajectory.h"
#include "eval/plots.h"
#include "eval/top_view.h"
#include "recording/recording.h"

namespace roamlab::experiment {
namespace {

namespace fs = std::filesystem;
namespace odo = estimator::odometry;
using nlohmann::json;

Outcome Bad(const std::string& message) { return Outcome::BadInput(Status::Error(message)); }
Outcome Failed(const std::string& message) { return Outcome::Failed(Status::Error(message)); }

// The pairs `rows` of `data`.
odo::TrainingSet SelectPairs(const odo::TrainingSet& data, const std::vector<int>& rows) {
  odo::TrainingSet out;
  out.wheels = data.wheels;
  const auto n = static_cast<Eigen::Index>(rows.size());
  out.delta.resize(n, data.delta.cols());
  out.s.resize(n, 3);
  out.s_sigma.resize(n, 3);
  for (Eigen::Index k = 0; k < n; ++k) {
    out.delta.row(k) = data.delta.row(rows[static_cast<std::size_t>(k)]);
    out.s.row(k) = data.s.row(rows[static_cast<std::size_t>(k)]);
    out.s_sigma.row(k) = data.s_sigma.row(rows[static_cast<std::size_t>(k)]);
  }
  return out;
}

// Trains the model the options name on `all`.
Result<odo::OdometryModel> Train(const OdometryLearnOptions& args, const odo::TrainingSet& all,
                                 const recording::Platform& platform) {
  // Gross outliers (off eq. 9's robust linear surface) out, except for the robust linear model itself.
  odo::TrainingSet data = all;
  if (args.model != "linear" && args.outlier_threshold > 0.0) {
    Result<odo::HuberFit> fit = odo::FitHuberLinear(all.delta, all.s, all.s_sigma);
    if (!fit.ok()) return fit.status();
    data = SelectPairs(all, odo::InlierRows(fit.value(), all.delta, all.s, all.s_sigma, args.outlier_threshold));
    if (args.log) {
      std::ostringstream line;
      line << all.size() - data.size() << " of " << all.size() << " pairs beyond " << args.outlier_threshold
           << " robust sigmas dropped as outliers";
      args.log(line.str());
    }
  }
  odo::OdometryModel model;
  model.platform = platform.kind;
  model.wheels = data.wheels;
  model.interval_s = args.interval_s;
  model.training_pairs = data.size();
  if (args.model == "gp") {
    odo::GpOptions options;
    if (!odo::ParseGpMean(args.mean, &options.mean)) return Status::Error("--mean must be zero or linear");
    if (!odo::ParseGpKernel(args.kernel, &options.kernel)) {
      return Status::Error("--kernel must be rbf, linear or rbf+linear");
    }
    options.hyperparameter_subset = args.hyperparameter_subset;
    // At most max_pairs pairs (seeded, in their original order): O(n^2) memory and O(n^3) time.
    std::vector<int> rows(static_cast<std::size_t>(data.size()));
    std::iota(rows.begin(), rows.end(), 0);
    if (args.max_pairs > 0 && data.size() > args.max_pairs) {
      std::mt19937_64 rng(options.seed);
      std::shuffle(rows.begin(), rows.end(), rng);
      rows.resize(static_cast<std::size_t>(args.max_pairs));
      std::sort(rows.begin(), rows.end());
    }
    const odo::TrainingSet used = SelectPairs(data, rows);
    model.training_pairs = used.size();
    const Eigen::MatrixXd noise_var = used.s_sigma.array().square();
    Result<odo::GaussianProcess> gp = odo::GaussianProcess::Train(used.delta, used.s, noise_var, options);
    if (!gp.ok()) return gp.status();
    model.kind = odo::ModelKind::kGp;
    model.gp = std::move(gp).value();
  } else if (args.model == "linear") {
    Result<odo::HuberFit> fit = odo::FitHuberLinear(data.delta, data.s, data.s_sigma);
    if (!fit.ok()) return fit.status();
    model.kind = odo::ModelKind::kLinear;
    model.W = fit.value().W;
    model.huber_scale = fit.value().scale;
  } else if (args.model == "parametric") {
    model.kind = odo::ModelKind::kParametric;
    if (platform.kind == "differential_drive") {
      Result<odo::CensiCalibration> cal = odo::CalibrateDifferentialDrive(data);
      if (!cal.ok()) return cal.status();
      model.kinematics = cal.value().kinematics;
    } else {
      // No parametric calibration for this platform: its nominal kinematics (the seed's mecanum baseline).
      Result<odo::WheelKinematics> nominal = odo::NominalKinematics(platform, data.wheels);
      if (!nominal.ok()) return nominal.status();
      model.kinematics = nominal.value();
    }
  } else {
    return Status::Error("--model must be gp, linear or parametric");
  }
  return model;
}

// The training pairs of every recording (the estimator side: no ground truth); `platform` receives the recordings'.
Outcome ReadTrainingSet(const OdometryLearnOptions& options, odo::TrainingSet* data, recording::Platform* platform,
                        std::size_t* recordings) {
  odo::KeyTimeOptions key_options;
  key_options.interval_s = options.interval_s;
  key_options.encoder_stream = options.encoder_stream;
  key_options.sensor_stream = options.sensor_stream;
  std::vector<odo::KeySequence> sequences;
  for (const std::string& dir : options.recordings) {
    recording::ReadOptions read;
    read.load_ground_truth = false;
    Result<recording::Recording> rec = recording::ReadRecording(dir, read);
    if (!rec.ok()) return Outcome::BadInput(rec.status());
    if (sequences.empty()) *platform = rec.value().platform;
    if (rec.value().platform.kind != platform->kind)
      return Bad(dir + ": platform '" + rec.value().platform.kind + "' differs from '" + platform->kind + "'");
    Result<odo::KeySequence> seq = odo::CutAtKeyTimes(rec.value(), dir, key_options, true);
    if (!seq.ok()) return Outcome::BadInput(seq.status());
    sequences.push_back(std::move(seq).value());
  }
  Result<odo::TrainingSet> set = odo::MakeTrainingSet(sequences);
  if (!set.ok()) return Outcome::BadInput(set.status());
  *data = std::move(set).value();
  *recordings = sequences.size();
  return Outcome::Ok();
}

// One evaluated trajectory.
struct Evaluated {
  std::string label;
  std::vector<odo::Pose2> poses;
  std::vector<double> absolute, relative;                  // [m]
  std::vector<double> absolute_heading, relative_heading;  // [rad]
};

// One table row; `errors` holds the model's absolute and relative translation [m] and heading [rad] errors.
json Row(const std::string& model, const std::string& mean, const std::string& kernel,
         const std::array<const std::vector<double>*, 4>& errors) {
  constexpr double kDegree = 57.295779513082320877;
  return {{"model", model},
          {"mean", mean == "-" ? json(nullptr) : json(mean)},
          {"kernel", kernel == "-" ? json(nullptr) : json(kernel)},
          {"ate_m", odo::RootMeanSquare(*errors[0])},
          {"rpe_mm", 1000.0 * odo::RootMeanSquare(*errors[1])},
          {"ate_deg", kDegree * odo::RootMeanSquare(*errors[2])},
          {"rpe_deg", kDegree * odo::RootMeanSquare(*errors[3])}};
}

// Key times of the first model's interval where the reference exists: the reference poses and the wheel-angle
// increments between them.
Outcome ReferenceAtKeyTimes(const recording::Recording& rec, const std::string& dir, const odo::KeySequence& seq,
                            std::vector<odo::Pose2>* reference, Eigen::MatrixXd* delta) {
  std::vector<int> rows;
  for (int k = 0; k < seq.size(); ++k) {
    odo::Pose2 pose;
    if (eval::PlanarPoseAt(*rec.ground_truth, seq.t[k], &pose)) {
      reference->push_back(pose);
      rows.push_back(k);
    }
  }
  if (reference->size() < 2) return Bad(dir + ": the ground truth does not cover two key times");
  Eigen::MatrixXd angles(static_cast<Eigen::Index>(rows.size()), seq.wheel_angle_rad.cols());
  for (std::size_t k = 0; k < rows.size(); ++k)
    angles.row(static_cast<Eigen::Index>(k)) = seq.wheel_angle_rad.row(rows[k]);
  *delta = angles.bottomRows(angles.rows() - 1) - angles.topRows(angles.rows() - 1);
  return Outcome::Ok();
}

// Pooled errors over the recordings: index 0 = nominal, then the models in order.
struct Pooled {
  std::vector<std::vector<double>> absolute, relative, absolute_heading, relative_heading;

  void Add(std::size_t i, const Evaluated& e) {
    absolute[i].insert(absolute[i].end(), e.absolute.begin(), e.absolute.end());
    relative[i].insert(relative[i].end(), e.relative.begin(), e.relative.end());
    absolute_heading[i].insert(absolute_heading[i].end(), e.absolute_heading.begin(), e.absolute_heading.end());
    relative_heading[i].insert(relative_heading[i].end(), e.relative_heading.begin(), e.relative_heading.end());
  }
  std::array<const std::vector<double>*, 4> Errors(std::size_t i) const {
    return {&absolute[i], &relative[i], &absolute_heading[i], &relative_heading[i]};
  }
};

// Dead-reckons recording `r` with the nominal model and every model; adds its errors to `pooled` and its row to
// `per_recording`, and draws its figure.
Outcome EvaluateRecording(const OdometryEvaluateOptions& options, const std::vector<odo::OdometryModel>& models,
                          std::size_t r, bool plots, Pooled* pooled, json* per_recording) {
  const std::string& dir = options.recordings[r];
  Result<recording::Recording> rec = recording::ReadRecording(dir);
  if (!rec.ok()) return Outcome::BadInput(rec.status());
  if (!rec.value().ground_truth) return Bad(dir + ": no ground_truth.tum (the reference)");
  odo::KeyTimeOptions key_options;
  key_options.interval_s = models.front().interval_s;
  key_options.encoder_stream = options.encoder_stream;
  Result<odo::KeySequence> seq = odo::CutAtKeyTimes(rec.value(), dir, key_options, false);
  if (!seq.ok()) return Outcome::BadInput(seq.status());
  std::vector<odo::Pose2> reference;
  Eigen::MatrixXd delta;
  if (Outcome o = ReferenceAtKeyTimes(rec.value(), dir, seq.value(), &reference, &delta); !o.ok()) return o;

  // The nominal model from this recording's metadata, then every model.
  Result<odo::WheelKinematics> nominal = odo::NominalKinematics(rec.value().platform, seq.value().wheels);
  if (!nominal.ok()) return Bad(dir + ": " + nominal.status().message());
  std::vector<Evaluated> evaluated;
  evaluated.push_back({"nominal",
                       odo::PredictTrajectory([&](const Eigen::VectorXd& d) { return nominal.value().Displacement(d); },
                                              delta, reference.front()),
                       {},
                       {},
                       {},
                       {}});
  for (std::size_t i = 0; i < models.size(); ++i) {
    const odo::OdometryModel& model = models[i];
    if (model.wheels != seq.value().wheels)
      return Bad(options.models[i] + ": the model's wheels do not match the encoder columns of " + dir);
    if (std::abs(model.interval_s - models.front().interval_s) > 1e-12)
      return Bad(options.models[i] + ": all models must share one key interval");
    evaluated.push_back(
        {DescribeOdometryModel(model) + " [" + fs::path(options.models[i]).filename().string() + "]",
         odo::PredictTrajectory([&](const Eigen::VectorXd& d) { return model.Predict(d); }, delta, reference.front()),
         {},
         {},
         {},
         {}});
  }

  // Errors, the recording's rows and its figure.
  json rows_json = json::array();
  for (std::size_t i = 0; i < evaluated.size(); ++i) {
    Evaluated& e = evaluated[i];
    e.absolute = odo::AbsoluteErrors(e.poses, reference);
    e.relative = odo::RelativeErrors(e.poses, reference);
    e.absolute_heading = odo::AbsoluteHeadingErrors(e.poses, reference);
    e.relative_heading = odo::RelativeHeadingErrors(e.poses, reference);
    pooled->Add(i, e);
    const std::string kind = i == 0 ? "nominal" : odo::ModelKindName(models[i - 1].kind);
    json row = Row(kind, i == 0 ? "-" : models[i - 1].MeanLabel(), i == 0 ? "-" : models[i - 1].KernelLabel(),
                   {&e.absolute, &e.relative, &e.absolute_heading, &e.relative_heading});
    if (i > 0) row["model_file"] = options.models[i - 1];
    rows_json.push_back(row);
  }
  char name[32];
  std::snprintf(name, sizeof name, "trajectory_%02zu", r + 1);
  per_recording->push_back({{"recording", dir},
                            {"key_poses", reference.size()},
                            {"rows", rows_json},
                            {"figure", plots ? std::string(name) + ".png" : std::string()}});
  if (!plots) return Outcome::Ok();
  std::vector<eval::TopViewSeries> series;
  for (const Evaluated& e : evaluated) series.push_back({e.label, e.poses});
  const Status drawn =
      eval::WriteTopViewFigure(options.out, name, fs::path(dir).filename().string(), reference, series);
  return drawn.ok() ? Outcome::Ok() : Outcome::Failed(drawn);
}

// The pooled table (the seed's Tables III-IV).
json PooledTable(const OdometryEvaluateOptions& options, const std::vector<odo::OdometryModel>& models,
                 const Pooled& pooled, const json& per_recording) {
  json table;
  table["rows"] = json::array();
  table["rows"].push_back(Row("nominal", "-", "-", pooled.Errors(0)));
  for (std::size_t i = 0; i < models.size(); ++i) {
    json row =
        Row(odo::ModelKindName(models[i].kind), models[i].MeanLabel(), models[i].KernelLabel(), pooled.Errors(i + 1));
    row["model_file"] = options.models[i];
    table["rows"].push_back(row);
  }
  table["recordings"] = per_recording;
  table["interval_s"] = models.front().interval_s;
  return table;
}

}  // namespace

std::string DescribeOdometryModel(const odo::OdometryModel& model) {
  std::ostringstream s;
  s << odo::ModelKindName(model.kind);
  if (model.gp) s << " (mean " << model.MeanLabel() << ", kernel " << model.KernelLabel() << ")";
  return s.str();
}

Outcome LearnOdometry(const OdometryLearnOptions& options, LearnedOdometry* learned) {
  if (options.recordings.empty()) return Bad("learn needs at least one --recording");
  if (options.model != "gp" && options.model != "linear" && options.model != "parametric")
    return Bad("--model must be gp, linear or parametric");
  odo::TrainingSet data;
  recording::Platform platform;
  std::size_t recordings = 0;
  if (Outcome read = ReadTrainingSet(options, &data, &platform, &recordings); !read.ok()) return read;
  if (options.log) {
    std::ostringstream line;
    line << data.size() << " pairs " << options.interval_s << " s apart from " << recordings << " recordings";
    options.log(line.str());
  }
  const auto start = std::chrono::steady_clock::now();
  Result<odo::OdometryModel> model = Train(options, data, platform);
  if (!model.ok()) return Outcome::Failed(model.status());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  model.value().training_recordings = options.recordings;
  if (Status s = odo::SaveOdometryModel(model.value(), options.out); !s.ok()) return Outcome::Failed(s);
  if (learned) *learned = {std::move(model).value(), platform.kind, seconds};
  return Outcome::Ok();
}

Outcome EvaluateOdometry(const OdometryEvaluateOptions& options, json* table) {
  if (options.models.empty() || options.recordings.empty()) return Bad("evaluate needs --model and --recording");
  std::vector<odo::OdometryModel> models;
  for (const std::string& path : options.models) {
    Result<odo::OdometryModel> model = odo::LoadOdometryModel(path);
    if (!model.ok()) return Outcome::BadInput(model.status());
    models.push_back(std::move(model).value());
  }
  std::error_code ec;
  fs::create_directories(options.out, ec);
  if (ec) return Failed(options.out + ": cannot create the output directory: " + ec.message());
  const bool plots = options.plots && eval::GnuplotAvailable();
  if (options.plots && !plots && options.log) options.log("gnuplot not found, no figures");

  const std::vector<std::vector<double>> empty(models.size() + 1);
  Pooled pooled{empty, empty, empty, empty};
  json per_recording = json::array();
  for (std::size_t r = 0; r < options.recordings.size(); ++r)
    if (Outcome o = EvaluateRecording(options, models, r, plots, &pooled, &per_recording); !o.ok()) return o;
  const json pooled_table = PooledTable(options, models, pooled, per_recording);
  const std::string path = (fs::path(options.out) / "table.json").string();
  if (Status s = WriteFileAtomic(path, pooled_table.dump(2) + "\n"); !s.ok()) return Failed(s.message());
  if (table) *table = pooled_table;
  return Outcome::Ok();
}

}  // namespace roamlab::experiment
