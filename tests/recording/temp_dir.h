// A fresh directory per test, removed with everything in it when the test ends, and small file helpers.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

namespace roamlab::testing {

class TempDir {
 public:
  TempDir() {
    // Unique across the parallel test processes ctest starts: process id plus a random number.
    std::random_device random;
    path_ = std::filesystem::temp_directory_path() /
            ("roamlab_recording_test_" + std::to_string(::getpid()) + "_" + std::to_string(random()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code error;
    std::filesystem::remove_all(path_, error);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  std::string path() const { return path_.string(); }
  // Path of `name` inside the directory.
  std::string File(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

inline void WriteFile(const std::string& path, const std::string& content) {
  std::ofstream(path, std::ios::binary) << content;
}

inline std::string ReadFile(const std::string& path);

// A command's exit code, standard output and standard error.
struct CommandRun {
  int exit_code;
  std::string out;
  std::string err;
};

// Runs `command` through the shell with its standard output and error captured in files of `directory`.
inline CommandRun RunCommand(const std::string& command, const std::string& directory) {
  const std::string out = (std::filesystem::path(directory) / "stdout.txt").string();
  const std::string err = (std::filesystem::path(directory) / "stderr.txt").string();
  const int status = std::system((command + " > " + out + " 2> " + err).c_str());
  return {WEXITSTATUS(status), ReadFile(out), ReadFile(err)};
}

inline std::string ReadFile(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  std::ostringstream content;
  content << file.rdbuf();
  return content.str();
}

}  // namespace roamlab::testing
