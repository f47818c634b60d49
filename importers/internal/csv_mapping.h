// The mapping of the CSV importer (importers/csv.h) as read from its YAML file: how each input file is split, its time
// column, and for each stream the source columns with the factor that brings each to the canonical unit. Private to
// the importer.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "recording/recording.h"

namespace roamlab::importers::internal {

struct CsvFormat {
  char delimiter = ',';
  bool whitespace = false;  // cells separated by runs of spaces and tabs
  bool header = true;
  std::string comment;  // "" = no comment lines
  int skip_rows = 0;
  bool skip_non_numeric = false;
};

// A column as the mapping names it: by header name (header: true) or by 0-based index.
struct ColumnRef {
  std::string name;
  int index = -1;
  std::string Describe() const { return index >= 0 ? std::to_string(index) : "'" + name + "'"; }
};

struct TimeSpec {
  ColumnRef column;
  int decimal_exponent = 0;  // the unit is 10^-decimal_exponent s: s 0, ms 3, us 6, ns 9
  bool epoch = false;
  double offset_s = 0.0;
};

struct FileSpec {
  CsvFormat format;
  TimeSpec time;
};

enum class Collapse { kNone, kByChange, kByColumn };

struct StreamSpec {
  recording::StreamInfo info;  // rate_hz 0 = estimated from the samples
  int file = 0;
  std::vector<ColumnRef> sources;  // one per info.columns entry
  std::vector<double> scale;       // canonical value = scale * source value, per column
  std::optional<Eigen::Matrix3d> rotation;
  std::vector<int> triples;  // first columns of the vector triples the rotation applies to
  Collapse collapse = Collapse::kNone;
  ColumnRef collapse_column;
  int collapse_exponent = -1;  // >= 0: stamp the samples with the collapse column in that time unit
};

struct Mapping {
  std::vector<FileSpec> files;  // one per input file
  recording::Platform platform;
  std::optional<recording::GeodeticOrigin> origin;
  std::vector<StreamSpec> streams;
};

// Reads the mapping for `file_count` input files. Errors: "<mapping>:<line>: <problem>" naming the key.
Result<Mapping> ReadCsvMapping(const std::string& path, int file_count);

}  // namespace roamlab::importers::internal
