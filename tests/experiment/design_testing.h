// Helpers of the design step's tests.
#pragma once

#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "tests/recording/temp_dir.h"
#include "tests/support/paths.h"

namespace roamlab::testing {

// The repository's configs/NAME without its target_std entries, written into `dir`: a test that sets its own targets
// sees only them. The configurations write each parameter as a one-line flow mapping ("..., target_std: 3.0e-4}").
inline std::string ConfigWithoutTargets(const std::string& name, const TempDir& dir) {
  std::ifstream in(SourceDir() + "/configs/" + name);
  std::stringstream text;
  text << in.rdbuf();
  const std::string stripped = std::regex_replace(text.str(), std::regex(", target_std: [^,}]+"), "");
  const std::string path = dir.File("untargeted_" + name);
  std::ofstream(path) << stripped;
  return path;
}

}  // namespace roamlab::testing
