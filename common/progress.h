// Progress of a long step, for a person at a terminal and for a log file alike: "LABEL: 12/50 (24%), 1m03s elapsed,
// about 3m10s left". On a terminal the line is rewritten in place (`\r`); elsewhere (a log, a pipe) a line is printed
// only each time another `kLogStep` of the work is done, so that a log holds about twenty lines, not one per update.
#pragma once

#include <chrono>
#include <functional>
#include <iosfwd>
#include <mutex>
#include <string>

namespace roamlab {

// True when `out` is std::cout or std::cerr (or std::clog) and that descriptor is a terminal.
bool IsTerminal(const std::ostream& out);

// "45s", "3m10s", "2h05m" (whole seconds; negative or not finite as "?").
std::string FormatDuration(double seconds);

// Seconds left when `fraction` (in [0, 1]) of the work took `seconds`, at that rate: NaN while nothing is done.
double SecondsLeft(double seconds, double fraction);

// ", 1m03s elapsed" and, when `left_s` is finite and positive, ", about 3m10s left".
std::string ElapsedAndLeft(double elapsed_s, double left_s);

class ProgressMeter {
 public:
  // Fraction of the work between two lines when `out` is not a terminal.
  static constexpr double kLogStep = 0.05;

  // Writes to `out` (kept, not owned); a terminal when IsTerminal(out).
  ProgressMeter(std::string label, std::ostream* out);
  // With the terminal decided and a clock in seconds given (tests).
  ProgressMeter(std::string label, std::ostream* out, bool terminal, std::function<double()> clock_s);
  // Ends an unfinished `\r` line.
  ~ProgressMeter();
  ProgressMeter(const ProgressMeter&) = delete;
  ProgressMeter& operator=(const ProgressMeter&) = delete;

  // The time left is extrapolated from the first update on, so that what ran before it (reading inputs, a
  // calibration) does not count as progress.
  // `done` of `total` items finished: "LABEL: 12/50 (24%), ...".
  void Update(int done, int total);
  // `fraction` in [0, 1] of the work finished: "LABEL: 24%, ...".
  void Update(double fraction);
  // A message line ("LABEL: line (1m03s)"): on a terminal it replaces the progress line, which the next update draws
  // again below it.
  void Note(const std::string& line);
  // Ends the `\r` line on a terminal (the next output starts on a fresh line).
  void Finish();

  // Seconds since construction.
  double ElapsedSeconds() const;

 private:
  void Draw(double fraction, const std::string& counts);

  std::string label_;
  std::ostream* out_;
  bool terminal_;
  std::function<double()> clock_s_;
  double start_s_;
  double first_s_ = 0.0;          // clock at the first update
  double first_fraction_ = -1.0;  // fraction at the first update; < 0 before it
  int logged_steps_ = -1;         // the last kLogStep multiple printed off a terminal
  bool line_open_ = false;        // a `\r` line is on the terminal
  std::mutex mutex_;
};

}  // namespace roamlab
