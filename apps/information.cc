#include "apps/information.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "apps/cli.h"
#include "common/progress.h"

namespace roamlab::apps {
namespace {

// How many of the windows with the largest shares the table lists.
constexpr int kTopWindows = 3;
// The table's "measured by" lists the streams whose measured share is at least this in size.
constexpr double kMeasuredShown = 0.05;

std::string Format(const char* format, double value) {
  if (!std::isfinite(value)) return "-";
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, value);
  return buffer;
}

// The truth of one component: the Euclidean parameter's entry; "-" for a rotation's tangent component.
std::string TruthText(const estimator::InformationParameter& p, int k) {
  if (!p.has_truth) return "(none)";
  if (p.manifold.kind() != estimator::ManifoldKind::kEuclidean) return "-";
  return Format("%.4g", p.truth[k]);
}

// "gps 100, odometer 12" for the streams whose measured share is at least kMeasuredShown in size.
std::string MeasuredBy(const estimator::InformationComponent& c) {
  std::string out;
  for (const auto& [stream, share] : c.measured_by)
    if (std::abs(share) >= kMeasuredShown) out += (out.empty() ? "" : ", ") + stream + " " + Format("%.0f", 100 * share);
  return out.empty() ? "-" : out;
}

// "12-13 s 9%, 5-6 s 7%, ..." for the windows with the largest shares.
std::string TopWindows(const estimator::InformationComponent& c, double window_s) {
  std::vector<int> order(c.by_window.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = static_cast<int>(k);
  if (order.empty() || !std::isfinite(c.by_window.front())) return "-";
  std::sort(order.begin(), order.end(), [&](int a, int b) { return c.by_window[a] > c.by_window[b]; });
  std::string out;
  for (int i = 0; i < kTopWindows && i < static_cast<int>(order.size()); ++i) {
    const int k = order[i];
    out += (i ? ", " : "") + Format("%g", k * window_s) + "-" + Format("%g", (k + 1) * window_s) + " s " +
           Format("%.0f%%", 100.0 * c.by_window[k]);
  }
  return out;
}

void PrintTable(const experiment::InformationRun& run) {
  const estimator::InformationResult& r = run.result;
  std::printf("Cramer-Rao bound at the truth (noise-free drive, %d poses, %d factors); per stream the share of each "
              "component's CRB variance its noise causes [%%], the streams that measure it (measured share [%%]) and the "
              "windows (%g s) whose factors carry the largest variance shares\n\n",
              r.poses, r.factors, r.window_s);
  std::printf("| component | truth | CRB std | observability |");
  for (const std::string& s : r.streams) std::printf(" %s |", s.c_str());
  std::printf(" measured by | largest windows |\n|---|---|---|---|---|");
  for (std::size_t s = 0; s < r.streams.size(); ++s) std::printf("---|");
  std::printf("---|\n");
  for (const estimator::InformationParameter& p : r.parameters) {
    for (int k = 0; k < p.manifold.tangent_dim(); ++k) {
      const estimator::InformationComponent& c = r.components[static_cast<std::size_t>(p.first_component + k)];
      std::printf("| %s | %s | %s | %s |", c.label.c_str(), TruthText(p, k).c_str(),
                  Format("%.3g", c.crb_std).c_str(), estimator::ObservabilityName(c.observability));
      for (const std::string& s : r.streams) {
        const auto it = c.by_stream.find(s);
        std::printf(" %s |", Format("%.1f", it == c.by_stream.end() ? 0.0 : 100.0 * it->second).c_str());
      }
      std::printf(" %s | %s |\n", MeasuredBy(c).c_str(), TopWindows(c, r.window_s).c_str());
    }
  }
  std::printf("\n");
  if (r.directions.empty()) std::printf("no weak or unobservable direction\n");
  for (const estimator::InformationDirection& d : r.directions)
    std::printf("%s direction (relative information %.2g): %s\n", estimator::ObservabilityName(d.observability),
                d.eigenvalue, d.name.c_str());
}

}  // namespace

int RunInformation(const InformationArgs& args) {
  experiment::InformationRequest request = args;
  ProgressMeter meter("information: simulate", &std::cerr);
  if (!args.quiet) request.progress = [&meter](double fraction) { meter.Update(fraction); };
  experiment::InformationRun run;
  const experiment::Outcome outcome = experiment::InformationToDirectory(request, &run);
  meter.Finish();
  if (!outcome.ok()) return Exit(args.err, "information", outcome);
  if (!run.plot_warning.empty())
    (args.err ? *args.err : std::cerr) << "roamlab information: no figure: " << run.plot_warning << "\n";
  if (args.quiet) return 0;
  PrintTable(run);
  std::printf("wrote %s/information.json, %s/information.png\n", args.out.c_str(), args.out.c_str());
  return 0;
}

}  // namespace roamlab::apps
