#include "recording/internal/stream_csv.h"

#include <algorithm>
#include <cmath>

#include "recording/internal/text_io.h"

namespace roamlab::recording::internal {
namespace {

// The header line expected for `columns`.
std::string HeaderLine(const std::vector<std::string>& columns) {
  std::string header = "t";
  for (const std::string& column : columns) header += "," + column;
  return header;
}

// Shortens what a user wrote for an error message.
std::string Quote(std::string_view text) {
  constexpr std::size_t kMax = 40;
  return "'" + std::string(text.substr(0, kMax)) + (text.size() > kMax ? "...'" : "'");
}

// Splits `line` at commas into `cells` (views into `line`).
void SplitCells(std::string_view line, std::vector<std::string_view>* cells) {
  cells->clear();
  std::size_t begin = 0;
  while (true) {
    const std::size_t comma = line.find(',', begin);
    if (comma == std::string_view::npos) {
      cells->push_back(line.substr(begin));
      return;
    }
    cells->push_back(line.substr(begin, comma - begin));
    begin = comma + 1;
  }
}

// Walks the lines of a text, numbering them from 1 and dropping a trailing '\r'.
class LineReader {
 public:
  explicit LineReader(std::string_view text) : text_(text) {}

  bool Next(std::string_view* line) {
    if (position_ >= text_.size()) return false;
    std::size_t end = text_.find('\n', position_);
    if (end == std::string_view::npos) end = text_.size();
    *line = text_.substr(position_, end - position_);
    if (!line->empty() && line->back() == '\r') line->remove_suffix(1);
    position_ = end + 1;
    ++line_number_;
    return true;
  }
  int line_number() const { return line_number_; }

