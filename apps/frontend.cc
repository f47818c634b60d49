#include "apps/frontend.h"

#include <cstdio>
#include <iostream>

#include "apps/cli.h"
#include "common/progress.h"
#include "frontend/recording_front_end.h"

namespace roamlab::apps {

int RunFrontEnd(const FrontEndArgs& args) {
  frontend::FrontEndOptions options;
  options.front_end =
      args.front_end == "scan" ? frontend::FrontEnd::kScanMatching : frontend::FrontEnd::kVisualOdometry;
  options.input_stream = args.input_stream;
  options.output_stream = args.output_stream;
  ProgressMeter meter("frontend", &std::cerr);
  if (!args.quiet) options.progress = [&meter](double fraction) { meter.Update(fraction); };
  bool bad_input = true;
  const auto run = frontend::RunFrontEnd(args.recording, args.out, options, &bad_input);
  meter.Finish();
  if (!run.ok()) return Report(args.err, "frontend", run.status().message(), bad_input ? kBadInputExit : kFailureExit);
  if (args.quiet) return 0;
  const frontend::FrontEndResult& r = run.value();
  std::printf("%s: %zu rows from stream '%s'\n", r.stream.info.name.c_str(), r.stream.t.size(), r.input_stream.c_str());
  if (const auto& vo = r.visual_odometry) {
    std::printf(
        "visual odometry: %d frames, %d pairs, %d estimates, %d failures (features %d, tracks %d, inliers "
        "%d, scale %d)\n",
        vo->frames, vo->pairs, vo->estimates, vo->failures, vo->too_few_features, vo->too_few_tracks,
        vo->too_few_inliers, vo->no_scale);
  } else {
    std::printf("scan matcher: %d scan pairs not matched\n", r.failed_scan_matches);
  }
  std::printf("wrote %s\n", args.out.c_str());
  return 0;
}

}  // namespace roamlab::apps
