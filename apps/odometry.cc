#include "apps/odometry.h"

#include <cstdio>
#include <iostream>

#include <nlohmann/json.hpp>

#include "apps/cli.h"
#include "common/progress.h"
#include "experiment/odometry.h"

namespace roamlab::apps {
namespace {

namespace odo = estimator::odometry;
using nlohmann::json;

void PrintLearned(const experiment::LearnedOdometry& learned, const std::string& out) {
  std::cout << "learned " << experiment::DescribeOdometryModel(learned.model) << " in " << learned.seconds << " s -> "
            << out << "\n";
  if (learned.model.kind == odo::ModelKind::kParametric && learned.platform == "differential_drive") {
    const odo::WheelKinematics& k = learned.model.kinematics;
    std::cout << "  Censi et al.: wheel radii [m]";
    for (std::size_t w = 0; w < k.wheels.size(); ++w) std::cout << " " << k.wheels[w] << " " << k.radius_m[w];
    std::cout << ", track " << k.J.col(2).cwiseAbs().sum() << " m, sensor pose [" << k.sensor_pose.transpose() << "]\n";
  }
}

void PrintTable(const json& table) {
  std::printf("%-12s %-8s %-11s %10s %10s %10s %10s\n", "model", "mean", "kernel", "ATE [m]", "RPE [mm]", "ATE [deg]",
              "RPE [deg]");
  for (const json& row : table["rows"]) {
    std::printf("%-12s %-8s %-11s %10.4f %10.3f %10.3f %10.4f\n", row["model"].get<std::string>().c_str(),
                row["mean"].is_null() ? "-" : row["mean"].get<std::string>().c_str(),
                row["kernel"].is_null() ? "-" : row["kernel"].get<std::string>().c_str(), row["ate_m"].get<double>(),
                row["rpe_mm"].get<double>(), row["ate_deg"].get<double>(), row["rpe_deg"].get<double>());
  }
}

}  // namespace

int RunOdometryLearn(const OdometryLearnArgs& args) {
  experiment::OdometryLearnOptions options = args;
  ProgressMeter meter("odometry learn", &std::cerr);
  if (!args.quiet) options.log = [&meter](const std::string& line) { meter.Note(line); };
  experiment::LearnedOdometry learned;
  const experiment::Outcome outcome = experiment::LearnOdometry(options, &learned);
  if (!outcome.ok()) return Exit(nullptr, "odometry", outcome);
  if (!args.quiet) PrintLearned(learned, args.out);
  return 0;
}

int RunOdometryEvaluate(const OdometryEvaluateArgs& args) {
  experiment::OdometryEvaluateOptions options;
  options.models = args.models;
  options.recordings = args.recordings;
  options.encoder_stream = args.encoder_stream;
  options.out = args.out;
  options.plots = !args.no_plots;
  options.log = [](const std::string& line) { Report(nullptr, "odometry", line, 0); };
  json table;
  const experiment::Outcome outcome = experiment::EvaluateOdometry(options, &table);
  if (!outcome.ok()) return Exit(nullptr, "odometry", outcome);
  if (!args.quiet) PrintTable(table);
  return 0;
}

}  // namespace roamlab::apps
