// Where the tests find the repository's files and the shared directory beside it, fixed when the build is configured
// (tests/support/CMakeLists.txt). Kept out of every test's compile line so that the tests' objects do not depend on
// the checkout's path.
#pragma once

#include <string>

namespace roamlab::testing {

// The repository's root directory.
std::string SourceDir();

// The shared directory beside the repository (its data/ holds the real recordings the tests read when present).
std::string SharedDir();

}  // namespace roamlab::testing
