// Duplicate keys in a YAML document. yaml-cpp accepts a mapping that repeats a key and answers a lookup with one of the
// values, so a configuration that sets a key twice would run silently with one of them. Every YAML reader of roamlab
// calls DuplicateKeyProblem on the loaded tree and refuses the file when it answers a problem.
#pragma once

#include <string>

namespace YAML {
class Node;
}  // namespace YAML

namespace roamlab {

// The deepest nesting of mappings and sequences DuplicateKeyProblem walks; deeper documents are refused too.
inline constexpr int kMaxYamlDepth = 64;

// "" when no mapping of the tree under `root` repeats a scalar key; otherwise "<line>: duplicate key '<key>'" for the
// first repetition (1-based line of the second occurrence), or "<line>: nesting deeper than 64 levels".
std::string DuplicateKeyProblem(const YAML::Node& root);

}  // namespace roamlab
