// Robust losses on the squared norm s of a whitened error (GTSAM/Ceres style: a separate object from the error model
// and its noise). The cost of one error is rho(s)/2, with rho(s) = s for the
// trivial loss, so that the total cost is 1/2 sum rho(s_i).
#pragma once

#include <cmath>
#include <string>

namespace roamlab::estimator {

struct Loss {
  enum class Type { kTrivial, kHuber, kCauchy };
  Type type = Type::kTrivial;
  double scale = 1.0;  // in units of whitened error (standard deviations); must be > 0

  static Loss Trivial() { return {}; }
  static Loss Huber(double c) { return {Type::kHuber, c}; }
  static Loss Cauchy(double c) { return {Type::kCauchy, c}; }

  // rho(s) and rho'(s) for s = |r|^2 >= 0.
  void Evaluate(double s, double* rho, double* rho_prime) const {
    const double c2 = scale * scale;
    switch (type) {
      case Type::kTrivial:
        *rho = s;
        *rho_prime = 1.0;
        return;
      case Type::kHuber:
        if (s <= c2) {
          *rho = s;
          *rho_prime = 1.0;
        } else {
          const double r = std::sqrt(s);
          *rho = 2.0 * scale * r - c2;
          *rho_prime = scale / r;
        }
        return;
      case Type::kCauchy:
        *rho = c2 * std::log1p(s / c2);
        *rho_prime = 1.0 / (1.0 + s / c2);
        return;
    }
  }
};

}  // namespace roamlab::estimator
