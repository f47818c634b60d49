// `roamlab odometry learn|evaluate`: model-free odometry calibration (experiment/odometry.h).
// Exit codes: 0; 2 with one line "roamlab odometry: <file>: <problem>" on bad input; 1 on a run-time failure.
#pragma once

#include <string>
#include <vector>

#include "experiment/odometry.h"

namespace roamlab::apps {

// The learner's options (without log, which the command sets).
struct OdometryLearnArgs : experiment::OdometryLearnOptions {
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