 private:
  std::string_view text_;
  std::size_t position_ = 0;
  int line_number_ = 0;
};

// Why a numeric cell of column `name` was rejected.
std::string CellProblem(NumberParse result, const std::string& name, std::string_view cell) {
  switch (result) {
    case NumberParse::kNaN:
      return "column '" + name + "' is NaN";
    case NumberParse::kInf:
      return "column '" + name + "' is Inf";
    default:
      return "column '" + name + "': not a number " + Quote(Trim(cell));
  }
}

// "<path>:<line>: <problem>".
Status LineError(const std::string& path, int line_number, const std::string& problem) {
  return Status::Error(path + ":" + std::to_string(line_number) + ": " + problem);
}

// A row stamped like the previous one with other values: two different readings claim one instant.
std::string RepeatProblem(Time t) {
  return "timestamp " + FormatSeconds(t) +
         " repeats the previous row's with other values (only an identical row, a duplicated message, may repeat)";
}

}  // namespace

Status ParseStreamCsv(std::string_view content, const std::string& path, const std::vector<std::string>& columns,
                      bool text_column, CsvColumns* out) {
  // Trailing blank lines (and the final newline) are allowed: cut them off before walking the lines.
  const std::size_t last = content.find_last_not_of(" \t\r\n");
  const bool ends_with_line_end = last != std::string_view::npos && content.find('\n', last) != std::string_view::npos;
  content = last == std::string_view::npos ? std::string_view() : content.substr(0, last + 1);
  const std::string header = HeaderLine(columns);
  if (content.empty()) return Status::Error(path + ":1: empty file, expected header '" + header + "'");

  // Header.
  LineReader lines(content);
  std::string_view line;
  lines.Next(&line);
  if (Trim(line) != header) {
    return Status::Error(path + ":1: header " + Quote(Trim(line)) + " does not match expected '" + header + "'");
  }

  // Rows, appended row-major to a flat buffer sized from the number of lines.
  const std::size_t expected_cells = columns.size() + 1;
  const std::size_t row_estimate = static_cast<std::size_t>(std::count(content.begin(), content.end(), '\n'));
  const std::size_t numeric_columns = text_column ? 0 : columns.size();
  std::vector<double> buffer;
  buffer.reserve(row_estimate * numeric_columns);
  out->duplicate_rows = 0;
  out->t.clear();
  out->t.reserve(row_estimate);
  out->text.clear();
  std::vector<std::string_view> cells;
  while (lines.Next(&line)) {
    const int n = lines.line_number();
    if (Trim(line).empty()) return LineError(path, n, "blank line");
    SplitCells(line, &cells);
    if (cells.size() != expected_cells) {
      return LineError(
          path, n, "expected " + std::to_string(expected_cells) + " columns, found " + std::to_string(cells.size()));
    }
    // Time: exact, strictly increasing, but for a row that repeats the previous one (a message delivered twice).
    const std::optional<Time> t = ParseSeconds(Trim(cells[0]));
    if (!t) return LineError(path, n, "column 't': not a time " + Quote(Trim(cells[0])));
    const bool repeat = !out->t.empty() && *t == out->t.back();
    if (!out->t.empty() && *t < out->t.back()) return LineError(path, n, TimeOrderProblem(out->t.back(), *t));
    // Values: text for a text stream, finite numbers otherwise.
    if (text_column) {
      const std::string_view cell = Trim(cells[1]);
      if (cell.empty()) return LineError(path, n, "column '" + columns[0] + "' is empty");
      if (repeat && cell != out->text.back()) return LineError(path, n, RepeatProblem(*t));
      if (repeat) {
        ++out->duplicate_rows;
        continue;
      }
      out->t.push_back(*t);
      out->text.emplace_back(cell);
      continue;
    }
    out->t.push_back(*t);
    for (std::size_t c = 0; c < columns.size(); ++c) {
      double value = 0.0;
      const NumberParse result = ParseNumber(cells[c + 1], &value);
      if (result != NumberParse::kOk) return LineError(path, n, CellProblem(result, columns[c], cells[c + 1]));
      if (std::abs(value) > kMaxCellMagnitude) {
        return LineError(path, n,
                         "column '" + columns[c] + "': " + FormatShortest(value) +
                             " is beyond any physical value (|value| <= 1e15)");
      }
      buffer.push_back(value);
    }
    if (repeat) {
      const auto row = buffer.end() - static_cast<std::ptrdiff_t>(numeric_columns);
      if (!std::equal(row, buffer.end(), row - static_cast<std::ptrdiff_t>(numeric_columns)))
        return LineError(path, n, RepeatProblem(*t));
      buffer.erase(row, buffer.end());
      out->t.pop_back();
      ++out->duplicate_rows;
    }
  }

  // A writer ends every row with a line end: a last row without one was cut short, and a number cut short still
  // reads as a (wrong) number.
  if (!out->t.empty() && !ends_with_line_end) {
    return LineError(path, lines.line_number(), "the last row has no line end: the file looks truncated");
  }

  // Row-major buffer -> column-major matrix.
  const Eigen::Index rows = static_cast<Eigen::Index>(out->t.size());
  const Eigen::Index cols = static_cast<Eigen::Index>(numeric_columns);
  out->values = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(buffer.data(),
                                                                                                         rows, cols);
  return Status::Ok();
}

std::string FormatStreamCsv(const std::vector<std::string>& columns, const std::vector<Time>& t,
                            const Eigen::MatrixXd& values, const std::vector<std::string>* text) {
  std::string out = HeaderLine(columns) + "\n";
  out.reserve(out.size() + t.size() * (21 + 24 * static_cast<std::size_t>(values.cols())));
  for (std::size_t i = 0; i < t.size(); ++i) {
    out += FormatSeconds(t[i]);
    if (text != nullptr) {
      out += ',';
      out += (*text)[i];
    }
    for (Eigen::Index c = 0; c < values.cols(); ++c) {
      out += ',';
      AppendFull(values(static_cast<Eigen::Index>(i), c), &out);
    }
    out += '\n';
  }
  return out;
}

}  // namespace roamlab::recording::internal
