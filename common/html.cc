#include "common/html.h"

#include <algorithm>
#include <fstream>
#include <iterator>
#include <sstream>

#include "common/atomic_file.h"

namespace roamlab::html {
namespace {

const char kStyle[] =
    "body{font-family:sans-serif;max-width:1150px;margin:1.5em auto;padding:0 1em;color:#222}"
    "h1{border-bottom:2px solid #444}h2{border-bottom:1px solid #aaa;margin-top:1.6em}"
    "table{border-collapse:collapse;margin:0.6em 0;font-size:0.9em}"
    "th,td{border:1px solid #bbb;padding:3px 8px;text-align:left;vertical-align:top}"
    "th{background:#eee}tr:nth-child(even) td{background:#f8f8f8}"
    "td{font-family:monospace}"
    "p.verdict-pass,p.verdict-fail,p.note{padding:0.6em 1em;border-radius:4px;font-weight:bold}"
    "p.verdict-pass{background:#e3f4e3;border:1px solid #4a4}p.verdict-fail{background:#fbe5e5;border:1px solid #c44}"
    "p.headline{font-size:1.1em;padding:0.6em 1em;background:#eef3fb;border:1px solid #7a9cd0}"
    "p.note{background:#fff7dd;border:1px solid #cb4;font-weight:normal}"
    "figure{margin:1em 0}figure img{max-width:100%;border:1px solid #ccc}figcaption{font-size:0.9em;color:#555}";

}  // namespace

std::string Escape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string Base64(const std::string& bytes) {
  static const char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::size_t n = std::min<std::size_t>(3, bytes.size() - i);
    unsigned word = 0;
    for (std::size_t k = 0; k < 3; ++k) word = (word << 8) | (k < n ? static_cast<unsigned char>(bytes[i + k]) : 0u);
    for (std::size_t k = 0; k < 4; ++k) out += k <= n ? kAlphabet[(word >> (18 - 6 * k)) & 0x3f] : '=';
  }
  return out;
}

Page::Page(std::string title) : title_(std::move(title)) {}

void Page::Heading(int level, const std::string& text) {
  const std::string tag = "h" + std::to_string(std::clamp(level, 1, 4));
  body_ += "<" + tag + ">" + Escape(text) + "</" + tag + ">\n";
}

void Page::Paragraph(const std::string& text, const std::string& css_class) {
  body_ += css_class.empty() ? "<p>" : "<p class=\"" + Escape(css_class) + "\">";
  body_ += Escape(text) + "</p>\n";
}

void Page::AddTable(const Table& table) {
  body_ += "<table>\n<thead><tr>";
  for (const std::string& cell : table.header) body_ += "<th>" + Escape(cell) + "</th>";
  body_ += "</tr></thead>\n<tbody>\n";
  for (const std::vector<std::string>& row : table.rows) {
    body_ += "<tr>";
    for (const std::string& cell : row) body_ += "<td>" + Escape(cell) + "</td>";
    body_ += "</tr>\n";
  }
  body_ += "</tbody>\n</table>\n";
}

Status Page::AddImage(const std::string& png_path, const std::string& caption) {
  std::ifstream in(png_path, std::ios::binary);
  if (!in) return Status::Error(png_path + ": cannot read the figure");
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  body_ += "<figure><img alt=\"" + Escape(caption) + "\" src=\"data:image/png;base64," + Base64(bytes) +
           "\" /><figcaption>" + Escape(caption) + "</figcaption></figure>\n";
  return Status::Ok();
}

std::string Page::Document() const {
  return "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\" />\n<title>" + Escape(title_) +
         "</title>\n<style>" + kStyle + "</style>\n</head>\n<body>\n<h1>" + Escape(title_) + "</h1>\n" + body_ +
         "</body>\n</html>\n";
}

Status Page::Write(const std::string& path) const { return WriteFileAtomic(path, Document()); }

}  // namespace roamlab::html
