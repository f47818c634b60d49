// `roamlab evaluate --estimate DIR|FILE... (--recording REC | --reference FILE) --out OUT`: accuracy, consistency and
// calibration error of one or several estimates against a reference (eval/evaluate.h). Returns the process exit code:
// 0 on success, 2 with one line "roamlab evaluate: <file>: <problem>" on bad input, 1 when the output cannot be
// written or gnuplot fails.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

namespace roamlab::apps {

struct EvaluateArgs {
  std::vector<std::string> estimates;  // directories with trajectory.tum [, covariance.csv, calibration.json] or files
  std::string recording;               // recording directory [with ground_truth.tum, truth.yaml]
  std::string reference;               // a plain trajectory file as the reference
  std::string reference_stream;        // a gps, position or pose stream of the recording as the reference
  std::string reference_format;        // "", "tum", "kitti", "euroc"; "" = detected
  std::string estimate_format;         // same, for estimate files
  std::string calibration;             // calibration.json for a stream's lever arm and the parameter table
  std::string covariance;              // covariance.csv of the (one) estimate: "" = DIR/covariance.csv
  std::string out;                     // output directory: metrics.json, figures
  std::string
      align;  // "", "none", "se3", "sim3", "yaw" ("yaw_translation") or "origin"; "" = eval/evaluate.h's default
  std::size_t align_first = 0;         // align on the first N matched poses (0: all)
  std::vector<double> align_window_s;  // empty or {start, end} [s since the reference's first pose]
  double t_offset_s = 0.0;             // added to the estimates' stamps
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
