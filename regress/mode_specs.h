// The modes a regression case can run, one table entry each: the case keys the mode reads and its output files with
// their key schemas (what a check's metric path may name). What runs a case of each mode is regress/modes.h; the suite
// loader needs only this table.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace roamlab::regress {

struct ModeOutput {
  std::string name;  // first component of a metric path
  std::string file;  // relative to the case directory
  // Key schema: an object whose leaves are "number", "numbers" (array of numbers), "timing" (not deterministic:
  // never a check), "relative" (derived: max_i |error_i / truth_i| of a parameter row); "<parameter>" and "<stream>"
  // stand for the names of the case's estimator configuration; an array of one object is an array of such objects.
  nlohmann::json schema;
};

struct ModeSpec {
  std::string name;
  std::vector<std::string> keys;      // case keys the mode reads besides name, mode, quick and checks
  std::vector<std::string> required;  // of those, the required ones; "a|b" means exactly one of a and b
  std::vector<ModeOutput> outputs;
};

// The mode of this name, nullptr when unknown.
const ModeSpec* FindMode(const std::string& name);
// Names of the modes, for messages.
std::string ModeNames();

}  // namespace roamlab::regress
