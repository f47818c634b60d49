#include "importers/internal/bag.h"

namespace roamlab::importers::internal {

Result<Bag> ReadRosbag2(const std::string& path) {
  return Status::Error(path + ": rosbag2 (SQLite) bags are not read by this build");
}

}  // namespace roamlab::importers::internal
