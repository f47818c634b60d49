// `roamlab import optiodom RUN.csv --out REC [--metadata FILE]`: converts a real OptiOdom run (recording/
// import_optiodom.h) into a recording directory. Returns the exit code: 0, 2 with one line
// "roamlab import: <file>:<line>: <problem>" on bad input, 1 when the recording cannot be written.
#pragma once

#include <string>

namespace roamlab::apps {

struct ImportOptiOdomArgs {
  std::string run_csv;
  std::string metadata;  // "" = <set>_metadata.csv next to the run
  std::string out;
  bool quiet = false;
};
int RunImportOptiOdom(const ImportOptiOdomArgs& args);

}  // namespace roamlab::apps
