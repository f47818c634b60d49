// Front ends over a recording: a raw stream of a recording in, the derived stream out, through the same code the
// simulator runs (so a simulated recording's stored frames or scans give back its own visual_odometry or
// scan_matching stream, byte for byte), and the core of `roamlab frontend vo|scan REC --out REC2`.
//
//   visual odometry   reads a camera stream (recording.h): PNG (or any image OpenCV reads) frames, turned to grayscale;
//                     its attributes must hold the six intrinsics and the floor reference camera_height_m,
//                     floor_normal_x, floor_normal_y, floor_normal_z (visual_odometry_stream.h). Writes a
//                     visual_odometry stream with the camera stream's rate, mounting and intrinsics, default
//                     options otherwise (visual_odometry.h).
//   scan matching     reads a laser_scan stream (recording.h, laser_scan.h) whose rows share one geometry. Writes a
//                     scan_matching stream with the laser_scan stream's rate and mounting (scan_matching_stream.h).
#pragma once

#include <functional>
#include <optional>
#include <string>

#include "common/status.h"
#include "frontend/visual_odometry.h"
#include "recording/recording.h"

namespace roamlab::frontend {

enum class FrontEnd { kVisualOdometry, kScanMatching };

struct FrontEndOptions {
  FrontEnd front_end = FrontEnd::kVisualOdometry;
  std::string input_stream;   // empty: the recording's only stream of type camera (laser_scan)
  std::string output_stream;  // empty: visual_odometry (scan_matching)
  std::function<void(double fraction)> progress;  // optional: the fraction of frames (scans) done, after each
};

struct FrontEndResult {
  recording::Stream stream;                   // the derived stream
  std::string input_stream;                   // the stream it was derived from
  std::optional<VoCounters> visual_odometry;  // visual odometry: frames, pairs, failures by reason
  int failed_scan_matches = 0;                // scan matching: pairs without a match
};

// The derived stream of `recording`, read from `directory` (camera frames are relative to it). Errors (one line,
// naming the file): no or several input streams of the type, an input stream of another type, missing attributes,
// an image that cannot be read or has the wrong size, scans whose geometry changes.
Result<FrontEndResult> DeriveStream(const recording::Recording& recording, const std::string& directory,
                                    const FrontEndOptions& options);

// `roamlab frontend`: reads the recording in `input_directory`, derives the stream and writes `output_directory`
// with the input's streams and ground truth plus the derived stream (in place of a stream of the same name, else
// last). When the output is another directory the camera frames and truth.yaml are copied along. On error,
// `bad_input` (when given) tells a bad input recording (true) from a failure to write the output (false).
Result<FrontEndResult> RunFrontEnd(const std::string& input_directory, const std::string& output_directory,
                                   const FrontEndOptions& options, bool* bad_input = nullptr);

}  // namespace roamlab::frontend
