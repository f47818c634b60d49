#include "apps/cli.h"

#include <iostream>

namespace roamlab::apps {

int Report(std::ostream* err, const std::string& command, const std::string& message, int code) {
  (err ? *err : std::cerr) << "roamlab " << command << ": " << message << "\n";
  return code;
}

int Exit(std::ostream* err, const std::string& command, const experiment::Outcome& outcome) {
  if (outcome.ok()) return 0;
  return Report(err, outcome.step.empty() ? command : outcome.step, outcome.status.message(),
                outcome.bad_input ? kBadInputExit : kFailureExit);
}

}  // namespace roamlab::apps
