// Clean interruption of the long commands. InstallInterruptHandlers() makes SIGINT and SIGTERM set a flag (the handler
// does nothing else: it is async-signal-safe); the long loops (solver iterations, tracking updates, simulation steps,
// regression cases, Monte-Carlo runs, diagnosis candidates) poll InterruptRequested() and stop with an error, and the
// command exits with InterruptExitCode(): 130 after SIGINT, 143 after SIGTERM. A second signal while the first is
// being handled ends the process at once (the default action).
//
// IncompleteMarker marks an output directory as incomplete while a command writes into it: DIR/INCOMPLETE, a JSON
// object {"command": the command line, "state": "running" | "interrupted" | "failed", "signal": "SIGINT" (when
// interrupted), "message": why it stopped, "done": what was finished}, written when the command starts writing
// (so that a process killed outright also leaves it) and rewritten when it stops early; removed when the command
// completes.
#pragma once

#include <string>
#include <vector>

#include "common/status.h"

namespace roamlab {

// Installs the SIGINT and SIGTERM handlers (sigaction, SA_RESTART).
void InstallInterruptHandlers();
// True once SIGINT or SIGTERM arrived after InstallInterruptHandlers().
bool InterruptRequested();
// The signal that arrived (SIGINT, SIGTERM), 0 when none.
int InterruptSignal();
// 128 + the signal (130 for SIGINT, 143 for SIGTERM), 0 when none arrived.
int InterruptExitCode();
// "interrupted by SIGINT" (or SIGTERM): the message of an error that an interruption caused.
Status InterruptedError();
// Sets the flag as the handler does; for tests.
void RequestInterrupt(int signal);
// Clears the flag; for tests.
void ClearInterrupt();

// The process's command line (argv joined by spaces), recorded in INCOMPLETE markers; "" until set.
void SetCommandLine(int argc, const char* const* argv);
const std::string& CommandLine();

inline constexpr char kIncompleteFile[] = "INCOMPLETE";

class IncompleteMarker {
 public:
  // Does not write; Start() does.
  explicit IncompleteMarker(std::string directory);
  // Unless Complete() succeeded: writes the marker with state "interrupted" (InterruptRequested()) or "failed".
  ~IncompleteMarker();
  IncompleteMarker(const IncompleteMarker&) = delete;
  IncompleteMarker& operator=(const IncompleteMarker&) = delete;

  // Writes DIR/INCOMPLETE with state "running" and the items already done (AddDone before Start).
  Status Start();
  // Records a finished item ("case gps_outage", "run 12"); rewrites the marker once started.
  Status AddDone(const std::string& item);
  // Why the command stopped (one line), written with the final state.
  void SetMessage(const std::string& message) { message_ = message; }
  // Removes the marker: the directory is complete.
  Status Complete();

  std::string path() const { return directory_ + "/" + kIncompleteFile; }

 private:
  Status Write(const std::string& state) const;

  std::string directory_;
  std::vector<std::string> done_;
  std::string message_;
  bool started_ = false;
  bool completed_ = false;
};

}  // namespace roamlab
