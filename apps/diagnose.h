// `roamlab diagnose --real REC --scenario SCENARIO.yaml --out DIR`: the reality-gap diagnosis of a recording against
// the nominal scenario (gap/diagnose.h). Reads REC's streams only (never truth.yaml). Unless --no-baseline, first
// simulates the nominal scenario (its effects removed, the recording's duration, seed --baseline-seed) and diagnoses
// that, to learn the levels and candidate gains the nominal model reaches on MuJoCo data without any hidden effect
// (gap/learn_baseline.h). With a scenario, the nominal scenario is simulated again without noise, as believed and with
// the accepted effects, and compared with the recording's held-out part (gap/resimulate.h; gap.json "simulation").
// Writes DIR/gap.json, DIR/report.md, the patches and the figures (gap/report.h).
// Exit codes: 0 done, 2 bad input (one line naming the file), 1 a failure at run time.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>

#include "gap/learn_baseline.h"

namespace roamlab::apps {

struct DiagnoseArgs {
  std::string recording;                 // --real REC
  std::string scenario;                  // --scenario SCENARIO.yaml (the nominal robot); "" for a robot without a
                                         // MuJoCo twin: then config and no_baseline are required
  std::string config;                    // --config EST.yaml: nominal estimator configuration (default: from the
                                         // scenario, gap::NominalConfig)
  std::string out;
  bool no_baseline = false;
  std::uint64_t baseline_seed = gap::kDefaultBaselineSeed;   // noise seed of the nominal simulation
  std::optional<double> max_shift_s;     // --max-shift: the time-shift search range (default gap::DiagnoseOptions')
  bool no_plots = false;
  bool quiet = false;
  std::ostream* err = nullptr;           // receives the one-line error; nullptr: stderr
};
int RunDiagnose(const DiagnoseArgs& args);

}  // namespace roamlab::apps
