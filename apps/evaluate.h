// `roamlab evaluate --estimate DIR --recording REC --out OUT`: accuracy, consistency and calibration error of an
// estimate against the recording's truth (eval/evaluate.h). Returns the process exit code: 0 on success, 2 with one
// line "roamlab evaluate: <file>: <problem>" on bad input, 1 when the output cannot be written or gnuplot fails.
#pragma once

#include <iosfwd>
#include <string>

namespace roamlab::apps {

struct EvaluateArgs {
  std::string estimate;   // directory with trajectory.tum [, covariance.csv, calibration.json]
  std::string recording;  // recording directory with ground_truth.tum [, truth.yaml]
  std::string out;        // output directory: metrics.json, figures
  std::string align;      // "", "none", "se3" or "yaw_translation"; "" = the default of eval/evaluate.h
  double max_time_difference_s = 0.01;
  double rpe_delta_s = 1.0;
  double rpe_distance_m = 10.0;
  double nees_t0_s = 0.0;
  bool no_plots = false;
  bool quiet = false;           // no summary on stdout
  std::ostream* err = nullptr;  // receives the one-line error and notes; nullptr: stderr
};
int RunEvaluate(const EvaluateArgs& args);

}  // namespace roamlab::apps
