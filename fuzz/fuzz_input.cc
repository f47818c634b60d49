#include "fuzz/fuzz_input.h"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace roamlab::fuzz {
namespace {

constexpr std::string_view kSeparator = "\n%%%% ";

bool SafeName(const std::string& name) {
  if (name.empty() || name.size() > 64 || name[0] == '.') return false;
  for (const char c : name) {
    const bool ok =
        (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-' || c == '.';
    if (!ok) return false;
  }
  return true;
}

std::string& Scratch() {
  static std::string directory;
  return directory;
}

void RemoveScratch() {
  std::error_code ignored;
  if (!Scratch().empty()) std::filesystem::remove_all(Scratch(), ignored);
}

}  // namespace

std::vector<InputFile> SplitInput(const std::uint8_t* data, std::size_t size, const std::string& main_name) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  std::vector<InputFile> files;
  std::size_t start = 0;
  std::string name = main_name;
  while (true) {
    const std::size_t separator = text.find(kSeparator, start);
    const std::size_t end = separator == std::string_view::npos ? text.size() : separator + 1;
    if (SafeName(name)) files.push_back({name, std::string(text.substr(start, end - start))});
    if (separator == std::string_view::npos) break;
    const std::size_t name_begin = separator + kSeparator.size();
    const std::size_t line_end = text.find('\n', name_begin);
    name = std::string(
        text.substr(name_begin, line_end == std::string_view::npos ? std::string_view::npos : line_end - name_begin));
    if (line_end == std::string_view::npos) break;
    start = line_end + 1;
  }
  return files;
}

const std::string& ScratchDirectory(const std::vector<std::pair<std::string, std::string>>& links) {
  if (Scratch().empty()) {
    std::string pattern = (std::filesystem::temp_directory_path() / "roamlab_fuzz_XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) std::abort();
    Scratch() = pattern;
    std::atexit(RemoveScratch);
    for (const auto& [name, target] : links) {
      std::filesystem::create_directory_symlink(target, std::filesystem::path(Scratch()) / name);
    }
  }
  return Scratch();
}

void ResetScratch(const std::vector<InputFile>& files, const std::string& subdirectory) {
  const std::filesystem::path root = ScratchDirectory();
  for (const auto& entry : std::filesystem::directory_iterator(root)) {
    if (!entry.is_symlink()) std::filesystem::remove_all(entry.path());
  }
  const std::filesystem::path directory = root / subdirectory;
  std::filesystem::create_directories(directory);
  for (const InputFile& file : files) WriteBytes((directory / file.name).string(), file.bytes);
}

void WriteBytes(const std::string& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

}  // namespace roamlab::fuzz
