// What runs a regression case of each mode (regress/mode_specs.h) in its own directory, writing the files the
// `roamlab` commands write.
#pragma once

#include <string>

#include "common/status.h"
#include "regress/mode_specs.h"
#include "regress/suite.h"

namespace roamlab::regress {

struct CaseContext {
  const Case& c;
  std::string dir;  // the case's output directory (exists, empty)
  int jobs = 1;     // threads a mode may use inside the case (montecarlo runs)
};

// Runs a case, writing the mode's outputs; the error is one line.
using ModeRunner = Status (*)(const CaseContext& context);

// The runner of the mode of this name, nullptr when unknown.
ModeRunner FindModeRunner(const std::string& name);

}  // namespace roamlab::regress
