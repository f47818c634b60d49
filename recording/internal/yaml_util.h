// Private helpers of the recording module for strict YAML reading (unknown and duplicate keys are errors, numbers must
// be finite) and deterministic writing. Every error is one line "<file>:<line>: <problem>" (1-based line; without the
// line when yaml-cpp has no position for the node). Not part of the public interface.
#pragma once

#include <initializer_list>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "common/status.h"

namespace roamlab::recording::internal {

// "<path>:<line>" for the node, or "<path>" when the node carries no position.
std::string Where(const std::string& path, const YAML::Node& node);

// Reads and parses a YAML file. Syntax errors become "<path>:<line>:<column>: <yaml-cpp message>".
Status LoadYamlFile(const std::string& path, YAML::Node* root);

// Checks that `map` is a mapping whose keys are all in `allowed`, each at most once. `context` completes the message:
// "<path>:<line>: unknown key 'foo' in <context>".
Status CheckKeys(const YAML::Node& map, const std::string& path, const std::string& context,
                 std::initializer_list<std::string_view> allowed);

// "<path>:<line>: missing required key '<key>' in <context>" when `map` has no such key.
Status RequireKey(const YAML::Node& map, const std::string& key, const std::string& path, const std::string& context);

// Typed readers. `what` names the value in messages, e.g. "rate_hz of stream 'gps'".
Status ReadString(const YAML::Node& node, const std::string& path, const std::string& what, std::string* out);
Status ReadNumber(const YAML::Node& node, const std::string& path, const std::string& what, double* out);
// A sequence of numbers; `expected_size` < 0 accepts any length.
Status ReadNumberList(const YAML::Node& node, const std::string& path, const std::string& what, int expected_size,
                      std::vector<double>* out);
Status ReadStringList(const YAML::Node& node, const std::string& path, const std::string& what,
                      std::vector<std::string>* out);
// A mapping string -> number (nominal geometry, noise, attributes, effect parameters).
Status ReadNumberMap(const YAML::Node& node, const std::string& path, const std::string& what,
                     std::map<std::string, double>* out);

// Writers: numbers go out as their shortest round-trip text, containers in flow style ("{a: 1, b: 2}", "[1, 2]").
void EmitNumber(double value, YAML::Emitter* out);
void EmitNumberList(const std::vector<double>& values, YAML::Emitter* out);
void EmitStringList(const std::vector<std::string>& values, YAML::Emitter* out);
void EmitNumberMap(const std::map<std::string, double>& values, YAML::Emitter* out);

}  // namespace roamlab::recording::internal
