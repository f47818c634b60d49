// What the batch tests share: the roamlab command, a 6 s ATV drive (the scenario with its model path made absolute)
// and file helpers.
#pragma once

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <nlohmann/json.hpp>

#include "tests/recording/temp_dir.h"
#include "tests/support/paths.h"

namespace roamlab::testing {

// Runs roamlab with `args` in `dir` (relative paths are DIR's).
inline CommandRun Roamlab(const std::string& args, const std::filesystem::path& dir) {
  return RunCommand("cd '" + dir.string() + "' && " + std::string(ROAMLAB_BINARY) + " " + args, dir.string());
}

inline std::string SlurpFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

inline nlohmann::json ReadJson(const std::filesystem::path& path) {
  return nlohmann::json::parse(SlurpFile(path), nullptr, false);
}

// scenarios/atv_hills.yaml shortened to `duration_s`, written to DIR/atv_short.yaml; its path, "" when the scenario
// did not have the expected lines.
inline std::string WriteShortAtvScenario(const std::filesystem::path& dir, const std::string& duration_s) {
  std::string scenario = SlurpFile(roamlab::testing::SourceDir() + "/scenarios/atv_hills.yaml");
  const std::string from = "duration_s: 30.0", model = "../models/atv.xml";
  if (scenario.find(from) == std::string::npos || scenario.find(model) == std::string::npos) return "";
  scenario.replace(scenario.find(from), from.size(), "duration_s: " + duration_s);
  scenario.replace(scenario.find(model), model.size(), roamlab::testing::SourceDir() + "/models/atv.xml");
  const std::string path = (dir / "atv_short.yaml").string();
  std::ofstream(path) << scenario;
  return path;
}

// runs.json without each run's tracking time (the one value that depends on the machine).
inline nlohmann::json RunsWithoutTimes(const std::filesystem::path& runs_json) {
  nlohmann::json runs = ReadJson(runs_json);
  if (!runs.is_object() || !runs.contains("runs")) return runs;
  for (nlohmann::json& run : runs["runs"]) run.erase("track_seconds");
  return runs;
}

}  // namespace roamlab::testing
