// Self-contained HTML pages: one file with inline CSS, PNG figures embedded as data: URIs (base64), no JavaScript, so
// that a report can be mailed, archived or opened from anywhere. Text is escaped; the structure is a flat sequence of
// headings, paragraphs, tables and figures, every element closed.
#pragma once

#include <string>
#include <vector>

#include "common/status.h"

namespace roamlab::html {

// `text` with &, <, >, " and ' replaced by their character references.
std::string Escape(const std::string& text);

// Standard base64 (RFC 4648, alphabet A-Z a-z 0-9 + /, '=' padding, no line breaks) of arbitrary bytes.
std::string Base64(const std::string& bytes);

// A table: header cells and rows of plain-text cells (escaped when written).
struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
};

class Page {
 public:
  explicit Page(std::string title);

  // <h1>..<h4> (level clamped to 1..4).
  void Heading(int level, const std::string& text);
  // <p>; css_class "headline", "verdict-pass", "verdict-fail" or "note" gives a coloured box, "" a plain paragraph.
  void Paragraph(const std::string& text, const std::string& css_class = "");
  void AddTable(const Table& table);
  // <figure> with the PNG at png_path embedded and the caption below. Errors: the file cannot be read.
  Status AddImage(const std::string& png_path, const std::string& caption);

  // The whole document.
  std::string Document() const;
  // Writes Document() to path. Errors name the path.
  Status Write(const std::string& path) const;

 private:
  std::string title_;
  std::string body_;
};

}  // namespace roamlab::html
