// Plain trajectory files as evaluation inputs: TUM, KITTI poses and EuRoC ground-truth CSV.
//
//   tum    "t x y z qx qy qz qw" per line, whitespace-separated, '#' comments (recording/trajectory.h ReadTum).
//   kitti  twelve numbers per line: the first three rows of the 4x4 pose matrix, row-major
//          "r11 r12 r13 tx r21 r22 r23 ty r31 r32 r33 tz". No time: pose i gets the stamp i seconds (`timed` false),
//          and the evaluation pairs such a file with the other trajectory by index. The rotation must be orthonormal
//          to 1e-3 (|R^T R - I| max entry) and proper.
//   euroc  comma-separated "#timestamp [ns], p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [],
//          q_RS_z []" followed by any number of further columns (velocities, biases), which are ignored. The stamp is
//          an integer of nanoseconds; a header line (starting with '#' or not numeric) is skipped.
// Every format: strictly increasing time, finite values, quaternions within 1e-3 of unit norm (normalized on read).
//
// Format detection (DetectTrajectoryFormat), when no format is given: the extension ".tum" is TUM, ".kitti" is KITTI;
// otherwise the first data line decides: commas -> EuRoC, 12 whitespace-separated fields -> KITTI, 8 -> TUM.
#pragma once

#include <optional>
#include <string>

#include "common/status.h"
#include "recording/trajectory.h"

namespace roamlab::eval {

enum class TrajectoryFormat { kTum, kKitti, kEuroc };

// "tum", "kitti", "euroc"; ParseTrajectoryFormat is the inverse (nullopt for anything else).
const char* TrajectoryFormatName(TrajectoryFormat format);
std::optional<TrajectoryFormat> ParseTrajectoryFormat(const std::string& name);

// The format of the file at `path` (see the top of this file). Errors: the file cannot be read, has no data line, or
// its first data line fits no format.
Result<TrajectoryFormat> DetectTrajectoryFormat(const std::string& path);

struct TrajectoryFile {
  Trajectory poses;
  TrajectoryFormat format = TrajectoryFormat::kTum;
  bool timed = true;  // false for KITTI: stamps are the row index in seconds
};

// Reads `path` in `format`, or in the detected format when nullopt. Errors name the file and line.
Result<TrajectoryFile> ReadTrajectoryFile(const std::string& path, std::optional<TrajectoryFormat> format);

}  // namespace roamlab::eval
