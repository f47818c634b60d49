// Fuzzes the scenario loader (sim/scenario.h): the input is a scenario file in scenarios/ of a scratch directory whose
// models/ links to the repository's, so that "../models/atv.xml" resolves; further parts (fuzz_input.h) are files
// beside it.
#include "fuzz/fuzz_input.h"
#include "sim/scenario.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string& directory = roamlab::fuzz::ScratchDirectory({{"models", ROAMLAB_SOURCE_DIR "/models"}});
  roamlab::fuzz::ResetScratch(roamlab::fuzz::SplitInput(data, size, "scenario.yaml"), "scenarios");
  roamlab::fuzz::ExpectOneLineError(roamlab::sim::LoadScenario(directory + "/scenarios/scenario.yaml"));
  return 0;
}
