// Fast cell-level parsing for the CSV importer (importers/csv.h): splitting a line into cells and reading numbers
// and time stamps from views of the file's text, without allocating per cell. Private to the importer.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "importers/internal/csv_mapping.h"

namespace roamlab::importers::internal {

// Splits `line` into `cells` (cleared first): on the delimiter, or on runs of spaces and tabs (format.whitespace).
// Each cell is trimmed of spaces, tabs and a carriage return, and of one pair of surrounding double quotes.
void SplitCells(std::string_view line, const CsvFormat& format, std::vector<std::string_view>* cells);

// A whole cell as a finite number of magnitude at most 1e15, the recording format's limit (a leading '+' accepted);
// false for anything else, including NaN, Inf and 1e308.
bool ParseCellNumber(std::string_view cell, double* value);

// A decimal time stamp in units of 10^-exponent s (exponent 0, 3, 6 or 9) into integer nanoseconds, exactly for
// plain decimals ("1712345678901.5"), through a double for scientific notation. False when not a number or out of the
// int64 nanosecond range.
bool ParseTimeNs(std::string_view cell, int exponent, std::int64_t* ns);

}  // namespace roamlab::importers::internal
