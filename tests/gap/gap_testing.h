// Shared helpers of the diagnosis tests.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "gap/diagnose.h"
#include "gap/learn_baseline.h"
#include "gap/nominal_config.h"
#include "sim/simulator.h"
#include "tests/support/paths.h"

namespace roamlab::gap::testing {

// The scenario simulated with noise seed `seed` (it must succeed).
inline sim::Simulation SimulatedWithSeed(const sim::Scenario& scenario, std::uint64_t seed) {
  sim::SimulateOptions options;
  options.seed = seed;
  auto simulation = sim::Simulate(scenario, options);
  EXPECT_TRUE(simulation.ok()) << simulation.status().message();
  return std::move(simulation).value();
}

// A nominal scenario with its nominal model and the baseline learned on its simulation with noise seed
// kDefaultBaselineSeed (a seed no test case uses), as `roamlab diagnose` learns it (LearnBaseline).
struct LearnedNominal {
  sim::Scenario scenario;
  estimator::EstimatorConfig config;
  Baseline baseline;
};

// Loads SourceDir()/`scenario_path` and learns its baseline; nullptr (with a test failure) when that fails.
// `adjust`, when given, changes the nominal configuration (what the user believes) before the baseline is learned.
inline std::unique_ptr<LearnedNominal> LearnNominal(
    const std::string& scenario_path, const std::function<void(estimator::EstimatorConfig*)>& adjust = {}) {
  auto loaded = sim::LoadScenario(roamlab::testing::SourceDir() + "/" + scenario_path);
  EXPECT_TRUE(loaded.ok()) << loaded.status().message();
  if (!loaded.ok()) return nullptr;
  auto out = std::make_unique<LearnedNominal>();
  out->scenario = loaded.value();
  auto config = NominalConfig(out->scenario);
  EXPECT_TRUE(config.ok()) << config.status().message();
  if (!config.ok()) return nullptr;
  out->config = config.value();
  if (adjust) adjust(&out->config);
  auto learned = LearnBaseline(out->scenario, out->config);
  EXPECT_TRUE(learned.ok()) << learned.status().message();
  if (!learned.ok()) return nullptr;
  out->baseline = learned.value().baseline;
  return out;
}

// The nominal scenario with `effects` hidden, simulated with noise seed `seed` and diagnosed against the baseline.
inline Result<Diagnosis> DiagnoseHidden(const LearnedNominal& nominal, const std::vector<sim::EffectOptions>& effects,
                                        std::uint64_t seed) {
  sim::Scenario hidden = nominal.scenario;
  hidden.effects = effects;
  DiagnoseOptions options;
  options.baseline = &nominal.baseline;
  return Diagnose(nominal.config, SimulatedWithSeed(hidden, seed).recording, options);
}

}  // namespace roamlab::gap::testing
