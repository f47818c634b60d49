// The modes a regression case can run, one table entry each: the case keys the mode reads, its output files with
// their key schemas (what a check's metric path may name), and the function that runs a case in its own directory,
// writing the files the `roamlab` commands write. A mode without a run function is known but not available in this
// build: suites naming it are refused when loaded.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/status.h"
#include "regress/suite.h"

namespace roamlab::regress {

struct CaseContext {
  const Case& c;
  std::string dir;  // the case's output directory (exists, empty)
  int jobs = 1;     // threads a mode may use inside the case (montecarlo runs)
};

struct ModeOutput {
  std::string name;  // first component of a metric path
  std::string file;  // relative to the case directory
  // Key schema: an object whose leaves are "number", "numbers" (array of numbers), "timing" (not deterministic:
  // never a check), "relative" (derived: max_i |error_i / truth_i| of a parameter row); "<parameter>" and "<stream>"
  // stand for the names of the case's estimator configuration; an array of one object is an array of such objects.
  nlohmann::json schema;
};

// Runs a case, writing the mode's outputs; the error is one line.
using ModeRunner = Status (*)(const CaseContext& context);

struct ModeSpec {
  std::string name;
  std::vector<std::string> keys;      // case keys the mode reads besides name, mode, quick and checks
  std::vector<std::string> required;  // of those, the required ones; "a|b" means exactly one of a and b
  std::vector<ModeOutput> outputs;
  // Runs the case, writing the outputs above; nullptr: not available in this build.
  ModeRunner run = nullptr;
};

// The mode of this name, nullptr when unknown.
const ModeSpec* FindMode(const std::string& name);
// Names of the modes available in this build, for messages.
std::string AvailableModeNames();

}  // namespace roamlab::regress
