// Model-free odometry calibration (seed 001, estimator/odometry/) as experiments on recordings:
//
//   learn     training pairs from the recordings' wheel encoders and exteroceptive pose stream (never the ground
//             truth), then one model: gp (CGP, Algorithm 1), linear (Huber, eq. 9) or parametric (Censi et al. for a
//             differential drive, the nominal kinematics otherwise); writes the model file (odometry_model.h).
//   evaluate  dead reckoning of every model and of the nominal model (from each recording's platform metadata) over
//             the recordings' key intervals, against ground_truth.tum: OUT/table.json =
//             {"rows": [{"model", "mean", "kernel", "ate_m", "rpe_mm", "model_file"}], "recordings": [...],
//             "interval_s"} with ATE (eq. 11) and RPE (eq. 10) pooled over all recordings (root mean square over all
//             poses / steps), one row per recording in "recordings", and OUT/trajectory_NN.png per recording (the
//             seed's Fig. 5).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "estimator/odometry/odometry_model.h"
#include "experiment/steps.h"

namespace roamlab::experiment {

struct OdometryLearnOptions {
  std::vector<std::string> recordings;
  std::string model = "gp";         // gp | linear | parametric
  std::string mean = "linear";      // gp: zero | linear
  std::string kernel = "rbf";       // gp: rbf | linear | rbf+linear
  double interval_s = 0.5;          // T between key times
  std::string encoder_stream;       // "" = the only wheel_encoders stream
  std::string sensor_stream;        // "" = the only pose stream
  int hyperparameter_subset = 400;  // gp: pairs for the hyper-parameter optimization (0 = all)
  double outlier_threshold =
      5.0;               // gp, parametric: drop pairs beyond this many robust sigmas of eq. 9's fit (0 = keep)
  int max_pairs = 6000;  // gp: condition on a seeded random subset of at most this many pairs (0 = all)
  std::string out;       // model file (JSON)
  std::function<void(const std::string& line)> log;  // optional: what is being done, one line at a time
};

struct LearnedOdometry {
  estimator::odometry::OdometryModel model;
  std::string platform;  // the recordings' platform kind
  double seconds = 0.0;  // training time
};

// Learns the model from the recordings and writes it to `out`. `learned` (optional) receives it.
Outcome LearnOdometry(const OdometryLearnOptions& options, LearnedOdometry* learned = nullptr);

struct OdometryEvaluateOptions {
  std::vector<std::string> models;      // model files
  std::vector<std::string> recordings;  // test recordings with ground_truth.tum
  std::string encoder_stream;
  std::string out;
  bool plots = true;                                 // draw trajectory_NN.png (with gnuplot, when it is installed)
  std::function<void(const std::string& line)> log;  // optional: notes ("gnuplot not found, no figures")
};

// Evaluates the models on the recordings and writes OUT/table.json (and the figures). `table` (optional) receives it.
Outcome EvaluateOdometry(const OdometryEvaluateOptions& options, nlohmann::json* table = nullptr);

// "gp (mean linear, kernel rbf)", "linear", ...
std::string DescribeOdometryModel(const estimator::odometry::OdometryModel& model);

}  // namespace roamlab::experiment
