#include "apps/odometry.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <numeric>
#include <random>
#include <sstream>

#include <nlohmann/json.hpp>

#include "estimator/odometry/gaussian_process.h"
#include "estimator/odometry/odometry_model.h"
#include "estimator/odometry/parametric.h"
#include "estimator/odometry/robust_linear.h"
#include "estimator/odometry/trajectory.h"
#include "estimator/odometry/training_data.h"
#include "eval/plots.h"
#include "recording/recording.h"

namespace roamlab::apps {
namespace {

namespace fs = std::filesystem;
namespace odo = estimator::odometry;
using nlohmann::json;

int BadInput(const std::string& message) {
  std::cerr << "roamlab odometry: " << message << "\n";
  return 2;
}

int Failure(const std::string& message) {
  std::cerr << "roamlab odometry: " << message << "\n";
  return 1;
}

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

// Trains the model the arguments name on `all`.
Result<odo::OdometryModel> Learn(const OdometryLearnArgs& args, const odo::TrainingSet& all,
                                 const recording::Platform& platform) {
  // Gross outliers (off eq. 9's robust linear surface) out, except for the robust linear model itself.
  odo::TrainingSet data = all;
  if (args.model != "linear" && args.outlier_threshold > 0.0) {
    Result<odo::HuberFit> fit = odo::FitHuberLinear(all.delta, all.s, all.s_sigma);
    if (!fit.ok()) return fit.status();
    data = SelectPairs(all, odo::InlierRows(fit.value(), all.delta, all.s, all.s_sigma, args.outlier_threshold));
    if (!args.quiet) {
      std::cerr << "odometry learn: " << all.size() - data.size() << " of " << all.size() << " pairs beyond "
                << args.outlier_threshold << " robust sigmas dropped as outliers\n";
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

std::string Describe(const odo::OdometryModel& model) {
  std::ostringstream s;
  s << odo::ModelKindName(model.kind);
  if (model.gp) s << " (mean " << model.MeanLabel() << ", kernel " << model.KernelLabel() << ")";
  return s.str();
}

// Planar reference pose (x, y, yaw) of the ground truth at t, linearly interpolated; false outside its span.
bool ReferenceAt(const Trajectory& truth, Time t, odo::Pose2* pose) {
  if (truth.size() < 2 || t < truth.front().t || t > truth.back().t) return false;
  const auto it = std::upper_bound(truth.begin(), truth.end(), t,
                                   [](Time q, const StampedPose& p) { return q < p.t; });
  std::size_t i = it == truth.begin() ? 0 : static_cast<std::size_t>(it - truth.begin()) - 1;
  i = std::min(i, truth.size() - 2);
  const double w = SecondsBetween(truth[i].t, t) / SecondsBetween(truth[i].t, truth[i + 1].t);
  const auto yaw = [](const Eigen::Quaterniond& q) {
    return std::atan2(2.0 * (q.w() * q.z() + q.x() * q.y()), 1.0 - 2.0 * (q.y() * q.y() + q.z() * q.z()));
  };
  const double a = yaw(truth[i].q_world_body);
  const double b = yaw(truth[i + 1].q_world_body);
  const Eigen::Vector3d p = (1.0 - w) * truth[i].p_world_body + w * truth[i + 1].p_world_body;
  *pose = odo::Pose2(p.x(), p.y(), a + w * odo::WrapAngle(b - a));
  return true;
}

// One evaluated trajectory.
struct Evaluated {
  std::string label;
  std::vector<odo::Pose2> poses;
  std::vector<double> absolute;
  std::vector<double> relative;
};

json Row(const std::string& model, const std::string& mean, const std::string& kernel, double ate_m, double rpe_m) {
  return {{"model", model}, {"mean", mean == "-" ? json(nullptr) : json(mean)},
          {"kernel", kernel == "-" ? json(nullptr) : json(kernel)}, {"ate_m", ate_m}, {"rpe_mm", 1000.0 * rpe_m}};
}

// Top view of the reference and every model (the seed's Fig. 5): NAME.dat, NAME.gp, NAME.png in `dir`.
Status WriteTrajectoryFigure(const std::string& dir, const std::string& name, const std::string& title,
                             const std::vector<odo::Pose2>& reference, const std::vector<Evaluated>& models) {
  std::ostringstream data;
  data << "# x_ref_m y_ref_m";
  for (const Evaluated& e : models) data << "  x_m y_m (" << e.label << ")";
  data << "\n";
  for (std::size_t k = 0; k < reference.size(); ++k) {
    data << reference[k][0] << ' ' << reference[k][1];
    for (const Evaluated& e : models) data << ' ' << e.poses[k][0] << ' ' << e.poses[k][1];
    data << '\n';
  }
  std::ostringstream gp;
  gp << "# Redraw: cd into this directory, then: gnuplot " << name << ".gp\n"
     << "set terminal pngcairo size 900,900 noenhanced font 'sans,11'\nset output '" << name << ".png'\n"
     << "set title '" << title << "'\nset xlabel 'x [m]'\nset ylabel 'y [m]'\nset size ratio -1\nset grid\n"
     << "set key outside below\n"
     << "plot '" << name << ".dat' using 1:2 with lines lw 3 lc rgb 'black' title 'reference (ground_truth.tum)'";
  // Distinct colours, none black (the reference).
  static const char* kColors[] = {"#d62728", "#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd",
                                  "#8c564b", "#e377c2", "#17becf", "#bcbd22", "#7f7f7f"};
  for (std::size_t i = 0; i < models.size(); ++i) {
    gp << ", \\\n     '' using " << 3 + 2 * i << ":" << 4 + 2 * i << " with lines lw 1.5 lc rgb '"
       << kColors[i % 10] << "' title '" << models[i].label << "'";
  }
  gp << "\n";
  for (const auto& [file, text] : {std::pair{name + ".dat", data.str()}, std::pair{name + ".gp", gp.str()}}) {
    std::ofstream out(fs::path(dir) / file);
    out << text;
    if (!out) return Status::Error((fs::path(dir) / file).string() + ": cannot write");
  }
  return eval::RunGnuplot(dir, name + ".gp");
}

}  // namespace

int RunOdometryLearn(const OdometryLearnArgs& args) {
  if (args.recordings.empty()) return BadInput("learn needs at least one --recording");
  if (args.model != "gp" && args.model != "linear" && args.model != "parametric") {
    return BadInput("--model must be gp, linear or parametric");
  }
  // Training pairs from every recording (the estimator side: no ground truth).
  odo::KeyTimeOptions key_options;
  key_options.interval_s = args.interval_s;
  key_options.encoder_stream = args.encoder_stream;
  key_options.sensor_stream = args.sensor_stream;
  std::vector<odo::KeySequence> sequences;
  recording::Platform platform;
  for (const std::string& dir : args.recordings) {
    recording::ReadOptions read;
    read.load_ground_truth = false;
    Result<recording::Recording> rec = recording::ReadRecording(dir, read);
    if (!rec.ok()) return BadInput(rec.status().message());
    if (sequences.empty()) platform = rec.value().platform;
    if (rec.value().platform.kind != platform.kind) {
      return BadInput(dir + ": platform '" + rec.value().platform.kind + "' differs from '" + platform.kind + "'");
    }
    Result<odo::KeySequence> seq = odo::CutAtKeyTimes(rec.value(), dir, key_options, true);
    if (!seq.ok()) return BadInput(seq.status().message());
    sequences.push_back(std::move(seq).value());
  }
  Result<odo::TrainingSet> data = odo::MakeTrainingSet(sequences);
  if (!data.ok()) return BadInput(data.status().message());
  if (!args.quiet) {
    std::cerr << "odometry learn: " << data.value().size() << " pairs " << args.interval_s << " s apart from "
              << sequences.size() << " recordings\n";
  }
  const auto start = std::chrono::steady_clock::now();
  Result<odo::OdometryModel> model = Learn(args, data.value(), platform);
  if (!model.ok()) return Failure(model.status().message());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  model.value().training_recordings = args.recordings;
  if (Status s = odo::SaveOdometryModel(model.value(), args.out); !s.ok()) return Failure(s.message());
  if (!args.quiet) {
    std::cout << "learned " << Describe(model.value()) << " in " << seconds << " s -> " << args.out << "\n";
    if (model.value().kind == odo::ModelKind::kParametric && platform.kind == "differential_drive") {
      const odo::WheelKinematics& k = model.value().kinematics;
      std::cout << "  Censi et al.: wheel radii [m]";
      for (std::size_t w = 0; w < k.wheels.size(); ++w) std::cout << " " << k.wheels[w] << " " << k.radius_m[w];
      std::cout << ", track " << k.J.col(2).cwiseAbs().sum() << " m, sensor pose [" << k.sensor_pose.transpose()
                << "]\n";
    }
  }
  return 0;
}

int RunOdometryEvaluate(const OdometryEvaluateArgs& args) {
  if (args.models.empty() || args.recordings.empty()) return BadInput("evaluate needs --model and --recording");
  std::vector<odo::OdometryModel> models;
  for (const std::string& path : args.models) {
    Result<odo::OdometryModel> model = odo::LoadOdometryModel(path);
    if (!model.ok()) return BadInput(model.status().message());
    models.push_back(std::move(model).value());
  }
  std::error_code ec;
  fs::create_directories(args.out, ec);
  if (ec) return Failure(args.out + ": cannot create the output directory: " + ec.message());
  const bool plots = !args.no_plots && eval::GnuplotAvailable();
  if (!args.no_plots && !plots) std::cerr << "roamlab odometry: gnuplot not found, no figures\n";

  // Pooled errors: index 0 = nominal, then the models in order.
  std::vector<std::vector<double>> absolute(models.size() + 1);
  std::vector<std::vector<double>> relative(models.size() + 1);
  json per_recording = json::array();
  for (std::size_t r = 0; r < args.recordings.size(); ++r) {
    const std::string& dir = args.recordings[r];
    Result<recording::Recording> rec = recording::ReadRecording(dir);
    if (!rec.ok()) return BadInput(rec.status().message());
    if (!rec.value().ground_truth) return BadInput(dir + ": no ground_truth.tum (the reference)");
    // Key times of the first model's interval, kept where the reference exists.
    odo::KeyTimeOptions key_options;
    key_options.interval_s = models.front().interval_s;
    key_options.encoder_stream = args.encoder_stream;
    Result<odo::KeySequence> seq = odo::CutAtKeyTimes(rec.value(), dir, key_options, false);
    if (!seq.ok()) return BadInput(seq.status().message());
    std::vector<odo::Pose2> reference;
    std::vector<int> rows;
    for (int k = 0; k < seq.value().size(); ++k) {
      odo::Pose2 pose;
      if (ReferenceAt(*rec.value().ground_truth, seq.value().t[k], &pose)) {
        reference.push_back(pose);
        rows.push_back(k);
      }
    }
    if (reference.size() < 2) return BadInput(dir + ": the ground truth does not cover two key times");
    Eigen::MatrixXd angles(static_cast<Eigen::Index>(rows.size()), seq.value().wheel_angle_rad.cols());
    for (std::size_t k = 0; k < rows.size(); ++k) angles.row(static_cast<Eigen::Index>(k)) =
        seq.value().wheel_angle_rad.row(rows[k]);
    const Eigen::MatrixXd delta = angles.bottomRows(angles.rows() - 1) - angles.topRows(angles.rows() - 1);
    // The nominal model from this recording's metadata, then every model.
    Result<odo::WheelKinematics> nominal = odo::NominalKinematics(rec.value().platform, seq.value().wheels);
    if (!nominal.ok()) return BadInput(dir + ": " + nominal.status().message());
    std::vector<Evaluated> evaluated;
    evaluated.push_back({"nominal", odo::PredictTrajectory(
                                        [&](const Eigen::VectorXd& d) { return nominal.value().Displacement(d); },
                                        delta, reference.front()), {}, {}});
    for (std::size_t i = 0; i < models.size(); ++i) {
      const odo::OdometryModel& model = models[i];
      if (model.wheels != seq.value().wheels) {
        return BadInput(args.models[i] + ": the model's wheels do not match the encoder columns of " + dir);
      }
      if (std::abs(model.interval_s - models.front().interval_s) > 1e-12) {
        return BadInput(args.models[i] + ": all models must share one key interval");
      }
      evaluated.push_back({Describe(model) + " [" + fs::path(args.models[i]).filename().string() + "]",
                           odo::PredictTrajectory([&](const Eigen::VectorXd& d) { return model.Predict(d); }, delta,
                                                  reference.front()), {}, {}});
    }
    json rows_json = json::array();
    for (std::size_t i = 0; i < evaluated.size(); ++i) {
      Evaluated& e = evaluated[i];
      e.absolute = odo::AbsoluteErrors(e.poses, reference);
      e.relative = odo::RelativeErrors(e.poses, reference);
      absolute[i].insert(absolute[i].end(), e.absolute.begin(), e.absolute.end());
      relative[i].insert(relative[i].end(), e.relative.begin(), e.relative.end());
      const std::string kind = i == 0 ? "nominal" : odo::ModelKindName(models[i - 1].kind);
      json row = Row(kind, i == 0 ? "-" : models[i - 1].MeanLabel(), i == 0 ? "-" : models[i - 1].KernelLabel(),
                     odo::RootMeanSquare(e.absolute), odo::RootMeanSquare(e.relative));
      if (i > 0) row["model_file"] = args.models[i - 1];
      rows_json.push_back(row);
    }
    char name[32];
    std::snprintf(name, sizeof name, "trajectory_%02zu", r + 1);
    per_recording.push_back({{"recording", dir}, {"key_poses", reference.size()}, {"rows", rows_json},
                             {"figure", plots ? std::string(name) + ".png" : std::string()}});
    if (plots) {
      if (Status s = WriteTrajectoryFigure(args.out, name, fs::path(dir).filename().string(), reference, evaluated);
          !s.ok()) {
        return Failure(s.message());
      }
    }
  }
  // The pooled table (the seed's Tables III-IV).
  json table;
  table["rows"] = json::array();
  table["rows"].push_back(Row("nominal", "-", "-", odo::RootMeanSquare(absolute[0]), odo::RootMeanSquare(relative[0])));
  for (std::size_t i = 0; i < models.size(); ++i) {
    json row = Row(odo::ModelKindName(models[i].kind), models[i].MeanLabel(), models[i].KernelLabel(),
                   odo::RootMeanSquare(absolute[i + 1]), odo::RootMeanSquare(relative[i + 1]));
    row["model_file"] = args.models[i];
    table["rows"].push_back(row);
  }
  table["recordings"] = per_recording;
  table["interval_s"] = models.front().interval_s;
  const std::string path = (fs::path(args.out) / "table.json").string();
  std::ofstream out(path);
  out << table.dump(2) << "\n";
  if (!out) return Failure(path + ": cannot write");
  if (!args.quiet) {
    std::printf("%-12s %-8s %-11s %10s %10s\n", "model", "mean", "kernel", "ATE [m]", "RPE [mm]");
    for (const json& row : table["rows"]) {
      std::printf("%-12s %-8s %-11s %10.4f %10.3f\n", row["model"].get<std::string>().c_str(),
                  row["mean"].is_null() ? "-" : row["mean"].get<std::string>().c_str(),
                  row["kernel"].is_null() ? "-" : row["kernel"].get<std::string>().c_str(),
                  row["ate_m"].get<double>(), row["rpe_mm"].get<double>());
    }
  }
  return 0;
}

}  // namespace roamlab::apps
