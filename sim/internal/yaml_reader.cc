#include "sim/internal/yaml_reader.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>

#include "common/yaml_keys.h"

namespace roamlab::sim::internal {
namespace {

// Shortens what a user wrote for an error message.
std::string Quote(const std::string& text) {
  constexpr std::size_t kMax = 40;
  return "'" + (text.size() <= kMax ? text : text.substr(0, kMax) + "...") + "'";
}

std::string Describe(const YAML::Node& node) {
  if (node.IsScalar()) return Quote(node.Scalar());
  if (node.IsSequence()) return "a sequence";
  if (node.IsMap()) return "a mapping";
  return "nothing";
}

// Parses the whole text as a finite double (C locale).
bool ParseFinite(const std::string& text, double* value) {
  if (text.empty()) return false;
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size() || errno == ERANGE || !std::isfinite(v)) return false;
  *value = v;
  return true;
}

}  // namespace

YamlReader::YamlReader(std::string path) : path_(std::move(path)) {
  std::ifstream file(path_, std::ios::binary);
  if (!file) {
    error_ = path_ + ": cannot open file";
    return;
  }
  std::ostringstream content;
  content << file.rdbuf();
  try {
    root_ = YAML::Load(content.str());
    if (const std::string problem = DuplicateKeyProblem(root_); !problem.empty()) error_ = path_ + ":" + problem;
  } catch (const YAML::Exception& e) {
    error_ = e.mark.is_null() ? path_ + ": " + e.msg
                              : path_ + ":" + std::to_string(e.mark.line + 1) + ":" +
                                    std::to_string(e.mark.column + 1) + ": " + e.msg;
  }
}

std::string YamlReader::Where(const YAML::Node& node) const {
  const YAML::Mark mark = node.Mark();
  if (mark.is_null() || mark.line < 0) return path_;
  return path_ + ":" + std::to_string(mark.line + 1);
}

void YamlReader::Fail(const YAML::Node& node, const std::string& key, const std::string& problem) {
  if (!ok()) return;
  error_ = Where(node) + ": " + (key.empty() ? "" : key + ": ") + problem;
}

void YamlReader::Remember(const std::string& key, const YAML::Node& node) {
  const YAML::Mark mark = node.Mark();
  if (!mark.is_null() && mark.line >= 0) lines_[key] = mark.line + 1;
}

std::string YamlReader::LineOf(const std::string& key) const {
  // The key itself, else its nearest enclosing key that was read.
  std::string k = key;
  while (true) {
    const auto it = lines_.find(k);
    if (it != lines_.end()) return path_ + ":" + std::to_string(it->second);
    const std::size_t cut = k.find_last_of(".[");
    if (cut == std::string::npos || cut == 0) return path_;
    k = k.substr(0, cut);
  }
}

