// Helpers shared by the libFuzzer harnesses: the fuzz input as files in a scratch directory.
//
// A multi-file input is text: the first part is the harness's main file; each further part starts with a line
// "%%%% NAME" and becomes the file NAME (letters, digits, '_', '-' and '.', not starting with '.', at most 64
// characters; a part with another name is dropped). Example for the recording reader:
//
//   format_version: 1
//   ...
//   %%%% imu.csv
//   t,wx,wy,wz,ax,ay,az
//   0.000000000,0,0,0,0,0,9.81
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace roamlab::fuzz {

// One file of a multi-file input: its name and its bytes.
struct InputFile {
  std::string name;
  std::string bytes;
};

// Splits `data` into the main part (name `main_name`) and the named parts that follow it.
std::vector<InputFile> SplitInput(const std::uint8_t* data, std::size_t size, const std::string& main_name);

// The process's scratch directory (created on first use, removed at exit), with `links` (name -> absolute target)
// as symbolic links inside it, which ClearScratch keeps.
const std::string& ScratchDirectory(const std::vector<std::pair<std::string, std::string>>& links = {});

// Removes every regular file and directory of the scratch directory (the links stay), then writes `files` into it.
void ResetScratch(const std::vector<InputFile>& files, const std::string& subdirectory = "");

// Writes `bytes` to `path` (truncating).
void WriteBytes(const std::string& path, std::string_view bytes);

// The project's rule for bad input: one line naming the file and the problem. Aborts (a finding) when `result` is an
// error whose message is empty or spans several lines.
template <typename ResultT>
void ExpectOneLineError(const ResultT& result) {
  if (result.ok()) return;
  const std::string& message = result.status().message();
  if (message.empty() || message.find('\n') != std::string::npos) {
    std::fprintf(stderr, "error message not one line: '%s'\n", message.c_str());
    std::abort();
  }
}

}  // namespace roamlab::fuzz
