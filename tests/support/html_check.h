// A small HTML checker for the report tests: every element closed in order (void elements img, meta, br, hr, link
// excepted), the header cells of every table, the src of every image, and a strict base64 decoder for data: URIs.
#pragma once

#include <cctype>
#include <optional>
#include <string>
#include <vector>

namespace roamlab::testing {

struct HtmlSummary {
  std::string error;                                    // "" when well-formed, else what and where
  std::vector<std::vector<std::string>> table_headers;  // the <th> texts of each table, in order
  std::vector<std::string> image_sources;               // src of each <img>
};

// Strict RFC 4648 base64: length a multiple of 4, alphabet A-Z a-z 0-9 + /, at most two '=' at the end only.
inline std::optional<std::string> DecodeBase64(const std::string& text) {
  if (text.size() % 4 != 0) return std::nullopt;
  const auto value = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
  };
  std::string out;
  for (std::size_t i = 0; i < text.size(); i += 4) {
    const bool last = i + 4 == text.size();
    int pad = 0;
    unsigned word = 0;
    for (std::size_t k = 0; k < 4; ++k) {
      const char c = text[i + k];
      if (c == '=' && last && k >= 2) {
        ++pad;
        word <<= 6;
        continue;
      }
      const int v = value(c);
      if (v < 0 || pad > 0) return std::nullopt;
      word = (word << 6) | static_cast<unsigned>(v);
    }
    for (int k = 0; k < 3 - pad; ++k) out += static_cast<char>((word >> (16 - 8 * k)) & 0xff);
  }
  return out;
}

namespace internal {

inline bool IsVoidElement(const std::string& name) {
  return name == "img" || name == "meta" || name == "br" || name == "hr" || name == "link" || name == "input";
}

// The value of attribute `name` inside a tag's text, "" when absent.
inline std::string Attribute(const std::string& tag, const std::string& name) {
  const std::size_t at = tag.find(" " + name + "=\"");
  if (at == std::string::npos) return "";
  const std::size_t start = at + name.size() + 3;
  const std::size_t end = tag.find('"', start);
  return end == std::string::npos ? "" : tag.substr(start, end - start);
}

}  // namespace internal

inline HtmlSummary CheckHtml(const std::string& document) {
  HtmlSummary summary;
  std::vector<std::string> open;
  std::size_t i = 0;
  const auto fail = [&](const std::string& what) {
    summary.error = what + " at offset " + std::to_string(i);
    return summary;
  };
  while (i < document.size()) {
    if (document[i] != '<') {
      if (!open.empty() && open.back() == "th") summary.table_headers.back().back() += document[i];
      ++i;
      continue;
    }
    const std::size_t end = document.find('>', i);
    if (end == std::string::npos) return fail("unterminated tag");
    const std::string tag = document.substr(i + 1, end - i - 1);
    if (tag.empty()) return fail("empty tag");
    if (tag[0] == '!') {
      i = end + 1;
      continue;
    }
    const bool closing = tag[0] == '/';
    std::size_t n = closing ? 1 : 0;
    std::string name;
    while (n < tag.size() && std::isalnum(static_cast<unsigned char>(tag[n]))) name += tag[n++];
    if (name.empty()) return fail("a '<' that starts no tag");
    if (closing) {
      if (open.empty() || open.back() != name)
        return fail("</" + name + "> closes " + (open.empty() ? "nothing" : "<" + open.back() + ">"));
      open.pop_back();
    } else if (!internal::IsVoidElement(name) && tag.back() != '/') {
      open.push_back(name);
      if (name == "table") summary.table_headers.emplace_back();
      if (name == "th") {
        if (summary.table_headers.empty()) return fail("<th> outside a table");
        summary.table_headers.back().emplace_back();
      }
      if (name == "style") {  // raw text up to </style>
        const std::size_t close = document.find("</style>", end);
        if (close == std::string::npos) return fail("<style> never closed");
        i = close;
        continue;
      }
    } else if (name == "img") {
      summary.image_sources.push_back(internal::Attribute(tag, "src"));
    }
    i = end + 1;
  }
  if (!open.empty()) return fail("<" + open.back() + "> never closed");
  return summary;
}

}  // namespace roamlab::testing
