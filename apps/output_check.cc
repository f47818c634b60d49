#include "apps/output_check.h"

#include <algorithm>
#include <filesystem>
#include <system_error>

namespace roamlab::apps {
namespace {

namespace fs = std::filesystem;

// The absolute, symlink-resolved form of `path` (as far as it exists).
fs::path Resolved(const std::string& path) {
  std::error_code error;
  fs::path resolved = fs::weakly_canonical(fs::absolute(path, error), error);
  if (error) resolved = fs::absolute(path).lexically_normal();
  return resolved.has_filename() ? resolved : resolved.parent_path();  // "rec/" as "rec"
}

// True when `inner` is `outer` or below it.
bool Within(const fs::path& inner, const fs::path& outer) {
  auto i = inner.begin();
  for (auto o = outer.begin(); o != outer.end(); ++o, ++i) {
    if (o->empty()) continue;  // a trailing separator
    if (i == inner.end() || *i != *o) return false;
  }
  return true;
}

}  // namespace

std::string OutputOverlapsInput(const std::string& out, const std::vector<std::string>& inputs, bool dirs_of_files) {
  const fs::path out_path = Resolved(out);
  for (const std::string& input : inputs) {
    std::error_code error;
    const fs::file_status status = fs::status(input, error);
    if (error || !fs::exists(status)) continue;
    const fs::path in_path = Resolved(input);
    if (fs::is_directory(status)) {
      if (Within(out_path, in_path))
        return "--out " + out + " is " + (out_path == in_path ? "the" : "inside the") + " input directory " + input +
               ": choose a directory of its own";
      continue;
    }
    if (out_path == in_path) return "--out " + out + " is the input file " + input;
    if (dirs_of_files && out_path == in_path.parent_path())
      return "--out " + out + " is the directory of the input file " + input + ": choose a directory of its own";
  }
  return "";
}

}  // namespace roamlab::apps
