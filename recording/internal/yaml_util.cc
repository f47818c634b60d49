#include "recording/internal/yaml_util.h"

#include <algorithm>
#include <set>

#include "common/yaml_keys.h"
#include "recording/internal/text_io.h"

namespace roamlab::recording::internal {
namespace {

// Shortens what a user wrote for an error message.
std::string Quote(const std::string& text) {
  constexpr std::size_t kMax = 40;
  return "'" + (text.size() <= kMax ? text : text.substr(0, kMax) + "...") + "'";
}

Status NodeError(const std::string& path, const YAML::Node& node, const std::string& problem) {
  return Status::Error(Where(path, node) + ": " + problem);
}

}  // namespace

std::string Where(const std::string& path, const YAML::Node& node) {
  const YAML::Mark mark = node.Mark();
  if (mark.is_null() || mark.line < 0) return path;
  return path + ":" + std::to_string(mark.line + 1);
}

Status LoadYamlFile(const std::string& path, YAML::Node* root) {
  std::string content;
  if (Status status = ReadTextFile(path, &content); !status.ok()) return status;
  try {
    *root = YAML::Load(content);
    if (const std::string problem = DuplicateKeyProblem(*root); !problem.empty()) {
      return Status::Error(path + ":" + problem);
    }
  } catch (const YAML::Exception& e) {
    if (e.mark.is_null()) return Status::Error(path + ": " + e.msg);
    return Status::Error(path + ":" + std::to_string(e.mark.line + 1) + ":" + std::to_string(e.mark.column + 1) + ": " +
                         e.msg);
  }
  return Status::Ok();
}

Status CheckKeys(const YAML::Node& map, const std::string& path, const std::string& context,
                 std::initializer_list<std::string_view> allowed) {
  if (!map.IsMap()) return NodeError(path, map, context + " must be a mapping");
  std::set<std::string> seen;
  for (const auto& item : map) {
    if (!item.first.IsScalar()) return NodeError(path, item.first, "non-scalar key in " + context);
    const std::string& key = item.first.Scalar();
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
      return NodeError(path, item.first, "unknown key " + Quote(key) + " in " + context);
    }
    if (!seen.insert(key).second) return NodeError(path, item.first, "duplicate key " + Quote(key) + " in " + context);
  }
  return Status::Ok();
}

Status RequireKey(const YAML::Node& map, const std::string& key, const std::string& path, const std::string& context) {
  if (map[key]) return Status::Ok();
  return NodeError(path, map, "missing required key '" + key + "' in " + context);
}

Status ReadString(const YAML::Node& node, const std::string& path, const std::string& what, std::string* out) {
  if (!node.IsScalar()) return NodeError(path, node, what + " must be a string");
  *out = node.Scalar();
  return Status::Ok();
}

Status ReadNumber(const YAML::Node& node, const std::string& path, const std::string& what, double* out) {
  if (!node.IsScalar()) return NodeError(path, node, what + " must be a number");
  switch (ParseNumber(node.Scalar(), out)) {
    case NumberParse::kOk:
      return Status::Ok();
    case NumberParse::kNaN:
      return NodeError(path, node, what + " is NaN");
    case NumberParse::kInf:
      return NodeError(path, node, what + " is Inf");
    case NumberParse::kNotANumber:
      break;
  }
  return NodeError(path, node, what + ": not a number " + Quote(node.Scalar()));
}

Status ReadNumberList(const YAML::Node& node, const std::string& path, const std::string& what, int expected_size,
                      std::vector<double>* out) {
  if (!node.IsSequence()) return NodeError(path, node, what + " must be a list of numbers");
  if (expected_size >= 0 && node.size() != static_cast<std::size_t>(expected_size)) {
    return NodeError(
        path, node,
        what + " must have " + std::to_string(expected_size) + " numbers, found " + std::to_string(node.size()));
  }
  out->clear();
  for (std::size_t i = 0; i < node.size(); ++i) {
    double value = 0.0;
    const std::string item_what = what + "[" + std::to_string(i) + "]";
    if (Status status = ReadNumber(node[i], path, item_what, &value); !status.ok()) return status;
    out->push_back(value);
  }
  return Status::Ok();
}

Status ReadStringList(const YAML::Node& node, const std::string& path, const std::string& what,
                      std::vector<std::string>* out) {
  if (!node.IsSequence()) return NodeError(path, node, what + " must be a list of strings");
  out->clear();
  for (std::size_t i = 0; i < node.size(); ++i) {
    std::string value;
    const std::string item_what = what + "[" + std::to_string(i) + "]";
    if (Status status = ReadString(node[i], path, item_what, &value); !status.ok()) return status;
    out->push_back(value);
  }
  return Status::Ok();
}

Status ReadNumberMap(const YAML::Node& node, const std::string& path, const std::string& what,
                     std::map<std::string, double>* out) {
  if (!node.IsMap()) return NodeError(path, node, what + " must be a mapping of names to numbers");
  out->clear();
  for (const auto& item : node) {
    if (!item.first.IsScalar()) return NodeError(path, item.first, "non-scalar key in " + what);
    const std::string& key = item.first.Scalar();
    double value = 0.0;
    if (Status status = ReadNumber(item.second, path, what + "." + key, &value); !status.ok()) return status;
    if (!out->emplace(key, value).second) {
      return NodeError(path, item.first, "duplicate key " + Quote(key) + " in " + what);
    }
  }
  return Status::Ok();
}

void EmitNumber(double value, YAML::Emitter* out) { *out << FormatShortest(value); }

void EmitNumberList(const std::vector<double>& values, YAML::Emitter* out) {
  *out << YAML::Flow << YAML::BeginSeq;
  for (double value : values) EmitNumber(value, out);
  *out << YAML::EndSeq;
}

void EmitStringList(const std::vector<std::string>& values, YAML::Emitter* out) {
  *out << YAML::Flow << YAML::BeginSeq;
  for (const std::string& value : values) *out << value;
  *out << YAML::EndSeq;
}

void EmitNumberMap(const std::map<std::string, double>& values, YAML::Emitter* out) {
  *out << YAML::Flow << YAML::BeginMap;
  for (const auto& [key, value] : values) {
    *out << YAML::Key << key << YAML::Value;
    EmitNumber(value, out);
  }
  *out << YAML::EndMap;
}

}  // namespace roamlab::recording::internal
