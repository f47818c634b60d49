// Shared helpers of the diagnosis tests.
#pragma once

#include <cstdint>
#include <utility>

#include <gtest/gtest.h>

#include "sim/simulator.h"

namespace roamlab::gap::testing {

// The scenario simulated with noise seed `seed` (it must succeed).
inline sim::Simulation SimulatedWithSeed(const sim::Scenario& scenario, std::uint64_t seed) {
  sim::SimulateOptions options;
  options.seed = seed;
  auto simulation = sim::Simulate(scenario, options);
  EXPECT_TRUE(simulation.ok()) << simulation.status().message();
  return std::move(simulation).value();
}

}  // namespace roamlab::gap::testing