void YamlReader::CheckKeys(const YAML::Node& map, const std::string& key,
                           std::initializer_list<std::string_view> allowed) {
  if (!ok()) return;
  Remember(key, map);
  if (!map.IsMap()) {
    Fail(map, key, "expected a mapping, got " + Describe(map));
    return;
  }
  std::set<std::string> seen;
  for (const auto& item : map) {
    const std::string name = item.first.IsScalar() ? item.first.Scalar() : std::string("?");
    if (std::find(allowed.begin(), allowed.end(), name) == allowed.end()) {
      std::string list;
      for (std::string_view a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      Fail(item.first, Join(key, name), "unknown key (allowed here: " + list + ")");
      return;
    }
    if (!seen.insert(name).second) {
      Fail(item.first, Join(key, name), "duplicate key");
      return;
    }
    Remember(Join(key, name), item.first);
  }
}

bool YamlReader::Require(const YAML::Node& map, const std::string& parent_key, const std::string& key) {
  if (!ok()) return false;
  if (map.IsMap() && map[key]) return true;
  Fail(map, Join(parent_key, key), "missing required key");
  return false;
}

void YamlReader::NodeNumber(const YAML::Node& node, const std::string& key, double* out) {
  if (!ok()) return;
  Remember(key, node);
  double value = 0.0;
  if (!node.IsScalar() || !ParseFinite(node.Scalar(), &value)) {
    Fail(node, key, "expected a finite number, got " + Describe(node));
    return;
  }
  if (std::abs(value) > kMaxScenarioNumber) {
    Fail(node, key, node.Scalar() + " is beyond any physical value (|value| <= 1e9)");
    return;
  }
  *out = value;
}

void YamlReader::NodeNumbers(const YAML::Node& node, const std::string& key, int size, std::vector<double>* out) {
  if (!ok()) return;
  Remember(key, node);
  if (!node.IsSequence()) {
    Fail(node, key, "expected a sequence of numbers, got " + Describe(node));
    return;
  }
  if (size >= 0 && static_cast<int>(node.size()) != size) {
    Fail(node, key, "expected " + std::to_string(size) + " numbers, got " + std::to_string(node.size()));
    return;
  }
  std::vector<double> values(node.size());
  for (std::size_t i = 0; i < node.size(); ++i) {
    NodeNumber(node[i], key + "[" + std::to_string(i) + "]", &values[i]);
  }
  if (ok()) *out = std::move(values);
}

void YamlReader::Number(const YAML::Node& map, const std::string& parent_key, const std::string& key, double* out) {
  if (!ok() || !map[key]) return;
  NodeNumber(map[key], Join(parent_key, key), out);
}

void YamlReader::Integer(const YAML::Node& map, const std::string& parent_key, const std::string& key,
                         std::int64_t* out) {
  if (!ok() || !map[key]) return;
  const YAML::Node node = map[key];
  const std::string full = Join(parent_key, key);
  Remember(full, node);
  double value = 0.0;
  if (!node.IsScalar() || !ParseFinite(node.Scalar(), &value) || value != std::floor(value) ||
      std::abs(value) > 9.0e15) {
    Fail(node, full, "expected an integer, got " + Describe(node));
    return;
  }
  *out = static_cast<std::int64_t>(value);
}

void YamlReader::Unsigned(const YAML::Node& map, const std::string& parent_key, const std::string& key,
                          std::uint64_t* out) {
  if (!ok() || !map[key]) return;
  const YAML::Node node = map[key];
  const std::string full = Join(parent_key, key);
  Remember(full, node);
  const std::string text = node.IsScalar() ? node.Scalar() : std::string();
  const bool digits = !text.empty() && text.size() <= 20 &&
                      std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; });
  errno = 0;
  const unsigned long long value = digits ? std::strtoull(text.c_str(), nullptr, 10) : 0;
  if (!digits || errno == ERANGE) {
    Fail(node, full, "expected a non-negative integer, got " + Describe(node));
    return;
  }
  *out = static_cast<std::uint64_t>(value);
}

void YamlReader::String(const YAML::Node& map, const std::string& parent_key, const std::string& key,
                        std::string* out) {
  if (!ok() || !map[key]) return;
  const YAML::Node node = map[key];
  const std::string full = Join(parent_key, key);
  Remember(full, node);
  if (!node.IsScalar() || node.Scalar().empty()) {
    Fail(node, full, "expected a non-empty string, got " + Describe(node));
    return;
  }
  *out = node.Scalar();
}

void YamlReader::OneOf(const YAML::Node& map, const std::string& parent_key, const std::string& key,
                       std::initializer_list<std::string_view> allowed, std::string* out) {
  std::string value = *out;
  String(map, parent_key, key, &value);
  if (!ok() || !map[key]) return;
  if (std::find(allowed.begin(), allowed.end(), value) != allowed.end()) {
    *out = value;
    return;
  }
  std::string names;
  for (std::string_view a : allowed) names += (names.empty() ? "" : ", ") + std::string(a);
  Fail(map[key], Join(parent_key, key), "unknown value '" + value + "' (allowed: " + names + ")");
}

void YamlReader::Bool(const YAML::Node& map, const std::string& parent_key, const std::string& key, bool* out) {
  if (!ok() || !map[key]) return;
  const YAML::Node node = map[key];
  const std::string full = Join(parent_key, key);
  Remember(full, node);
  const std::string text = node.IsScalar() ? node.Scalar() : std::string();
  if (text == "true") {
    *out = true;
  } else if (text == "false") {
    *out = false;
  } else {
    Fail(node, full, "expected true or false, got " + Describe(node));
  }
}

void YamlReader::Numbers(const YAML::Node& map, const std::string& parent_key, const std::string& key, int size,
                         std::vector<double>* out) {
  if (!ok() || !map[key]) return;
  NodeNumbers(map[key], Join(parent_key, key), size, out);
}

}  // namespace roamlab::sim::internal
