// `roamlab odometry learn|evaluate`: model-free odometry calibration (seed 001, estimator/odometry/).
//
//   learn     training pairs from the recordings' wheel encoders and exteroceptive pose stream (never the ground
//             truth), then one model: gp (CGP, Algorithm 1), linear (Huber, eq. 9) or parametric (Censi et al. for a
//             differential drive, the nominal kinematics otherwise); writes the model file (odometry_model.h).
//   evaluate  dead reckoning of every model and of the nominal model (from each recording's platform metadata) over
//             the recordings' key intervals, against ground_truth.tum: OUT/table.json =
//             {"rows": [{"model", "mean", "kernel", "ate_m", "rpe_mm", "model_file"}], "recordings": [...]} with ATE
//             (eq. 11) and RPE (eq. 10) pooled over all recordings (root mean square over all poses / steps), one row
//             per recording in "recordings", and OUT/trajectory_NN.png per recording (the seed's Fig. 5).
// Exit codes: 0; 2 with one line "roamlab odometry: <file>: <problem>" on bad input; 1 on a run-time failure.
#pragma once

#include <string>
#include <vector>

namespace roamlab::apps {

struct OdometryLearnArgs {
  std::vector<std::string> recordings;
  std::string model = "gp";        // gp | linear | parametric
  std::string mean = "linear";     // gp: zero | linear
  std::string kernel = "rbf";      // gp: rbf | linear | rbf+linear
  double interval_s = 0.5;         // T between key times
  std::string encoder_stream;      // "" = the only wheel_encoders stream
  std::string sensor_stream;       // "" = the only pose stream
  int hyperparameter_subset = 400; // gp: pairs for the hyper-parameter optimization (0 = all)
  double outlier_threshold = 5.0;  // gp, parametric: drop pairs beyond this many robust sigmas of eq. 9's fit (0 = keep)
  int max_pairs = 6000;            // gp: condition on a seeded random subset of at most this many pairs (0 = all)
  std::string out;                 // model file (JSON)
  bool quiet = false;
};
int RunOdometryLearn(const OdometryLearnArgs& args);

struct OdometryEvaluateArgs {
  std::vector<std::string> models;      // model files
  std::vector<std::string> recordings;  // test recordings with ground_truth.tum
  std::string encoder_stream;
  std::string out;
  bool no_plots = false;
  bool quiet = false;
};
int RunOdometryEvaluate(const OdometryEvaluateArgs& args);

}  // namespace roamlab::apps
