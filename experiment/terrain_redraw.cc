#include "experiment/terrain_redraw.h"

#include "common/check.h"

namespace roamlab::experiment {

std::string TerrainRedrawProblem(const sim::Scenario& scenario) {
  if (scenario.terrain.type != sim::TerrainOptions::Type::kHills)
    return "world.terrain is flat: only hills have a seed to redraw";
  return "";
}

std::uint64_t RunTerrainSeed(std::uint64_t base, int i) {
  ROAMLAB_CHECK(i >= 0, "a run index is not negative");
  return base + static_cast<std::uint64_t>(i);
}

sim::Scenario WithTerrainSeed(const sim::Scenario& scenario, std::uint64_t terrain_seed) {
  ROAMLAB_CHECK(TerrainRedrawProblem(scenario).empty(), "the scenario's terrain cannot be redrawn");
  sim::Scenario redrawn = scenario;
  redrawn.terrain.seed = terrain_seed;
  return redrawn;
}

}  // namespace roamlab::experiment
