// Fuzzes the estimator configuration parser (estimator/config.h) on the input as YAML text.
#include <cstddef>
#include <cstdint>
#include <string>

#include "estimator/config.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  roamlab::fuzz::ExpectOneLineError(roamlab::estimator::ParseEstimatorConfig(text, "fuzz.yaml"));
  return 0;
}
