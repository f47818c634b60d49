// Result type for operations that can fail on bad data or at run time. The message is one line meant for the user:
// it names the file (and line, column or key) and the problem, e.g. "rec/gps.csv:12: timestamp not increasing".
// Error keeps it one line whatever it quotes from the input: a line break or other control character (a YAML parser
// naming the character it stumbled on, a key that holds "\n") is written as an escape: \n, \r, \t or \xNN.
#pragma once

#include <algorithm>
#include <optional>
#include <string>
#include <utility>
#include <variant>

#include "common/check.h"

namespace roamlab {

class Status {
 public:
  static Status Ok() { return Status(); }
  static Status Error(std::string message) { return Status(OneLine(std::move(message))); }

  bool ok() const { return !message_.has_value(); }
  const std::string& message() const {
    ROAMLAB_CHECK(!ok(), "message() on an ok Status");
    return *message_;
  }

 private:
  Status() = default;
  explicit Status(std::string message) : message_(std::move(message)) {}
  static std::string OneLine(std::string text) {
    const auto control = [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == '\x7f'; };
    if (std::none_of(text.begin(), text.end(), control)) return text;
    static constexpr char kHex[] = "0123456789abcdef";
    std::string out;
    for (const char c : text) {
      const auto byte = static_cast<unsigned char>(c);
      if (!control(c)) {
        out += c;
      } else if (c == '\n') {
        out += "\\n";
      } else if (c == '\r') {
        out += "\\r";
      } else if (c == '\t') {
        out += "\\t";
      } else {
        out += {'\\', 'x', kHex[byte >> 4], kHex[byte & 0xf]};
      }
    }
    return out;
  }
  std::optional<std::string> message_;
};

// Either a value or an error Status.
template <typename T>
class Result {
 public:
  Result(T value) : data_(std::move(value)) {}  // NOLINT
  Result(Status status) : data_(std::move(status)) {
    ROAMLAB_CHECK(!std::get<Status>(data_).ok(), "ok status");
  }  // NOLINT

  bool ok() const { return std::holds_alternative<T>(data_); }
  const Status& status() const {
    ROAMLAB_CHECK(!ok(), "status() on a Result holding a value");
    return std::get<Status>(data_);
  }
  const T& value() const& {
    ROAMLAB_CHECK(ok(), "value() on an error: " << std::get<Status>(data_).message());
    return std::get<T>(data_);
  }
  T& value() & {
    ROAMLAB_CHECK(ok(), "value() on an error: " << std::get<Status>(data_).message());
    return std::get<T>(data_);
  }
  T&& value() && {
    ROAMLAB_CHECK(ok(), "value() on an error: " << std::get<Status>(data_).message());
    return std::get<T>(std::move(data_));
  }

 private:
  std::variant<T, Status> data_;
};

}  // namespace roamlab
