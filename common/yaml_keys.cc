#include "common/yaml_keys.h"

#include <set>

#include <yaml-cpp/yaml.h>

namespace roamlab {
namespace {

std::string LineOf(const YAML::Node& node) {
  const YAML::Mark mark = node.Mark();
  return mark.is_null() || mark.line < 0 ? "?" : std::to_string(mark.line + 1);
}

std::string Walk(const YAML::Node& node, int depth) {
  if (!node.IsMap() && !node.IsSequence()) return "";
  if (depth > kMaxYamlDepth) return LineOf(node) + ": nesting deeper than " + std::to_string(kMaxYamlDepth) + " levels";
  if (node.IsSequence()) {
    for (const YAML::Node& item : node)
      if (std::string problem = Walk(item, depth + 1); !problem.empty()) return problem;
    return "";
  }
  std::set<std::string> keys;
  for (const auto& item : node) {
    if (item.first.IsScalar() && !keys.insert(item.first.Scalar()).second) {
      constexpr std::size_t kMax = 40;
      const std::string& key = item.first.Scalar();
      return LineOf(item.first) + ": duplicate key '" + (key.size() <= kMax ? key : key.substr(0, kMax) + "...") + "'";
    }
    if (std::string problem = Walk(item.second, depth + 1); !problem.empty()) return problem;
  }
  return "";
}

}  // namespace

std::string DuplicateKeyProblem(const YAML::Node& root) { return Walk(root, 0); }

}  // namespace roamlab
