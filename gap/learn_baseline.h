// Learning the baseline of the diagnosis (gap/diagnose.h, Baseline): the levels and candidate fits the nominal model
// reaches on a nominal simulation of the same robot and drive, without any hidden effect.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "common/status.h"
#include "estimator/config.h"
#include "gap/diagnose.h"
#include "sim/scenario.h"
#include "sim/simulator.h"

namespace roamlab::gap {

// The noise seed of the nominal simulation `roamlab diagnose` and gap-benchmark learn the baseline from (a seed no
// test or benchmark case uses).
inline constexpr std::uint64_t kDefaultBaselineSeed = 900001;

struct LearnBaselineOptions {
  std::uint64_t seed = kDefaultBaselineSeed;  // noise seed of the nominal simulation
  // The diagnosis of the nominal simulation: these options with max_effects = 0 and no baseline.
  DiagnoseOptions diagnose;
  // Receives "baseline: simulating ..." before the simulation and "baseline: diagnosing ..." before the diagnosis.
  std::function<void(const std::string&)> progress;
};

struct LearnedBaseline {
  Baseline baseline;
  sim::Simulation simulation;  // the nominal simulation (its truth, for a caller that scores against it)
};

// Simulates `nominal` (its effects removed, its duration as given) with options.seed, diagnoses the simulation with
// `config` scoring the candidates only, and takes the baseline from it (BaselineFrom). Errors: "nominal simulation:
// ..." when the simulation fails, "baseline: ..." when the diagnosis does.
Result<LearnedBaseline> LearnBaseline(const sim::Scenario& nominal, const estimator::EstimatorConfig& config,
                                      const LearnBaselineOptions& options = {});

}  // namespace roamlab::gap
