// Shared fixtures of the simulator tests: the real scenario and model, shortened, and the ATV model with extra MJCF
// (sites and MuJoCo's own sensors) spliced in.
#pragma once

#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "sim/scenario.h"
#include "tests/support/paths.h"

namespace roamlab::sim::testing {

inline std::string SourcePath(const std::string& relative) { return roamlab::testing::SourceDir() + "/" + relative; }

inline std::string ReadText(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  std::ostringstream content;
  content << file.rdbuf();
  return content.str();
}

// scenarios/atv_hills.yaml, loaded (it must load) and shortened to `duration_s`.
inline Scenario AtvHills(double duration_s) {
  auto scenario = LoadScenario(SourcePath("scenarios/atv_hills.yaml"));
  EXPECT_TRUE(scenario.ok()) << scenario.status().message();
  Scenario s = scenario.value();
  s.duration_s = duration_s;
  return s;
}

// models/atv.xml with `chassis_xml` added next to the site "odom" (so on the chassis body), `top_level_xml` added
// before </mujoco> and `option_attributes` added to its <option> element.
inline std::string AtvModelWith(const std::string& chassis_xml, const std::string& top_level_xml,
                                const std::string& option_attributes = "") {
  std::string xml = ReadText(SourcePath("models/atv.xml"));
  const std::size_t site = xml.find("<site name=\"odom\"");
  const std::size_t end = xml.rfind("</mujoco>");
  const std::size_t option = xml.find("<option ");
  EXPECT_NE(site, std::string::npos);
  EXPECT_NE(end, std::string::npos);
  EXPECT_NE(option, std::string::npos);
  xml.insert(end, top_level_xml + "\n");
  xml.insert(site, chassis_xml + "\n      ");
  xml.insert(option + 8, option_attributes + " ");
  return xml;
}

}  // namespace roamlab::sim::testing
