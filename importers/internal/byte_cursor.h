// Bounds-checked little-endian reads from a byte buffer, shared by the bag readers and the message decoders. A read
// past the end returns zero bytes / a zero value and turns ok() false for good, so a decoder reads a whole message and
// checks once: a declared length never makes it read past the buffer.
#pragma once

#include <cstdint>
#include <cstring>
#include <string_view>

namespace roamlab::importers::internal {

class ByteCursor {
 public:
  explicit ByteCursor(std::string_view data) : data_(data) {}
  bool ok() const { return ok_; }
  std::size_t position() const { return position_; }
  std::size_t remaining() const { return ok_ ? data_.size() - position_ : 0; }
  bool done() const { return position_ >= data_.size(); }

  std::string_view Bytes(std::size_t n) {
    if (!ok_ || n > data_.size() - position_) {
      ok_ = false;
      return {};
    }
    const std::string_view out = data_.substr(position_, n);
    position_ += n;
    return out;
  }
  template <typename T>
  T Read() {
    T value{};
    const std::string_view b = Bytes(sizeof(T));
    if (ok_) std::memcpy(&value, b.data(), sizeof(T));
    return value;
  }
  std::uint32_t U32() { return Read<std::uint32_t>(); }
  std::uint64_t U64() { return Read<std::uint64_t>(); }
  double F64() { return Read<double>(); }
  void Skip(std::size_t n) { Bytes(n); }
  // Moves to `offset` from the buffer's start (CDR alignment); past the end turns ok() false.
  void Seek(std::size_t offset) {
    if (offset > data_.size()) ok_ = false;
    if (ok_) position_ = offset;
  }

 private:
  std::string_view data_;
  std::size_t position_ = 0;
  bool ok_ = true;
};

}  // namespace roamlab::importers::internal
