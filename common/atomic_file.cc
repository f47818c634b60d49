#include "common/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace roamlab {
namespace {

// Writes every byte of `content` to `fd`, retrying after a signal; false (errno set) on an error.
bool WriteAll(int fd, std::string_view content) {
  while (!content.empty()) {
    const ssize_t n = ::write(fd, content.data(), content.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    content.remove_prefix(static_cast<std::size_t>(n));
  }
  return true;
}

Status WriteError(const std::string& path, const char* what, int error) {
  return Status::Error(path + ": cannot write: " + what + ": " + std::strerror(error));
}

}  // namespace

Status WriteFileAtomic(const std::string& path, std::string_view content) {
  const std::string temporary = path + ".tmp-" + std::to_string(::getpid());
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) return WriteError(path, "cannot create the temporary file", errno);
  const auto fail = [&](const char* what) {
    const int error = errno;
    ::close(fd);
    ::unlink(temporary.c_str());
    return WriteError(path, what, error);
  };
  if (!WriteAll(fd, content)) return fail("write error");
  if (::fsync(fd) != 0) return fail("fsync failed");
  if (::close(fd) != 0) {
    const int error = errno;
    ::unlink(temporary.c_str());
    return WriteError(path, "close failed", error);
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    const int error = errno;
    ::unlink(temporary.c_str());
    return WriteError(path, "rename failed", error);
  }
  return Status::Ok();
}

Status RemoveStaleFile(const std::string& path) {
  std::error_code error;
  std::filesystem::remove(path, error);
  if (error) return Status::Error(path + ": cannot remove stale file: " + error.message());
  return Status::Ok();
}

Result<std::string> ReadWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::Error(path + ": cannot read");
  std::ostringstream content;
  content << in.rdbuf();
  if (in.bad()) return Status::Error(path + ": cannot read");
  return content.str();
}

}  // namespace roamlab
