// JSON helpers for the files the commands write: JSON has no NaN or Inf, so a non-finite number is written as null.
// Header only; a target that includes it links nlohmann_json.
#pragma once

#include <cmath>

#include <nlohmann/json.hpp>

namespace roamlab {

// `value`, or null when it is not finite.
inline nlohmann::json Number(double value) { return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(); }

// The elements of `values` (a std::vector<double> or an Eigen vector: size() and operator[]), each through Number().
template <typename Vector>
nlohmann::json NumberArray(const Vector& values) {
  nlohmann::json array = nlohmann::json::array();
  for (decltype(values.size()) i = 0; i < values.size(); ++i) array.push_back(Number(values[i]));
  return array;
}

}  // namespace roamlab
