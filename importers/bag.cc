#include <filesystem>
#include <fstream>

#include "importers/internal/bag.h"

namespace roamlab::importers::internal {

Result<Bag> ReadAnyBag(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return ReadRosbag2(path);
  const std::string extension = std::filesystem::path(path).extension().string();
  if (extension == ".yaml" || extension == ".db3") return ReadRosbag2(path);
  std::ifstream file(path, std::ios::binary);
  if (!file) return Status::Error(path + ": cannot open the file");
  char head[9] = {};
  file.read(head, sizeof(head));
  const std::string_view start(head, static_cast<std::size_t>(file.gcount()));
  if (start.substr(0, 5) == "\x89MCAP") return ReadMcap(path);
  if (start.substr(0, 9) == "#ROSBAG V") return ReadRos1Bag(path);
  if (start.empty()) return Status::Error(path + ": empty file (not a bag)");
  return Status::Error(path +
                       ": not a bag (neither '#ROSBAG V' nor the MCAP magic at the start, and not a rosbag2 "
                       "directory)");
}

}  // namespace roamlab::importers::internal
