// Programmer errors (wrong sizes, broken invariants) abort through ROAMLAB_CHECK with file, line and message.
// Bad data and runtime failures are reported through roamlab::Status instead (common/status.h).
#pragma once

#include <sstream>
#include <string>

namespace roamlab::internal {
[[noreturn]] void CheckFailed(const char* file, int line, const char* condition, const std::string& message);
}  // namespace roamlab::internal

#define ROAMLAB_CHECK(condition, message)                                                           \
  do {                                                                                              \
    if (!(condition)) {                                                                             \
      std::ostringstream roamlab_check_stream;                                                      \
      roamlab_check_stream << message;                                                              \
      ::roamlab::internal::CheckFailed(__FILE__, __LINE__, #condition, roamlab_check_stream.str()); \
    }                                                                                               \
  } while (false)
