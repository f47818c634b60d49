#include "importers/csv.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <optional>

#include "importers/internal/csv_mapping.h"
#include "importers/internal/csv_text.h"
#include "recording/internal/stream_types.h"
#include "recording/internal/text_io.h"

namespace roamlab::importers {

namespace fs = std::filesystem;
using internal::Collapse;
using internal::ColumnRef;
using internal::FileSpec;
using internal::StreamSpec;

namespace {

// One stream being read: its resolved columns, the samples so far and the row being staged.
struct StreamJob {
  const StreamSpec* spec = nullptr;
  CsvStreamReport* report = nullptr;
  std::vector<int> columns;  // resolved source column indices
  int collapse_column = -1;
  std::vector<std::int64_t> t_ns;
  std::vector<double> values;  // row-major, canonical units
  // Staging of the current row.
  std::vector<double> row;
  bool row_empty = false;
  double key = 0.0;
  std::int64_t key_ns = 0;
  // The previous row's values (by_change) or collapse-column value (by_column).
  std::vector<double> last;
  bool has_last = false;
  double last_key = 0.0;
};

// The lines of a file's text, one at a time, with their 1-based numbers.
class Lines {
 public:
  explicit Lines(std::string_view text) : text_(text) {}
  bool Next(std::string_view* line) {
    if (pos_ >= text_.size()) return false;
    const std::size_t end = text_.find('\n', pos_);
    terminated_ = end != std::string_view::npos;
    *line = text_.substr(pos_, terminated_ ? end - pos_ : std::string_view::npos);
    if (!line->empty() && line->back() == '\r') line->remove_suffix(1);
    pos_ = terminated_ ? end + 1 : text_.size();
    ++number_;
    return true;
  }
  std::int64_t number() const { return number_; }
  // Whether the line just returned is the last one and has no line terminator.
  bool Truncated() const { return !terminated_ && pos_ >= text_.size(); }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  std::int64_t number_ = 0;
  bool terminated_ = true;
};

// A cell for a one-line message: bytes outside printable ASCII as \xNN, at most 40 characters.
std::string Printable(std::string_view cell) {
  constexpr std::size_t kMax = 40;
  std::string out;
  for (std::size_t i = 0; i < cell.size() && i < kMax; ++i) {
    const auto c = static_cast<unsigned char>(cell[i]);
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
      continue;
    }
    const char* hex = "0123456789abcdef";
    out += std::string("\\x") + hex[c >> 4] + hex[c & 15];
  }
  if (cell.size() > kMax) out += "...";
  return out;
}

bool Ignored(std::string_view line, const std::string& comment) {
  std::size_t i = 0;
  while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
  if (i == line.size()) return true;
  return !comment.empty() && line.substr(i, comment.size()) == comment;
}

// A file being read: its text, format, column names and the jobs of its streams.
class FileReader {
 public:
  FileReader(const std::string& path, const FileSpec& spec, std::vector<StreamJob*> jobs, CsvFileReport* report)
      : path_(path), spec_(spec), jobs_(std::move(jobs)), report_(report) {}

  Status Read(std::optional<std::int64_t>* first_ns);

 private:
  std::string At(std::int64_t line) const { return path_ + ":" + std::to_string(line) + ": "; }
  Status LoadText();
  Status Resolve(const ColumnRef& ref, const std::string& owner, int* index) const;
  Status ResolveColumns();
  Status ReadRow(std::int64_t line, bool truncated);
  // Parses the stream cells of the current row into the jobs' staging; *skip when a non-numeric cell drops the row.
  Status Stage(std::int64_t line, bool* skip);
  Status Commit(std::int64_t line, std::int64_t t_ns);
  Status NotANumber(std::int64_t line, int column, const std::string& stream, bool* skip) const;

