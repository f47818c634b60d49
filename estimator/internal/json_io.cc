#include "estimator/internal/json_io.h"

#include "common/atomic_file.h"

namespace roamlab::estimator::internal {

using nlohmann::json;

Status WriteJson(const json& j, const std::string& path) { return WriteFileAtomic(path, j.dump(2) + "\n"); }

json CountsJson(const std::map<std::string, StreamCounts>& counts) {
  json j = json::object();
  for (const auto& [name, c] : counts)
    j[name] = {{"attached", c.attached},     {"rejected", c.rejected}, {"too_late", c.too_late}, {"outside", c.outside},
               {"duplicates", c.duplicates}, {"gaps", c.gaps},         {"frozen", c.frozen}};
  return j;
}

}  // namespace roamlab::estimator::internal
