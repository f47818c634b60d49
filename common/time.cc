#include "common/time.h"

#include <cmath>
#include <cstdlib>
#include <limits>

namespace roamlab {

Time Time::FromSeconds(double seconds) { return Time(static_cast<std::int64_t>(std::llround(seconds * 1e9))); }

std::optional<Time> ParseSeconds(std::string_view text) {
  if (text.empty() || text.size() > 64) return std::nullopt;
  std::size_t i = 0;
  bool negative = false;
  if (text[i] == '-' || text[i] == '+') {
    negative = text[i] == '-';
    ++i;
  }
  // Plain decimal: parse integer and fraction digits exactly.
  std::int64_t whole = 0;
  std::size_t whole_digits = 0;
  for (; i < text.size() && text[i] >= '0' && text[i] <= '9'; ++i, ++whole_digits) {
    if (whole > (std::numeric_limits<std::int64_t>::max() / 10 - 9) / 1000000000) return std::nullopt;
    whole = whole * 10 + (text[i] - '0');
  }
  std::int64_t frac = 0;
  std::size_t frac_digits = 0;
  bool round_up = false;
  if (i < text.size() && text[i] == '.') {
    ++i;
    for (; i < text.size() && text[i] >= '0' && text[i] <= '9'; ++i, ++frac_digits) {
      if (frac_digits < 9) {
        frac = frac * 10 + (text[i] - '0');
      } else if (frac_digits == 9) {
        round_up = text[i] >= '5';
      }
    }
  }
  if (i == text.size() && whole_digits + frac_digits > 0) {
    for (std::size_t k = frac_digits; k < 9; ++k) frac *= 10;
    std::int64_t ns = whole * 1000000000 + frac + (round_up ? 1 : 0);
    return Time::FromNanoseconds(negative ? -ns : ns);
  }
  // Scientific notation or anything else strtod accepts as a finite number.
  std::string copy(text);
  char* end = nullptr;
  const double value = std::strtod(copy.c_str(), &end);
  if (end != copy.c_str() + copy.size() || !std::isfinite(value) || std::abs(value) > 9e9) return std::nullopt;
  return Time::FromSeconds(value);
}

std::string FormatSeconds(Time t) {
  std::int64_t ns = t.nanoseconds();
  std::string sign;
  if (ns < 0) {
    sign = "-";
    ns = -ns;
  }
  std::string frac = std::to_string(ns % 1000000000);
  frac.insert(0, 9 - frac.size(), '0');
  return sign + std::to_string(ns / 1000000000) + "." + frac;
}

}  // namespace roamlab
