// Writing a result file so that a reader never sees it half written: the content goes to a temporary name in the
// same directory (PATH.tmp.<pid>.<thread>), which is then renamed to PATH. A run killed midway leaves at most the
// temporary file, never a partial PATH; readers (resume, aggregation) only look at PATH.
#pragma once

#include <string>

#include "common/status.h"

namespace roamlab {

// Writes `content` to `path` through a temporary file and a rename. An error names the path.
Status WriteFileAtomically(const std::string& path, const std::string& content);

// The whole content of `path`; an error names the path when it cannot be read.
Result<std::string> ReadWholeFile(const std::string& path);

}  // namespace roamlab
