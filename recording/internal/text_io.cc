#include "recording/internal/text_io.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>

namespace roamlab::recording::internal {
namespace {

struct FileCloser {
  void operator()(std::FILE* file) const { std::fclose(file); }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

bool IsBlank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

}  // namespace

Status ReadTextFile(const std::string& path, std::string* content) {
  FilePtr file(std::fopen(path.c_str(), "rb"));
  if (!file) return Status::Error(path + ": cannot open file");
  // Read in large blocks: the size of the file is not trusted (it may be a pipe).
  content->clear();
  char buffer[1 << 16];
  std::size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof(buffer), file.get())) > 0) content->append(buffer, n);
  if (std::ferror(file.get())) return Status::Error(path + ": read error");
  return Status::Ok();
}

std::string_view Trim(std::string_view text) {
  while (!text.empty() && IsBlank(text.front())) text.remove_prefix(1);
  while (!text.empty() && IsBlank(text.back())) text.remove_suffix(1);
  return text;
}

NumberParse ParseNumber(std::string_view cell, double* value) {
  cell = Trim(cell);
  if (cell.empty()) return NumberParse::kNotANumber;
  // strtod needs a terminated string: copy short cells (all real ones) to the stack, long ones to the heap.
  char stack_buffer[64];
  std::string heap_buffer;
  const char* begin = stack_buffer;
  if (cell.size() < sizeof(stack_buffer)) {
    cell.copy(stack_buffer, cell.size());
    stack_buffer[cell.size()] = '\0';
  } else {
    heap_buffer.assign(cell);
    begin = heap_buffer.c_str();
  }
  char* end = nullptr;
  const double parsed = std::strtod(begin, &end);
  if (end != begin + cell.size()) return NumberParse::kNotANumber;
  if (std::isnan(parsed)) return NumberParse::kNaN;
  if (std::isinf(parsed)) return NumberParse::kInf;
  *value = parsed;
  return NumberParse::kOk;
}

std::string FormatFull(double value) {
  std::string text;
  AppendFull(value, &text);
  return text;
}

void AppendFull(double value, std::string* out) {
  // std::to_chars in general format with precision 17 is "%.17g" by definition, without printf's locale and parsing.
  char buffer[32];
  const std::to_chars_result result =
      std::to_chars(buffer, buffer + sizeof(buffer), value, std::chars_format::general, 17);
  out->append(buffer, result.ptr);
}

std::string FormatShortest(double value) {
  char buffer[32];
  for (int precision = 15; precision < 17; ++precision) {
    std::snprintf(buffer, sizeof(buffer), "%.*g", precision, value);
    if (std::strtod(buffer, nullptr) == value) return buffer;
  }
  std::snprintf(buffer, sizeof(buffer), "%.17g", value);
  return buffer;
}

std::string TimeOrderProblem(Time previous, Time current) {
  if (current > previous) return "";
  if (current == previous) {
    return "timestamp " + FormatSeconds(current) + " not after previous " + FormatSeconds(previous) + " (duplicate)";
  }
  return "timestamp " + FormatSeconds(current) + " goes backwards (previous " + FormatSeconds(previous) + ")";
}

bool NormalizeNearUnit(Eigen::Quaterniond* q) {
  const double norm = q->norm();
  if (!(std::abs(norm - 1.0) < kQuaternionNormTolerance)) return false;
  // Leave quaternions that are unit to rounding alone: normalizing them could move the last bit.
  if (std::abs(norm - 1.0) > 1e-15) q->coeffs() /= norm;
  return true;
}

}  // namespace roamlab::recording::internal
