#include "tests/support/paths.h"

namespace roamlab::testing {

std::string SourceDir() { return ROAMLAB_SOURCE_DIR; }

std::string SharedDir() { return ROAMLAB_SHARED_DIR; }

}  // namespace roamlab::testing
