// Placeholder for the ROS 1 container reader, which the rosmsg branch provides in this file.
#include "importers/internal/bag.h"

namespace roamlab::importers::internal {

Result<Bag> ReadRos1Bag(const std::string& path) {
  return Status::Error(path + ": ROS 1 bags are not read through this reader in this build");
}

}  // namespace roamlab::importers::internal
