// Fuzzes the recording reader (recording/recording.h): the input is recording.yaml followed by named parts, the
// stream CSVs and ground_truth.tum (fuzz_input.h).
#include "fuzz/fuzz_input.h"
#include "recording/recording.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  roamlab::fuzz::ResetScratch(roamlab::fuzz::SplitInput(data, size, "recording.yaml"), "rec");
  roamlab::fuzz::ExpectOneLineError(roamlab::recording::ReadRecording(roamlab::fuzz::ScratchDirectory() + "/rec"));
  return 0;
}
