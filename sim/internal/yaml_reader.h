// Private helper of the simulator: strict reading of one YAML file (the scenario) with messages that name the file,
// the line and the key path, e.g. "scenarios/atv_hills.yaml:14: sensors.gps.rate_hz: expected a number, got 'fast'".
// Not part of the public interface.
//
// A YamlReader is sticky: after the first error every further call does nothing, so a loader reads a whole section
// and checks status() once. It also remembers the line of every key it read, so that problems found later (range
// checks on the loaded struct, which only know the key path) can still be reported with their line (LineOf).
#pragma once

#include <cstdint>
#include <initializer_list>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "common/status.h"

namespace roamlab::sim::internal {

// Every number of a scenario is at most this in magnitude (seeds, read as integers, aside).
inline constexpr double kMaxScenarioNumber = 1e9;

class YamlReader {
 public:
  // Parses `path`. A missing file or a syntax error is reported through status().
  explicit YamlReader(std::string path);

  const std::string& path() const { return path_; }
  const YAML::Node& root() const { return root_; }
  bool ok() const { return error_.empty(); }
  Status status() const { return ok() ? Status::Ok() : Status::Error(error_); }

  // Records a problem with `node` at `key` (a dotted key path, "" for the document); keeps only the first one.
  void Fail(const YAML::Node& node, const std::string& key, const std::string& problem);

  // `map` must be a mapping whose keys are in `allowed` (each once); the key path is `key`.
  void CheckKeys(const YAML::Node& map, const std::string& key, std::initializer_list<std::string_view> allowed);
  // Fails naming `parent_key.key` when `map` lacks `key`; returns whether it is present.
  bool Require(const YAML::Node& map, const std::string& parent_key, const std::string& key);

  // Typed reads of map[key] into *out; an absent key leaves *out unchanged (the in-class default). The key path in
  // messages is parent_key + "." + key.
  void Number(const YAML::Node& map, const std::string& parent_key, const std::string& key, double* out);
  void Integer(const YAML::Node& map, const std::string& parent_key, const std::string& key, std::int64_t* out);
  void Unsigned(const YAML::Node& map, const std::string& parent_key, const std::string& key, std::uint64_t* out);
  void String(const YAML::Node& map, const std::string& parent_key, const std::string& key, std::string* out);
  // A string that must be one of `allowed`; another value fails naming them all.
  void OneOf(const YAML::Node& map, const std::string& parent_key, const std::string& key,
             std::initializer_list<std::string_view> allowed, std::string* out);
  // YAML's true / false.
  void Bool(const YAML::Node& map, const std::string& parent_key, const std::string& key, bool* out);
  // A sequence of exactly `size` numbers (any length when size < 0).
  void Numbers(const YAML::Node& map, const std::string& parent_key, const std::string& key, int size,
               std::vector<double>* out);

  // Node-level reads (the node's own key path is `key`).
  void NodeNumber(const YAML::Node& node, const std::string& key, double* out);
  void NodeNumbers(const YAML::Node& node, const std::string& key, int size, std::vector<double>* out);

  // "path:line" of a key that was read, or of the document when the key is unknown.
  std::string LineOf(const std::string& key) const;
  // Remembers where `key` is (done by every read above; public for keys read through other means).
  void Remember(const std::string& key, const YAML::Node& node);

  static std::string Join(const std::string& parent_key, const std::string& key) {
    return parent_key.empty() ? key : parent_key + "." + key;
  }

 private:
  std::string Where(const YAML::Node& node) const;

  std::string path_;
  YAML::Node root_;
  std::string error_;
  std::map<std::string, int> lines_;  // key path -> 1-based line
};

}  // namespace roamlab::sim::internal
