// Private helpers of the recording module: the text of one stream file "<name>.csv".
//
//   t,<column 1>,<column 2>,...         header, line 1
//   12.000000001,0.5,-0.25,...          one row per sample: time in seconds, then one number per column
//
// Time is parsed exactly (roamlab::ParseSeconds) and must increase strictly, except that a row identical to the one
// before it (the same stamp and cells: a message delivered twice) is dropped and counted; numbers must be finite and at
// most kMaxCellMagnitude in magnitude. A text stream (camera) has a single text column instead of numbers. Trailing
// blank lines are allowed, others are not. Every row ends with a line end ("\n" or "\r\n"): a last row without one is
// refused as truncated (a number cut short, "0.12" of "0.125", would otherwise read as a valid value).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "common/time.h"

namespace roamlab::recording::internal {

// Numeric cells are at most this in magnitude (any unit of the format: m, rad, s, ticks, m^2, ...); a larger value is
// a corrupted file, not a measurement.
inline constexpr double kMaxCellMagnitude = 1e15;

// The content of one stream file in memory.
struct CsvColumns {
  std::vector<Time> t;
  Eigen::MatrixXd values;           // rows = samples; 0 columns for a text stream
  std::vector<std::string> text;    // text stream only: one cell per sample
  std::int64_t duplicate_rows = 0;  // rows identical to the one before, dropped
};

// Parses the text of a stream file whose columns after "t" are `columns`; when `text_column` is true there is exactly
// one column and it holds text. `path` only names the file in messages: "<path>:<line>: <problem>".
Status ParseStreamCsv(std::string_view content, const std::string& path, const std::vector<std::string>& columns,
                      bool text_column, CsvColumns* out);

// The text of a stream file. Preconditions (checked by the caller): values.rows() == t.size() (or 0 columns for a text
// stream with text.size() == t.size()), values.cols() == columns.size() for numeric streams.
std::string FormatStreamCsv(const std::vector<std::string>& columns, const std::vector<Time>& t,
                            const Eigen::MatrixXd& values, const std::vector<std::string>* text);

}  // namespace roamlab::recording::internal
