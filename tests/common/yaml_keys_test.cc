#include "common/yaml_keys.h"

#include <string>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

namespace roamlab {
namespace {

TEST(YamlKeysTest, FindsTheFirstRepeatedKeyWithItsLine) {
  EXPECT_EQ(DuplicateKeyProblem(YAML::Load("a: 1\nb: 2\n")), "");
  EXPECT_EQ(DuplicateKeyProblem(YAML::Load("a: 1\nb: 2\na: 3\n")), "3: duplicate key 'a'");
  // Nested mappings, flow style, and mappings inside sequences.
  EXPECT_EQ(DuplicateKeyProblem(YAML::Load("s:\n  n: {x: 1, x: 2}\n")), "2: duplicate key 'x'");
  EXPECT_EQ(DuplicateKeyProblem(YAML::Load("l:\n  - {k: 1}\n  - {k: 1, j: 2, k: 3}\n")), "3: duplicate key 'k'");
  // The same key in different mappings is fine.
  EXPECT_EQ(DuplicateKeyProblem(YAML::Load("a: {x: 1}\nb: {x: 2}\n")), "");
}

TEST(YamlKeysTest, RefusesNestingBeyondTheLimit) {
  std::string deep;
  for (int i = 0; i <= kMaxYamlDepth + 1; ++i) deep += "[";
  for (int i = 0; i <= kMaxYamlDepth + 1; ++i) deep += "]";
  EXPECT_NE(DuplicateKeyProblem(YAML::Load(deep)).find("nesting deeper than"), std::string::npos);
}

}  // namespace
}  // namespace roamlab
