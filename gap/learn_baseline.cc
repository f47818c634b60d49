#include "gap/learn_baseline.h"

#include <sstream>

namespace roamlab::gap {

Result<LearnedBaseline> LearnBaseline(const sim::Scenario& nominal, const estimator::EstimatorConfig& config,
                                      const LearnBaselineOptions& options) {
  const auto say = [&](const std::string& line) {
    if (options.progress) options.progress(line);
  };
  sim::Scenario scenario = nominal;
  scenario.effects.clear();
  sim::SimulateOptions sim_options;
  sim_options.seed = options.seed;
  std::ostringstream duration;
  duration.precision(4);
  duration << scenario.duration_s;
  say("baseline: simulating the nominal scenario (" + duration.str() + " s, seed " + std::to_string(options.seed) +
      ")");
  auto simulated = sim::Simulate(scenario, sim_options);
  if (!simulated.ok()) return Status::Error("nominal simulation: " + simulated.status().message());
  DiagnoseOptions learn = options.diagnose;
  learn.baseline = nullptr;
  learn.max_effects = 0;
  say("baseline: diagnosing the nominal simulation");
  auto learned = Diagnose(config, simulated.value().recording, learn);
  if (!learned.ok()) return Status::Error("baseline: " + learned.status().message());
  return LearnedBaseline{BaselineFrom(learned.value()), std::move(simulated).value()};
}

}  // namespace roamlab::gap
