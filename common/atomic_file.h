// Writing the files a command produces so that a reader never sees a partial one: the content goes to a temporary
// file `NAME.tmp-<pid>` in the same directory, is flushed to the disk (fsync) and renamed over NAME, which replaces
// an existing file in one step. An interruption (a signal, a full disk) leaves either the old file or the new one,
// and a failed write removes its temporary file. Only a process killed during the write (SIGKILL, a power cut) can
// leave a `NAME.tmp-<pid>` behind.
#pragma once

#include <string>
#include <string_view>

#include "common/status.h"

namespace roamlab {

// Writes `content` to `path` atomically (binary: the bytes as given). Error: "<path>: cannot write: <reason>".
Status WriteFileAtomic(const std::string& path, std::string_view content);

// Removes `path` when it exists (a stale output of an earlier run). Error: "<path>: cannot remove stale file: ...".
Status RemoveStaleFile(const std::string& path);

// The whole content of `path`; an error names the path when it cannot be read.
Result<std::string> ReadWholeFile(const std::string& path);

}  // namespace roamlab
