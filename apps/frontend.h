// `roamlab frontend vo|scan REC --out REC2 [--input STREAM] [--stream NAME]`: runs a sensor front end over a recording
// (frontend/recording_front_end.h): the visual odometry over a camera stream, or the scan matcher over a laser_scan
// stream, and writes REC2 with REC's streams plus the derived visual_odometry or scan_matching stream. Returns the
// exit code: 0, 2 with one line "roamlab frontend: <file>: <problem>" on bad input, 1 when REC2 cannot be written.
#pragma once

#include <iosfwd>
#include <string>

namespace roamlab::apps {

struct FrontEndArgs {
  std::string front_end;  // "vo" or "scan"
  std::string recording;
  std::string out;
  std::string input_stream;     // empty: the recording's only camera (laser_scan) stream
  std::string output_stream;    // empty: visual_odometry (scan_matching)
  bool quiet = false;           // no summary
  std::ostream* err = nullptr;  // receives the one-line error; nullptr: stderr
};
int RunFrontEnd(const FrontEndArgs& args);

}  // namespace roamlab::apps
