// Fuzzes the regression suite loader (regress/suite.h): the input is a suite file in regression/ of a scratch
// directory whose scenarios/, configs/, models/ and examples/ link to the repository's, so that the project's own
// suite entries resolve; further parts (fuzz_input.h) are files beside it.
#include "fuzz/fuzz_input.h"
#include "regress/suite.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string& directory = roamlab::fuzz::ScratchDirectory({{"scenarios", ROAMLAB_SOURCE_DIR "/scenarios"},
                                                                  {"configs", ROAMLAB_SOURCE_DIR "/configs"},
                                                                  {"models", ROAMLAB_SOURCE_DIR "/models"},
                                                                  {"examples", ROAMLAB_SOURCE_DIR "/examples"}});
  roamlab::fuzz::ResetScratch(roamlab::fuzz::SplitInput(data, size, "suite.yaml"), "regression");
  roamlab::fuzz::ExpectOneLineError(roamlab::regress::LoadSuite(directory + "/regression/suite.yaml"));
  return 0;
}
