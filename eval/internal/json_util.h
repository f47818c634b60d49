// JSON helpers shared by the eval sources: non-finite numbers become null (JSON has no NaN or Inf).
#pragma once

#include <cmath>
#include <vector>

#include <nlohmann/json.hpp>

namespace roamlab::eval::internal {

inline nlohmann::json Number(double value) { return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(); }

inline nlohmann::json NumberArray(const std::vector<double>& values) {
  nlohmann::json array = nlohmann::json::array();
  for (double v : values) array.push_back(Number(v));
  return array;
}

}  // namespace roamlab::eval::internal