  const std::string& path_;
  const FileSpec& spec_;
  std::vector<StreamJob*> jobs_;
  CsvFileReport* report_;
  std::string content_;
  std::vector<std::string> names_;  // header names, or "column <i>"
  std::vector<std::string_view> cells_;
  int time_column_ = -1;
  std::optional<std::int64_t> previous_ns_;
  std::string previous_text_;
  std::int64_t offset_ns_ = 0;
};

Status FileReader::LoadText() {
  if (Status s = recording::internal::ReadTextFile(path_, &content_); !s.ok()) return s;
  if (content_.empty()) return Status::Error(path_ + ": empty file");
  const void* nul = std::memchr(content_.data(), '\0', content_.size());
  if (nul != nullptr) {
    return Status::Error(path_ + ": binary file (NUL byte at offset " +
                         std::to_string(static_cast<const char*>(nul) - content_.data()) + "), expected CSV text");
  }
  return Status::Ok();
}

// `owner` completes the messages: " (time)", " (stream 'imu')".
Status FileReader::Resolve(const ColumnRef& ref, const std::string& owner, int* index) const {
  if (ref.index >= 0) {
    if (ref.index >= static_cast<int>(names_.size())) {
      return Status::Error(path_ + ": column " + std::to_string(ref.index) + owner + " is beyond the " +
                           std::to_string(names_.size()) + " columns of the file");
    }
    *index = ref.index;
    return Status::Ok();
  }
  const auto it = std::find(names_.begin(), names_.end(), ref.name);
  if (it == names_.end()) {
    std::string list;
    for (std::size_t c = 0; c < names_.size() && c < 30; ++c) list += (c == 0 ? "" : ", ") + Printable(names_[c]);
    if (names_.size() > 30) list += ", ...";
    return Status::Error(path_ + ": column '" + ref.name + "'" + owner + " is not in the header (" + list + ")");
  }
  if (std::find(it + 1, names_.end(), ref.name) != names_.end()) {
    return Status::Error(path_ + ": column '" + ref.name + "'" + owner + " appears more than once in the header");
  }
  *index = static_cast<int>(it - names_.begin());
  return Status::Ok();
}

Status FileReader::ResolveColumns() {
  if (Status s = Resolve(spec_.time.column, " (time)", &time_column_); !s.ok()) return s;
  for (StreamJob* job : jobs_) {
    const std::string what = " (stream '" + job->spec->info.name + "')";
    job->columns.resize(job->spec->sources.size());
    for (std::size_t c = 0; c < job->columns.size(); ++c) {
      if (Status s = Resolve(job->spec->sources[c], what, &job->columns[c]); !s.ok()) return s;
    }
    if (job->spec->collapse == Collapse::kByColumn) {
      if (Status s = Resolve(job->spec->collapse_column, " (by_column of stream '" + job->spec->info.name + "')",
                             &job->collapse_column);
          !s.ok()) {
        return s;
      }
    }
    job->row.resize(job->columns.size());
  }
  return Status::Ok();
}

Status FileReader::NotANumber(std::int64_t line, int column, const std::string& stream, bool* skip) const {
  if (spec_.format.skip_non_numeric) {
    *skip = true;
    return Status::Ok();
  }
  const std::string cell = Printable(cells_[static_cast<std::size_t>(column)]);
  return Status::Error(At(line) + "column '" + Printable(names_[static_cast<std::size_t>(column)]) + "'" +
                       (stream.empty() ? "" : " (stream '" + stream + "')") + ": '" + cell + "' is not a number");
}

Status FileReader::Stage(std::int64_t line, bool* skip) {
  for (StreamJob* job : jobs_) {
    job->row_empty = false;
    for (std::size_t c = 0; c < job->columns.size() && !job->row_empty; ++c) {
      job->row_empty = cells_[static_cast<std::size_t>(job->columns[c])].empty();
    }
    const int key_column = job->collapse_column;
    if (key_column >= 0 && cells_[static_cast<std::size_t>(key_column)].empty()) job->row_empty = true;
    if (job->row_empty) continue;
    for (std::size_t c = 0; c < job->columns.size(); ++c) {
      if (!internal::ParseCellNumber(cells_[static_cast<std::size_t>(job->columns[c])], &job->row[c])) {
        return NotANumber(line, job->columns[c], job->spec->info.name, skip);
      }
    }
    if (key_column < 0) continue;
    const std::string_view key = cells_[static_cast<std::size_t>(key_column)];
    const bool ok = job->spec->collapse_exponent >= 0
                        ? internal::ParseTimeNs(key, job->spec->collapse_exponent, &job->key_ns)
                        : internal::ParseCellNumber(key, &job->key);
    if (!ok) return NotANumber(line, key_column, job->spec->info.name, skip);
    if (job->spec->collapse_exponent >= 0) job->key = static_cast<double>(job->key_ns);
  }
  return Status::Ok();
}

// Appends `row` to the job's samples in canonical units, the sensor axes rotated.
void Append(StreamJob* job, std::int64_t t_ns) {
  const StreamSpec& spec = *job->spec;
  const std::size_t start = job->values.size();
  for (std::size_t c = 0; c < job->row.size(); ++c) job->values.push_back(job->row[c] * spec.scale[c]);
  if (spec.rotation) {
    for (const int first : spec.triples) {
      double* v = job->values.data() + start + first;
      const Eigen::Vector3d rotated = *spec.rotation * Eigen::Vector3d(v[0], v[1], v[2]);
      v[0] = rotated.x();
      v[1] = rotated.y();
      v[2] = rotated.z();
    }
  }
  job->t_ns.push_back(t_ns);
}

Status FileReader::Commit(std::int64_t line, std::int64_t t_ns) {
  for (StreamJob* job : jobs_) {
    if (job->row_empty) {
      ++job->report->empty_cells;
      continue;
    }
    const Collapse collapse = job->spec->collapse;
    const bool repeated = job->has_last && ((collapse == Collapse::kByChange && job->row == job->last) ||
                                            (collapse == Collapse::kByColumn && job->key == job->last_key));
    job->has_last = true;
    if (collapse == Collapse::kByChange) job->last = job->row;
    job->last_key = job->key;
    if (repeated) {
      ++job->report->collapsed;
      continue;
    }
    std::int64_t stamp = t_ns;
    if (collapse == Collapse::kByColumn && job->spec->collapse_exponent >= 0) {
      stamp = job->key_ns + offset_ns_;
      if (!job->t_ns.empty() && stamp <= job->t_ns.back()) {
        return Status::Error(At(line) + "column '" + Printable(names_[static_cast<std::size_t>(job->collapse_column)]) +
                             "' (by_column of stream '" + job->spec->info.name + "') does not increase");
      }
    }
    Append(job, stamp);
    ++job->report->samples;
  }
  return Status::Ok();
}

Status FileReader::ReadRow(std::int64_t line, bool truncated) {
  ++report_->rows;
  if (cells_.size() != names_.size()) {
    return Status::Error(At(line) + (truncated ? "truncated last line: " : "") + std::to_string(cells_.size()) +
                         " cells, expected " + std::to_string(names_.size()));
  }
  // A writer ends every line: a last line without its end was cut short, and a number cut short reads as another.
  if (truncated) return Status::Error(At(line) + "truncated last line: no line end (a number may be cut short)");
  std::int64_t t_ns = 0;
  bool skip = false;
  const std::string_view time_cell = cells_[static_cast<std::size_t>(time_column_)];
  if (!internal::ParseTimeNs(time_cell, spec_.time.decimal_exponent, &t_ns) ||
      __builtin_add_overflow(t_ns, offset_ns_, &t_ns)) {
    if (Status s = NotANumber(line, time_column_, "", &skip); !s.ok()) return s;
  }
  if (!skip) {
    if (Status s = Stage(line, &skip); !s.ok()) return s;
  }
  if (skip) {
    ++report_->skipped_non_numeric;
    return Status::Ok();
  }
  if (previous_ns_ && t_ns <= *previous_ns_) {
    if (t_ns < *previous_ns_) {
      return Status::Error(At(line) + "time '" + Printable(time_cell) + "' goes backwards (previous row '" +
                           Printable(previous_text_) + "')");
    }
    ++report_->skipped_duplicate_time;
    return Status::Ok();
  }
  previous_ns_ = t_ns;
  previous_text_.assign(time_cell);
  return Commit(line, t_ns);
}

Status FileReader::Read(std::optional<std::int64_t>* first_ns) {
  if (Status s = LoadText(); !s.ok()) return s;
  std::string_view text(content_);
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
  const double offset_ns = spec_.time.offset_s * 1e9;
  if (!(std::abs(offset_ns) < 9e18)) return Status::Error(path_ + ": time offset_s out of range");
  offset_ns_ = std::llround(offset_ns);
  Lines lines(text);
  std::string_view line;
  bool columns_known = false;
  while (lines.Next(&line)) {
    if (lines.number() <= spec_.format.skip_rows || Ignored(line, spec_.format.comment)) {
      ++report_->ignored_lines;
      continue;
    }
    internal::SplitCells(line, spec_.format, &cells_);
    if (!columns_known) {
      for (std::size_t c = 0; c < cells_.size(); ++c) {
        names_.push_back(spec_.format.header ? std::string(cells_[c]) : "column " + std::to_string(c));
      }
      if (Status s = ResolveColumns(); !s.ok()) return s;
      columns_known = true;
      if (spec_.format.header) continue;
    }
    if (Status s = ReadRow(lines.number(), lines.Truncated()); !s.ok()) return s;
    if (!first_ns->has_value() && previous_ns_) *first_ns = previous_ns_;
  }
  if (report_->rows == 0) return Status::Error(path_ + ": no data rows");
  return Status::Ok();
}

// The recording stream of a job, times shifted by -shift_ns.
Result<recording::Stream> BuildStream(const StreamJob& job, std::int64_t shift_ns, const std::string& path) {
  recording::Stream stream;
  stream.info = job.spec->info;
  const auto n = static_cast<Eigen::Index>(job.t_ns.size());
  const auto cols = static_cast<Eigen::Index>(job.spec->sources.size());
  if (n == 0) {
    return Status::Error(path + ": stream '" + stream.info.name + "' has no samples (" +
                         std::to_string(job.report->empty_cells) + " rows with empty cells, " +
                         std::to_string(job.report->collapsed) + " collapsed)");
  }
  stream.t.reserve(job.t_ns.size());
  for (const std::int64_t t : job.t_ns) stream.t.push_back(Time::FromNanoseconds(t - shift_ns));
  stream.values = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
      job.values.data(), n, cols);
  if (stream.info.rate_hz <= 0.0) {
    const double span_s = SecondsBetween(stream.t.front(), stream.t.back());
    if (n < 2 || !(span_s > 0.0)) {
      return Status::Error(path + ": stream '" + stream.info.name +
                           "' has one sample: its rate cannot be estimated (give rate_hz)");
    }
    stream.info.rate_hz = static_cast<double>(n - 1) / span_s;
  }
  return stream;
}

}  // namespace

