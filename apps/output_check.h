// The `--out` of a command against its inputs: an output directory (or file) equal to or inside an input directory
// would mix the outputs with the input (a calibration written into its recording, an import into the directory of
// its source files), and an output equal to an input file would overwrite it. Both are refused as bad input. The
// directory that holds an input file (a scenario's, a configuration's) is fine, except for `import`, which writes
// stream CSVs beside the source files it reads (`dirs_of_files`).
#pragma once

#include <string>
#include <vector>

namespace roamlab::apps {

// "" when `out` may be written, otherwise the problem, naming both paths. `inputs` are the paths the command reads
// (files or directories; those that do not exist are ignored). Paths are compared after resolving symbolic links.
std::string OutputOverlapsInput(const std::string& out, const std::vector<std::string>& inputs, bool dirs_of_files);

}  // namespace roamlab::apps
