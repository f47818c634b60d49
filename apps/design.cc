#include "apps/design.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>

#include "apps/cli.h"
#include "common/progress.h"

namespace roamlab::apps {
namespace {

// "NAME=STD" into targets; the problem naming the text, or empty.
std::string ParseTargets(const std::vector<std::string>& texts, std::map<std::string, double>* targets) {
  for (const std::string& text : texts) {
    const std::size_t eq = text.find('=');
    if (eq == std::string::npos || eq == 0) return "--target '" + text + "': expected NAME=STD";
    const std::string value = text.substr(eq + 1);
    char* end = nullptr;
    const double std = std::strtod(value.c_str(), &end);
    if (value.empty() || *end != '\0') return "--target '" + text + "': '" + value + "' is not a number";
    if (!targets->emplace(text.substr(0, eq), std).second)
      return "--target '" + text + "': " + text.substr(0, eq) + " given twice";
  }
  return "";
}

// A {min, max} option into two limits; the problem, or empty.
std::string ParseRange(const std::vector<double>& range, const char* option, double* min, double* max) {
  if (range.empty()) return "";
  if (range.size() != 2) return std::string(option) + ": expected MIN MAX";
  *min = range[0];
  *max = range[1];
  return "";
}

void PrintTable(const experiment::DesignResult& result) {
  const experiment::DesignCandidate& best = result.candidates[static_cast<std::size_t>(result.best)];
  int feasible = 0;
  for (const auto& c : result.candidates) feasible += c.infeasible.empty() ? 1 : 0;
  std::printf(
      "%zu drives tried (%d feasible); the best (#%d, %s): %s; %.0f m, roll %.1f deg, pitch %.1f deg, side slip "
      "%.2f m/s, lateral acceleration %.2f m/s^2, velocity error %.2f m/s\n",
      result.candidates.size(), feasible, result.best, best.stage.c_str(), result.best_drive.c_str(), best.distance_m,
      best.max_roll_deg, best.max_pitch_deg, best.max_side_slip_mps, best.max_lateral_accel_mps2,
      best.max_velocity_error_mps);
  std::printf("objective (max CRB std / target) %.3g, set by %s; start drive's %.3g\n\n", best.objective,
              best.worst.c_str(), result.candidates.front().objective);
  std::printf("| component | predicted std | target | ratio |\n|---|---|---|---|\n");
  for (const auto& [label, std] : best.crb_std) {
    const auto target = result.targets.find(label.substr(0, label.find('[')));
    if (target == result.targets.end()) {
      std::printf("| %s | %.3g | - | - |\n", label.c_str(), std);
      continue;
    }
    std::printf("| %s | %.3g | %.3g | %.2f |\n", label.c_str(), std, target->second, std / target->second);
  }
}

}  // namespace

int RunDesign(const DesignArgs& args) {
  experiment::DesignRequest request = args;
  if (std::string p = ParseTargets(args.target_texts, &request.targets); !p.empty())
    return BadInput(args.err, "design", p);
  if (std::string p = ParseRange(args.speed_range_mps, "--speed-range", &request.limits.min_speed_mps,
                                 &request.limits.max_speed_mps);
      !p.empty())
    return BadInput(args.err, "design", p);
  if (std::string p =
          ParseRange(args.period_range_s, "--period-range", &request.limits.min_period_s, &request.limits.max_period_s);
      !p.empty())
    return BadInput(args.err, "design", p);
  ProgressMeter meter("design: drives", &std::cerr);
  if (!args.quiet) request.progress = [&meter](double fraction) { meter.Update(fraction); };
  experiment::DesignResult result;
  const experiment::Outcome outcome = experiment::DesignToFile(request, &result);
  meter.Finish();
  if (!outcome.ok()) return Exit(args.err, "design", outcome);
  if (args.quiet) return 0;
  PrintTable(result);
  std::printf("\nwrote %s and design.json beside it\n", args.out.c_str());
  return 0;
}

}  // namespace roamlab::apps
