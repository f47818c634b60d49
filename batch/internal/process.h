// Running a program (sbatch, squeue) with arguments and no shell, and collecting what it printed.
#pragma once

#include <string>
#include <vector>

#include "common/status.h"

namespace roamlab::batch::internal {

struct ProcessResult {
  int exit_code = -1;  // -1 when it did not exit normally
  std::string out;     // standard output
  std::string err;     // standard error
};

// Runs argv[0] (looked up in PATH) with argv and waits for it. An error when it cannot be started.
Result<ProcessResult> RunProcess(const std::vector<std::string>& argv);

}  // namespace roamlab::batch::internal
