#include "importers/internal/csv_text.h"

#include <charconv>
#include <cmath>

namespace roamlab::importers::internal {

namespace {

bool IsBlank(char c) { return c == ' ' || c == '\t' || c == '\r'; }
bool IsDigit(char c) { return c >= '0' && c <= '9'; }

std::string_view TrimCell(std::string_view cell) {
  while (!cell.empty() && IsBlank(cell.front())) cell.remove_prefix(1);
  while (!cell.empty() && IsBlank(cell.back())) cell.remove_suffix(1);
  if (cell.size() >= 2 && cell.front() == '"' && cell.back() == '"') cell = cell.substr(1, cell.size() - 2);
  return cell;
}

}  // namespace

void SplitCells(std::string_view line, const CsvFormat& format, std::vector<std::string_view>* cells) {
  cells->clear();
  if (format.whitespace) {
    std::size_t i = 0;
    while (true) {
      while (i < line.size() && IsBlank(line[i])) ++i;
      if (i == line.size()) return;
      const std::size_t start = i;
      while (i < line.size() && !IsBlank(line[i])) ++i;
      cells->push_back(TrimCell(line.substr(start, i - start)));
    }
  }
  std::size_t start = 0;
  while (true) {
    const std::size_t end = line.find(format.delimiter, start);
    if (end == std::string_view::npos) {
      cells->push_back(TrimCell(line.substr(start)));
      return;
    }
    cells->push_back(TrimCell(line.substr(start, end - start)));
    start = end + 1;
  }
}

bool ParseCellNumber(std::string_view cell, double* value) {
  if (!cell.empty() && cell.front() == '+') cell.remove_prefix(1);
  if (cell.empty()) return false;
  const char* end = cell.data() + cell.size();
  const std::from_chars_result result = std::from_chars(cell.data(), end, *value);
  return result.ec == std::errc() && result.ptr == end && std::isfinite(*value) && std::abs(*value) <= 1e15;
}

bool ParseTimeNs(std::string_view cell, int exponent, std::int64_t* ns) {
  const int fraction_digits = 9 - exponent;  // digits after the point that are whole nanoseconds
  std::int64_t scale = 1;
  for (int k = 0; k < fraction_digits; ++k) scale *= 10;
  std::size_t i = 0;
  const bool negative = !cell.empty() && cell[0] == '-';
  if (!cell.empty() && (cell[0] == '-' || cell[0] == '+')) i = 1;
  std::int64_t whole = 0;
  bool any_digit = false;
  for (; i < cell.size() && IsDigit(cell[i]); ++i) {
    if (__builtin_mul_overflow(whole, 10, &whole) || __builtin_add_overflow(whole, cell[i] - '0', &whole)) return false;
    any_digit = true;
  }
  std::int64_t fraction = 0;
  int taken = 0;
  bool round_up = false;
  if (i < cell.size() && cell[i] == '.') {
    for (++i; i < cell.size() && IsDigit(cell[i]); ++i) {
      any_digit = true;
      if (taken < fraction_digits) {
        fraction = fraction * 10 + (cell[i] - '0');
        ++taken;
      } else if (taken == fraction_digits) {
        round_up = cell[i] >= '5';
        ++taken;
      }
    }
  }
  if (!any_digit) return false;
  if (i != cell.size()) {
    if (cell[i] != 'e' && cell[i] != 'E') return false;
    double value = 0.0;
    if (!ParseCellNumber(cell, &value)) return false;
    const double scaled = value * static_cast<double>(scale);
    if (!(std::abs(scaled) < 9.2e18)) return false;
    *ns = std::llround(scaled);
    return true;
  }
  for (int k = std::min(taken, fraction_digits); k < fraction_digits; ++k) fraction *= 10;
  std::int64_t total = 0;
  if (__builtin_mul_overflow(whole, scale, &total) ||
      __builtin_add_overflow(total, fraction + (round_up ? 1 : 0), &total))
    return false;
  *ns = negative ? -total : total;
  return true;
}

}  // namespace roamlab::importers::internal
