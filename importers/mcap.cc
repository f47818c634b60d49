#include "importers/internal/bag.h"

namespace roamlab::importers::internal {

Result<Bag> ReadMcap(const std::string& path) {
  return Status::Error(path + ": MCAP files are not read by this build");
}

}  // namespace roamlab::importers::internal
