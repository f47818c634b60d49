// The MCAP reader's entry for bytes already in memory, so a rosbag2 directory with MCAP storage (or a zstd-compressed
// .mcap) adds its files to one Bag. Private to the importers.
#pragma once

#include <string>

#include "importers/internal/bag.h"

namespace roamlab::importers::internal {

// Reads the MCAP file `content` (named `name` in messages) and appends its topics (merged by name), messages and
// chunks to `bag`; `content` moves into bag->storage. Returns the problem as one line "<name>: <problem>", or "" when
// the file was read whole.
std::string AppendMcap(const std::string& name, std::string content, Bag* bag);

// The whole file at `path` in `content`; the problem as "<path>: <problem>", or "".
std::string ReadFileBytes(const std::string& path, std::string* content);

}  // namespace roamlab::importers::internal
