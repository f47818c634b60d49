#include "common/time.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace roamlab {

namespace {

constexpr std::int64_t kMaxWholeSeconds = 9000000000;

}  // namespace

Time Time::FromSeconds(double seconds) {
  if (std::isnan(seconds)) return Time();
  const double clamped = std::clamp(seconds, -kMaxSeconds, kMaxSeconds);
  return Time(static_cast<std::int64_t>(std::llround(clamped * 1e9)));
}

std::optional<Time> Time::FromSecondsChecked(double seconds) {
  if (!std::isfinite(seconds) || std::abs(seconds) > kMaxSeconds) return std::nullopt;
  return FromSeconds(seconds);
}

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
    whole = whole * 10 + (text[i] - '0');
    if (whole > kMaxWholeSeconds) return std::nullopt;
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
    const std::int64_t ns = whole * 1000000000 + frac + (round_up ? 1 : 0);
    if (ns > kMaxWholeSeconds * 1000000000) return std::nullopt;
    return Time::FromNanoseconds(negative ? -ns : ns);
  }
  // Scientific notation or anything else strtod accepts as a finite number.
  std::string copy(text);
  char* end = nullptr;
  const double value = std::strtod(copy.c_str(), &end);
  if (end != copy.c_str() + copy.size()) return std::nullopt;
  return Time::FromSecondsChecked(value);
}

std::string FormatSeconds(Time t) {
  // The magnitude in unsigned arithmetic: -INT64_MIN does not fit an int64.
  const std::int64_t signed_ns = t.nanoseconds();
  const std::string sign = signed_ns < 0 ? "-" : "";
  const std::uint64_t ns =
      signed_ns < 0 ? ~static_cast<std::uint64_t>(signed_ns) + 1 : static_cast<std::uint64_t>(signed_ns);
  std::string frac = std::to_string(ns % 1000000000);
  frac.insert(0, 9 - frac.size(), '0');
  return sign + std::to_string(ns / 1000000000) + "." + frac;
}

}  // namespace roamlab
