// A terrain of its own for every run of a Monte-Carlo experiment (`roamlab montecarlo --calibration-consistency
// --redraw-terrain`): run i drives the scenario's hills drawn by the terrain generator (sim/terrain.h) with seed
// terrain_seed_base + i, everything else (relief, wavelengths, size, friction, drive, sensors) the scenario's. The
// noise seed stays apart (experiment/montecarlo.h), so the two draws are independent.
#pragma once

#include <cstdint>
#include <string>

#include "sim/scenario.h"

namespace roamlab::experiment {

// Run i draws terrain seed kDefaultTerrainSeedBase + i unless told otherwise (the noise seeds' default base too).
inline constexpr std::uint64_t kDefaultTerrainSeedBase = 1000;

// Why the scenario's terrain cannot be redrawn ("" when it can): a flat floor has no generator to seed.
std::string TerrainRedrawProblem(const sim::Scenario& scenario);

// Run i's terrain seed: base + i.
std::uint64_t RunTerrainSeed(std::uint64_t base, int i);

// The scenario with its hills drawn from `terrain_seed` (precondition, CHECK: TerrainRedrawProblem is "").
sim::Scenario WithTerrainSeed(const sim::Scenario& scenario, std::uint64_t terrain_seed);

}  // namespace roamlab::experiment
