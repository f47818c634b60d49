#include "apps/import.h"

#include <iostream>

#include "recording/import_optiodom.h"
#include "recording/recording.h"

namespace roamlab::apps {

int RunImportOptiOdom(const ImportOptiOdomArgs& args) {
  std::string metadata = args.metadata;
  if (metadata.empty()) metadata = recording::OptiOdomMetadataPath(args.run_csv);
  if (metadata.empty()) {
    std::cerr << "roamlab import: " << args.run_csv
              << ": cannot find the metadata file (expected <set>_run-NN.csv; use --metadata)\n";
    return 2;
  }
  Result<recording::Recording> rec = recording::ImportOptiOdom(args.run_csv, metadata);
  if (!rec.ok()) {
    std::cerr << "roamlab import: " << rec.status().message() << "\n";
    return 2;
  }
  if (Status s = recording::WriteRecording(rec.value(), args.out); !s.ok()) {
    std::cerr << "roamlab import: " << s.message() << "\n";
    return 1;
  }
  if (!args.quiet) {
    const recording::Stream& enc = rec.value().streams.front();
    std::cout << "imported " << enc.t.size() << " samples (" << rec.value().platform.kind << ", "
              << SecondsBetween(enc.t.front(), enc.t.back()) << " s) into " << args.out << "\n";
  }
  return 0;
}

}  // namespace roamlab::apps
