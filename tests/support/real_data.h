// The real datasets the tests read (each test skips when its file is absent): the directory the environment variable
// ROAMLAB_DATA_DIR names, else the data/ folder of the shared directory the build was configured with
// (SharedDir(), tests/support/paths.h).
#pragma once

#include <cstdlib>
#include <string>

#include "tests/support/paths.h"

namespace roamlab::testing {

inline std::string RealDataDir() {
  const char* dir = std::getenv("ROAMLAB_DATA_DIR");
  if (dir != nullptr && *dir != '\0') return dir;
  return roamlab::testing::SharedDir() + "/data";
}

// `relative` under RealDataDir(), e.g. "husky_test1/test1.bag".
inline std::string RealData(const std::string& relative) { return RealDataDir() + "/" + relative; }

}  // namespace roamlab::testing
