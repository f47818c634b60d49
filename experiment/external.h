// An estimator under test that is not roamlab's: a user's program run on a recording through /bin/sh, whose output
// roamlab scores as its own (ATE, RPE, NEES). The protocol (docs/external-estimator.md):
//
//   command   a shell command line; "{recording}" and "{out}" in it are replaced by the absolute paths of the
//             recording directory and of the output directory (each single-quoted for the shell); a command naming
//             neither gets both appended as two arguments. It runs with /bin/sh -c in `working_dir` (relative paths
//             in the command are relative to it), standard input /dev/null, standard output and error written to
//             the log file, in a process group of its own that is killed (SIGTERM, then SIGKILL) when it exceeds
//             timeout_s or when roamlab is interrupted.
//   input     the recording directory without ground_truth.tum and truth.yaml: the estimator under test is never
//             handed the truth.
//   output    OUT/trajectory.tum (required): TUM lines "t x y z qx qy qz qw", the pose of the body frame O in the
//             recording's world frame W, time in seconds on the recording's clock, strictly increasing.
//             OUT/covariance.csv (optional): header "t,xx,xy,xz,yx,yy,yz,zx,zy,zz", one row per pose with the pose's
//             stamp, the 3x3 world-frame covariance of the position of O [m^2], row-major (the file `roamlab track`
//             writes). Without it the estimate is scored for accuracy only (no NEES).
//
// Every failure of the program under test (it cannot start, exits non-zero, is killed, exceeds its time, writes no
// trajectory or a malformed one) is a run-time error of one line naming the command and the file, never a crash.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "recording/trajectory.h"

namespace roamlab::experiment {

struct ExternalCommand {
  std::string command;      // the shell command line (see the top of this file)
  std::string working_dir;  // where it runs; "" = the current directory
  double timeout_s = kDefaultTimeoutS;

  static constexpr double kDefaultTimeoutS = 600.0;

  // What is wrong ("the command is empty", "timeout_s must be positive and at most 1e6"), "" when nothing.
  std::string Validate() const;
};

// The command line /bin/sh runs for this recording and output directory (both made absolute and quoted).
std::string ExpandCommand(const std::string& command, const std::string& recording_dir, const std::string& out_dir);

// Makes `input_dir` hold a symbolic link to every entry of `recording_dir` except ground_truth.tum and truth.yaml:
// the recording as the estimator under test sees it. An error names the directory that cannot be made.
Status MakeEstimatorInput(const std::string& recording_dir, const std::string& input_dir);

// Runs the command on `recording_dir` (which the caller has stripped of the truth) with the empty output directory
// `out_dir` (created), its standard output and error in `log_file`. An error: one line naming the command and what
// went wrong (exit status, signal, time-out, cannot start), with the log's last line when it has one.
Status RunExternalCommand(const ExternalCommand& command, const std::string& recording_dir, const std::string& out_dir,
                          const std::string& log_file);

// What the command wrote: the trajectory and, when it wrote covariance.csv, one position covariance per pose.
struct ExternalEstimate {
  Trajectory trajectory;
  std::optional<std::vector<Eigen::Matrix3d>> position_covariance_world;  // m^2, one per pose, same order
};

// Reads OUT/trajectory.tum and the optional OUT/covariance.csv. Errors name the file (and line): a missing or empty
// trajectory, a malformed line, a covariance row count or stamp that does not match the poses'.
Result<ExternalEstimate> ReadExternalEstimate(const std::string& out_dir);

}  // namespace roamlab::experiment