Result<recording::Recording> ImportCsv(const std::vector<std::string>& csv_files, const std::string& mapping_path,
                                       CsvImportReport* report) {
  if (csv_files.empty()) return Status::Error("no CSV file given");
  Result<internal::Mapping> mapping = internal::ReadCsvMapping(mapping_path, static_cast<int>(csv_files.size()));
  if (!mapping.ok()) return mapping.status();
  const internal::Mapping& map = mapping.value();
  CsvImportReport local;
  local.files.resize(csv_files.size());
  local.streams.resize(map.streams.size());
  std::vector<StreamJob> jobs(map.streams.size());
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    jobs[i].spec = &map.streams[i];
    jobs[i].report = &local.streams[i];
    local.streams[i].name = map.streams[i].info.name;
  }
  // Each file, then the shared relative clock: the earliest first stamp of the relative files is t = 0.
  std::optional<std::int64_t> relative_start;
  for (std::size_t f = 0; f < csv_files.size(); ++f) {
    local.files[f].path = csv_files[f];
    std::vector<StreamJob*> file_jobs;
    for (StreamJob& job : jobs) {
      if (job.spec->file == static_cast<int>(f)) file_jobs.push_back(&job);
    }
    std::optional<std::int64_t> first_ns;
    FileReader reader(csv_files[f], map.files[f], file_jobs, &local.files[f]);
    if (Status s = reader.Read(&first_ns); !s.ok()) return s;
    if (!map.files[f].time.epoch && first_ns) relative_start = std::min(relative_start.value_or(*first_ns), *first_ns);
  }
  recording::Recording rec;
  rec.platform = map.platform;
  rec.origin = map.origin;
  rec.provenance.source = "imported";
  rec.provenance.description = "roamlab import csv:";
  for (const std::string& file : csv_files) rec.provenance.description += " " + fs::path(file).filename().string();
  rec.provenance.description += ", mapping " + fs::path(mapping_path).filename().string();
  for (const StreamJob& job : jobs) {
    const auto file = static_cast<std::size_t>(job.spec->file);
    const std::int64_t shift = map.files[file].time.epoch ? 0 : relative_start.value_or(0);
    Result<recording::Stream> stream = BuildStream(job, shift, csv_files[file]);
    if (!stream.ok()) return stream.status();
    rec.streams.push_back(std::move(stream).value());
    const recording::Stream& s = rec.streams.back();
    if (s.info.type == recording::StreamType::kGps && !rec.origin) {
      rec.origin = recording::GeodeticOrigin{s.values(0, 0), s.values(0, 1), s.values(0, 2)};
      const std::string problem = recording::internal::OriginProblem(*rec.origin);
      if (!problem.empty()) {
        return Status::Error(csv_files[file] + ": the first fix of stream '" + s.info.name + "' as origin: " + problem);
      }
    }
  }
  if (report) *report = std::move(local);
  return rec;
}

}  // namespace roamlab::importers
