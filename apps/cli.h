// How a `roamlab` command reports an error: one line "roamlab <command>: <message>" on `err` (stderr when nullptr),
// and the process exit code, 2 for bad input (options, files that do not load) and 1 for a failure at run time.
#pragma once

#include <iosfwd>
#include <string>

#include "experiment/steps.h"

namespace roamlab::apps {

inline constexpr int kBadInputExit = 2;
inline constexpr int kFailureExit = 1;

// Prints the line and returns `code`.
int Report(std::ostream* err, const std::string& command, const std::string& message, int code);
// Prints the line and returns kBadInputExit.
inline int BadInput(std::ostream* err, const std::string& command, const std::string& message) {
  return Report(err, command, message, kBadInputExit);
}
// Prints the line and returns kFailureExit.
inline int Failure(std::ostream* err, const std::string& command, const std::string& message) {
  return Report(err, command, message, kFailureExit);
}

// Prints the line of a failed step and returns its exit code; 0 when it succeeded. The prefix names `command`, or
// the inner command whose step failed (Outcome::step).
int Exit(std::ostream* err, const std::string& command, const experiment::Outcome& outcome);

}  // namespace roamlab::apps
