#include "apps/commands.h"

#include <cmath>
#include <cstdio>
#include <iostream>

#include "apps/cli.h"
#include "common/progress.h"
#include "estimator/calibration.h"
#include "estimator/covariance.h"
#include "estimator/tracking_io.h"
#include "experiment/steps.h"

namespace roamlab::apps {
namespace {

// "a, b, c" with `format` for each value; with `dash_non_finite`, "-" for the values that are not finite.
std::string Values(const Eigen::VectorXd& v, const char* format, bool dash_non_finite) {
  std::string out;
  for (int i = 0; i < v.size(); ++i) {
    char buf[64];
    std::snprintf(buf, sizeof buf, format, v[i]);
    out += i ? ", " : "";
    out += dash_non_finite && !std::isfinite(v[i]) ? "-" : buf;
  }
  return out;
}

// The human-readable table of a calibration.
void PrintCalibration(const estimator::CalibrationResult& r, const std::string& json_path) {
  std::printf("%-28s %-13s %s\n", "parameter", "observability", "estimate (std)");
  for (const auto& p : r.parameters)
    std::printf("%-28s %-13s [%s] (%s)\n", p.name.c_str(), estimator::ObservabilityName(p.observability),
                Values(p.estimate, "%.5g", false).c_str(), Values(p.std, "%.2g", true).c_str());
  for (const auto& c : r.correlations)
    std::printf("strongly correlated: %s ~ %s (rho %.3f)\n", c.a.c_str(), c.b.c_str(), c.rho);
  std::printf("std: %s; cost %.6g -> %.6g in %d iterations, %.2f s; wrote %s\n", r.std_method.c_str(), r.initial_cost,
              r.final_cost, r.iterations, r.seconds, json_path.c_str());
}

}  // namespace

int RunCalibrate(const CalibrateArgs& args) {
  experiment::CalibrateRequest request = args;
  ProgressMeter meter("calibrate", &std::cerr);
  if (!args.quiet) request.progress = [&meter](const std::string& line) { meter.Note(line); };
  request.warning = [](const std::string& line) { std::cerr << "roamlab calibrate: warning: " << line << "\n"; };
  estimator::CalibrationResult result;
  const experiment::Outcome outcome = experiment::CalibrateToDirectory(request, &result);
  if (!outcome.ok()) return Exit(args.err, "calibrate", outcome);
  if (!args.quiet) PrintCalibration(result, args.out + "/calibration.json");
  return 0;
}

int RunTrack(const TrackArgs& args) {
  experiment::TrackRequest request = args;
  ProgressMeter meter("track", &std::cerr);
  if (!args.quiet) request.progress = [&meter](double fraction) { meter.Update(fraction); };
  request.warning = [](const std::string& line) { std::cerr << "roamlab track: warning: " << line << "\n"; };
  estimator::TrackingResult r;
  const experiment::Outcome outcome = experiment::TrackToDirectory(request, &r);
  meter.Finish();
  if (!outcome.ok()) return Exit(args.err, "track", outcome);
  if (args.quiet) return 0;
  std::printf("tracked %zu poses, %d updates (mean %.2f ms, max %.2f ms), %d rejected, %.1fx real time; wrote %s\n",
              r.trajectory.size(), r.updates, 1e3 * r.mean_update_s, 1e3 * r.max_update_s,
              estimator::RejectedMeasurements(r), estimator::RealtimeFactor(r), (args.out + "/trajectory.tum").c_str());
  return 0;
}

}  // namespace roamlab::apps
