// Time stamps for every API boundary in roamlab: integer nanoseconds in a strong type.
//
// Recordings store time as decimal seconds with nine fractional digits; ParseSeconds reads that text exactly (no
// binary floating-point round trip), FormatSeconds writes it back, so a recording read and written again keeps every
// byte of its time column.
//
// Range: a stamp read from a file or converted from seconds lies within +-kMaxSeconds (9e9 s, about 285 years either
// side of the epoch: every Unix, GPS or ROS time to the year 2255). ParseSeconds and FromSecondsChecked refuse what
// lies outside, so that the int64 nanoseconds never overflow on reading.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace roamlab {

// The largest |stamp| [s] accepted from text or a double (see the top comment).
inline constexpr double kMaxSeconds = 9e9;

class Time {
 public:
  constexpr Time() = default;
  static constexpr Time FromNanoseconds(std::int64_t ns) { return Time(ns); }
  // Rounds to the nearest nanosecond. Outside +-kMaxSeconds (and for NaN) the result saturates at +-kMaxSeconds
  // (NaN: 0): defined, never an overflow; data read from files goes through FromSecondsChecked instead.
  static Time FromSeconds(double seconds);
  // Rounds to the nearest nanosecond; nullopt for NaN, Inf and |seconds| > kMaxSeconds.
  static std::optional<Time> FromSecondsChecked(double seconds);

  constexpr std::int64_t nanoseconds() const { return ns_; }
  constexpr double seconds() const { return static_cast<double>(ns_) * 1e-9; }

  friend constexpr bool operator==(Time a, Time b) { return a.ns_ == b.ns_; }
  friend constexpr bool operator!=(Time a, Time b) { return a.ns_ != b.ns_; }
  friend constexpr bool operator<(Time a, Time b) { return a.ns_ < b.ns_; }
  friend constexpr bool operator<=(Time a, Time b) { return a.ns_ <= b.ns_; }
  friend constexpr bool operator>(Time a, Time b) { return a.ns_ > b.ns_; }
  friend constexpr bool operator>=(Time a, Time b) { return a.ns_ >= b.ns_; }

 private:
  constexpr explicit Time(std::int64_t ns) : ns_(ns) {}
  std::int64_t ns_ = 0;
};

// Seconds between two stamps (b - a), as a double.
inline double SecondsBetween(Time a, Time b) { return static_cast<double>(b.nanoseconds() - a.nanoseconds()) * 1e-9; }

// Parses "[-]digits[.digits]" (at most 9 fractional digits are significant; more are rounded) or scientific notation
// (through strtod, then rounded). Returns nullopt on anything else, including NaN, Inf and |value| > kMaxSeconds.
std::optional<Time> ParseSeconds(std::string_view text);

// Writes the stamp as seconds with exactly nine fractional digits, e.g. "12.000000001"; every int64 stamp, including
// the most negative, is written correctly.
std::string FormatSeconds(Time t);

}  // namespace roamlab
