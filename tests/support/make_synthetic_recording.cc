// Writes a synthetic kinematic ATV recording (synthetic.h) with its truth.yaml: the stand-in for `roamlab simulate`
// until the MuJoCo simulator exists. Usage: make_synthetic_recording OUT_DIR [DURATION_S] [SEED]
#include <cstdio>
#include <cstdlib>
#include <string>

#include "recording/truth.h"
#include "tests/support/synthetic.h"

int main(int argc, char** argv) {
  if (argc < 2 || argc > 4) {
    std::fprintf(stderr, "usage: make_synthetic_recording OUT_DIR [DURATION_S] [SEED]\n");
    return 2;
  }
  roamlab::testing::SyntheticOptions options;
  if (argc > 2) options.duration_s = std::atof(argv[2]);
  if (argc > 3) options.seed = static_cast<std::uint32_t>(std::strtoul(argv[3], nullptr, 10));
  const std::string invalid = options.Validate();
  if (!invalid.empty()) {
    std::fprintf(stderr, "make_synthetic_recording: %s\n", invalid.c_str());
    return 2;
  }
  const auto synthetic = roamlab::testing::MakeAtvRecording(options);
  roamlab::Status status = roamlab::recording::WriteRecording(synthetic.recording, argv[1]);
  if (status.ok()) status = roamlab::recording::WriteTruth(synthetic.truth, argv[1]);
  if (!status.ok()) {
    std::fprintf(stderr, "make_synthetic_recording: %s\n", status.message().c_str());
    return 1;
  }
  std::printf("wrote %s (%.1f s synthetic ATV drive, seed %u)\n", argv[1], options.duration_s, options.seed);
  return 0;
}
