// Private helpers of the recording module: whole-file text I/O and number <-> text conversion shared by the CSV, TUM
// and YAML code. Not part of the public interface.
#pragma once

#include <string>
#include <string_view>

#include <Eigen/Geometry>

#include "common/status.h"
#include "common/time.h"

namespace roamlab::recording::internal {

// Reads the whole file into `content`. Error: "<path>: cannot open file" (or read error).
Status ReadTextFile(const std::string& path, std::string* content);

// Outcome of parsing one number cell.
enum class NumberParse { kOk, kNotANumber, kNaN, kInf };

// Parses a whole cell with std::strtod (C locale assumed). The cell must be consumed entirely; leading and trailing
// spaces or tabs are ignored. NaN and Inf (including overflow) are reported, never returned as values.
NumberParse ParseNumber(std::string_view cell, double* value);

// Removes leading and trailing spaces, tabs and carriage returns.
std::string_view Trim(std::string_view text);

// "%.17g": every double round-trips. Used for bulk data (CSV, TUM).
std::string FormatFull(double value);
// Appends "%.17g" of `value` to `out` without a temporary string.
void AppendFull(double value, std::string* out);

// The shortest "%.{15,16,17}g" text that reads back to the same double. Used for metadata (YAML), where 0.1 should
// stay "0.1".
std::string FormatShortest(double value);

// Why `current` cannot follow `previous` in a strictly increasing time column, or "" when it can:
//   "timestamp 1.200000000 not after previous 1.200000000 (duplicate)"
//   "timestamp 1.100000000 goes backwards (previous 1.200000000)"
std::string TimeOrderProblem(Time previous, Time current);

// Quaternions read from text must be within this distance of unit norm; they are normalized (unless already unit to
// rounding, so that write -> read is exact).
inline constexpr double kQuaternionNormTolerance = 1e-3;

// Normalizes `q` when | |q| - 1 | < kQuaternionNormTolerance and returns true; returns false (q untouched) otherwise.
bool NormalizeNearUnit(Eigen::Quaterniond* q);

}  // namespace roamlab::recording::internal
