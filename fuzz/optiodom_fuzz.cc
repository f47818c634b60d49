// Fuzzes the OptiOdom importer (importers/optiodom.h): the input is the run CSV followed by a part
// "%%%% set_metadata.csv" (fuzz_input.h).
#include "fuzz/fuzz_input.h"
#include "importers/optiodom.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  roamlab::fuzz::ResetScratch(roamlab::fuzz::SplitInput(data, size, "set_run-01.csv"));
  const std::string directory = roamlab::fuzz::ScratchDirectory();
  roamlab::fuzz::ExpectOneLineError(
      roamlab::importers::ImportOptiOdom(directory + "/set_run-01.csv", directory + "/set_metadata.csv"));
  return 0;
}
