#include "recording/truth.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <system_error>

#include <yaml-cpp/yaml.h>

#include "common/atomic_file.h"
#include "recording/internal/stream_types.h"
#include "recording/internal/text_io.h"
#include "recording/internal/yaml_util.h"

namespace roamlab::recording {
namespace {

namespace fs = std::filesystem;
using internal::CheckKeys;
using internal::ReadNumber;
using internal::ReadNumberList;
using internal::ReadNumberMap;
using internal::ReadString;
using internal::RequireKey;

// calibration: {name: number | [numbers]}; a single number is read as a vector of size one.
Status ParseCalibration(const YAML::Node& node, const std::string& path,
                        std::map<std::string, std::vector<double>>* out) {
  if (!node.IsMap()) return Status::Error(internal::Where(path, node) + ": calibration must be a mapping");
  for (const auto& item : node) {
    std::string name;
    if (Status status = ReadString(item.first, path, "calibration key", &name); !status.ok()) return status;
    std::vector<double> values(1);
    const std::string what = "calibration '" + name + "'";
    const Status status = item.second.IsScalar() ? ReadNumber(item.second, path, what, &values[0])
                                                 : ReadNumberList(item.second, path, what, -1, &values);
    if (!status.ok()) return status;
    if (values.empty()) return Status::Error(internal::Where(path, item.second) + ": " + what + " is empty");
    if (!out->emplace(name, values).second) {
      return Status::Error(internal::Where(path, item.first) + ": duplicate key '" + name + "' in calibration");
    }
  }
  return Status::Ok();
}

// effects: [{name: ..., parameters: {...}}, ...].
Status ParseEffects(const YAML::Node& node, const std::string& path, std::vector<Effect>* out) {
  if (!node.IsSequence()) return Status::Error(internal::Where(path, node) + ": effects must be a list");
  for (std::size_t i = 0; i < node.size(); ++i) {
    const YAML::Node entry = node[i];
    const std::string context = "effects[" + std::to_string(i) + "]";
    if (Status status = CheckKeys(entry, path, context, {"name", "parameters"}); !status.ok()) return status;
    if (Status status = RequireKey(entry, "name", path, context); !status.ok()) return status;
    Effect effect;
    if (Status status = ReadString(entry["name"], path, context + ".name", &effect.name); !status.ok()) return status;
    if (entry["parameters"]) {
      const std::string what = "parameters of effect '" + effect.name + "'";
      if (Status status = ReadNumberMap(entry["parameters"], path, what, &effect.parameters); !status.ok()) {
        return status;
      }
    }
    out->push_back(std::move(effect));
  }
  return Status::Ok();
}

// replay: {noise_free: true, drive: ..., start: ...}.
Status ParseReplay(const YAML::Node& node, const std::string& path, std::optional<ReplayNote>* out) {
  if (Status status = CheckKeys(node, path, "replay", {"noise_free", "drive", "start"}); !status.ok()) return status;
  ReplayNote note;
  if (node["drive"]) {
    if (Status status = ReadString(node["drive"], path, "replay.drive", &note.drive); !status.ok()) return status;
  }
  if (node["start"]) {
    if (Status status = ReadString(node["start"], path, "replay.start", &note.start); !status.ok()) return status;
  }
  *out = note;
  return Status::Ok();
}

// Refuses what ReadTruth would refuse: empty or non-finite values, effects without a name.
Status ValidateForWrite(const Truth& truth, const std::string& path) {
  for (const auto& [name, values] : truth.calibration) {
    if (values.empty()) return Status::Error(path + ": calibration '" + name + "' is empty");
    if (!std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); })) {
      return Status::Error(path + ": calibration '" + name + "' is not finite");
    }
  }
  for (const Effect& effect : truth.effects) {
    if (effect.name.empty()) return Status::Error(path + ": an effect has no name");
    for (const auto& [key, value] : effect.parameters) {
      if (!std::isfinite(value)) {
        return Status::Error(path + ": effect '" + effect.name + "': " + key + " is not finite");
      }
    }
  }
  return Status::Ok();
}

// The text of truth.yaml: keys in a fixed order, numbers as their shortest round-trip text.
std::string EmitTruth(const Truth& truth) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  // Calibration: one key per parameter, a single value as a number, longer ones as a list.
  out << YAML::Key << "calibration" << YAML::Value;
  if (truth.calibration.empty()) out << YAML::Flow;  // "{}" on the same line
  out << YAML::BeginMap;
  for (const auto& [name, values] : truth.calibration) {
    out << YAML::Key << name << YAML::Value;
    if (values.size() == 1) {
      internal::EmitNumber(values[0], &out);
    } else {
      internal::EmitNumberList(values, &out);
    }
  }
  out << YAML::EndMap;
  // Effects in the given order.
  out << YAML::Key << "effects" << YAML::Value;
  if (truth.effects.empty()) out << YAML::Flow;
  out << YAML::BeginSeq;
  for (const Effect& effect : truth.effects) {
    out << YAML::BeginMap << YAML::Key << "name" << YAML::Value << effect.name;
    out << YAML::Key << "parameters" << YAML::Value;
    internal::EmitNumberMap(effect.parameters, &out);
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
  if (truth.replay) {
    out << YAML::Key << "replay" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "noise_free" << YAML::Value << true;
    out << YAML::Key << "drive" << YAML::Value << truth.replay->drive;
    out << YAML::Key << "start" << YAML::Value << truth.replay->start;
    out << YAML::EndMap;
  }
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace

Result<Truth> ReadTruth(const std::string& directory) {
  const std::string path = (fs::path(directory) / internal::kTruthYamlFile).string();
  YAML::Node root;
  if (Status status = internal::LoadYamlFile(path, &root); !status.ok()) return status;
  // An empty file is an empty truth; anything else must be a mapping with known keys.
  Truth truth;
  if (root.IsNull()) return truth;
  if (Status status = CheckKeys(root, path, "the top level", {"calibration", "effects", "replay"}); !status.ok())
    return status;
  if (root["calibration"]) {
    if (Status status = ParseCalibration(root["calibration"], path, &truth.calibration); !status.ok()) return status;
  }
  if (root["effects"]) {
    if (Status status = ParseEffects(root["effects"], path, &truth.effects); !status.ok()) return status;
  }
  if (root["replay"]) {
    if (Status status = ParseReplay(root["replay"], path, &truth.replay); !status.ok()) return status;
  }
  return truth;
}

Status WriteTruth(const Truth& truth, const std::string& directory) {
  const std::string path = (fs::path(directory) / internal::kTruthYamlFile).string();
  if (Status status = ValidateForWrite(truth, path); !status.ok()) return status;
  // The directory may not exist yet (truth is written beside a fresh recording).
  std::error_code error;
  fs::create_directories(directory, error);
  if (error) return Status::Error(directory + ": cannot create directory: " + error.message());
  return WriteFileAtomic(path, EmitTruth(truth));
}

}  // namespace roamlab::recording
