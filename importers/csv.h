// Generic CSV/TSV importer: one or several delimited text files and a mapping (YAML) into one recording (recording.h).
// docs/import-csv.md is the full reference with examples; in short, the mapping holds:
//
//   csv:                      # how every file is read (all keys optional)
//     delimiter: ","          # "," | ";" | "\t" | "|" | whitespace (runs of spaces and tabs)
//     header: true            # true: the first row names the columns; false: columns are 0-based indices
//     comment: "#"            # lines starting with this prefix are ignored (default: none)
//     skip_rows: 0            # lines ignored at the top of the file, before the header
//     non_numeric: error      # error | skip_row: a non-numeric cell a stream needs stops the import, or drops
//                             # the row (counted)
//   time:                     # the time column of every file (required here or in each files entry)
//     column: "Time (s)"      # header name, or 0-based index when header: false
//     unit: s                 # s | ms | us | ns
//     clock: relative         # relative: the earliest first row over the relative files is t = 0; epoch: kept
//     offset_s: 0             # added to every stamp of the file (before a relative clock is shifted)
//   files:                    # optional: one entry per input file, in command-line order, overriding the csv keys
//     - {delimiter: ";", time: {column: 0, unit: ms, clock: epoch}}
//   platform: {kind: handheld, geometry: {wheelbase_m: 1.2}}   # optional; kind defaults to "unknown"
//   origin: {latitude_deg: 45.0, longitude_deg: 9.0, altitude_m: 120.0}   # optional; gps: the first fix otherwise
//   streams:                  # required, at least one; name -> entry
//     imu:
//       type: imu             # any recording stream type except camera and laser_scan
//       file: 0               # index of the input file holding the columns (default 0)
//       columns: [...]        # source columns in the order of the type's columns (recording.h)
//       names: [fl, fr]       # wheel_encoders and inputs: the recording's column names (one per source column)
//       units: deg/s          # one unit for every column of its dimension, or a list with one unit per column
//       axes: [x, -z, y]      # or rotation_wxyz: [w, x, y, z], or rotation_matrix: [[...], [...], [...]]:
//                             # applied to each vector triple (imu, gyroscope, accelerometer, magnetometer,
//                             # odometry types): v_out = R v_in, axes naming which input axis each output axis is
//       collapse: by_change   # or {by_column: gps_time, unit: s}: keep only the sensor's own updates
//       rate_hz: 100          # optional; otherwise (samples - 1) / span
//       noise: {...}, mounting: {...}, attributes: {...}   # written as given (recording.h)
//
// Units are converted to the canonical unit of the type's column (recording.h): angle rad | deg | ticks (with
// attributes.ticks_per_revolution); angular rate rad/s | deg/s | rpm; acceleration m/s^2 | g; speed m/s | km/h |
// mph | knots | ft/s; magnetic field uT | nT | mT | T | gauss | mG (into uT; normalized kept as is); length m | mm |
// cm | km | ft | in; time s | ms | us | ns. gps latitude and longitude are held in deg.
//
// Rows: blank and comment lines are ignored (counted); a row whose time equals the previous row's is skipped
// (counted); a row whose time goes backwards, a row with the wrong number of cells, a truncated last line, a NUL byte
// (binary file), an empty file, a column the mapping names that the file does not have, an unknown unit or key are
// errors, one line "<file>[:<line>]: <problem>". An empty cell in a stream's columns means no sample of that stream on
// that row (counted). With collapse, a row whose stream values repeat the previous row's (by_change) or whose fix-time
// column repeats (by_column) is collapsed into the previous sample (counted); by_column with a unit stamps the sample
// with that column, read on the file's clock.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/status.h"
#include "recording/recording.h"

namespace roamlab::importers {

struct CsvFileReport {
  std::string path;
  std::int64_t rows = 0;                    // data rows read (after the header, without blank and comment lines)
  std::int64_t ignored_lines = 0;           // skip_rows, blank and comment lines
  std::int64_t skipped_non_numeric = 0;     // rows dropped for a non-numeric cell (non_numeric: skip_row)
  std::int64_t skipped_duplicate_time = 0;  // rows whose time equals the previous row's
};

struct CsvStreamReport {
  std::string name;
  std::int64_t samples = 0;      // written
  std::int64_t empty_cells = 0;  // kept rows where a cell of the stream was empty: no sample
  std::int64_t collapsed = 0;    // kept rows that repeated the previous sample
};

// For each stream: samples + empty_cells + collapsed = rows - skipped_non_numeric - skipped_duplicate_time of its
// file.
struct CsvImportReport {
  std::vector<CsvFileReport> files;
  std::vector<CsvStreamReport> streams;  // in the order of the recording's streams
};

// Reads the files with the mapping file. On success fills `report` (when not null). Errors are one line naming the
// file (mapping or CSV) and the line, key or column.
Result<recording::Recording> ImportCsv(const std::vector<std::string>& csv_files, const std::string& mapping_path,
                                       CsvImportReport* report);

}  // namespace roamlab::importers
