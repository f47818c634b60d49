// Forward-mode dual numbers ("jets") with a fixed number of derivative slots, used to differentiate error models with
// respect to their tangent-space perturbations and their noise inputs in one evaluation (factor.h). A Jet<N> carries a
// value `a` and the gradient `v` of that value with respect to N seed variables.
#pragma once

#include <cmath>
#include <limits>

#include <Eigen/Core>

namespace roamlab::estimator {

template <int N>
struct Jet {
  using Gradient = Eigen::Matrix<double, N, 1, Eigen::DontAlign>;
  double a = 0.0;
  Gradient v = Gradient::Zero();

  Jet() = default;
  Jet(double value) : a(value), v(Gradient::Zero()) {}  // NOLINT: constants mix freely with jets
  Jet(double value, int slot) : a(value), v(Gradient::Zero()) { v[slot] = 1.0; }
  Jet(double value, const Gradient& gradient) : a(value), v(gradient) {}

  Jet& operator+=(const Jet& o) {
    a += o.a;
    v += o.v;
    return *this;
  }
  Jet& operator-=(const Jet& o) {
    a -= o.a;
    v -= o.v;
    return *this;
  }
  Jet& operator*=(const Jet& o) {
    v = v * o.a + o.v * a;
    a *= o.a;
    return *this;
  }
  Jet& operator/=(const Jet& o) {
    const double inv = 1.0 / o.a;
    a *= inv;
    v = (v - a * o.v) * inv;
    return *this;
  }
  Jet& operator+=(double s) {
    a += s;
    return *this;
  }
  Jet& operator-=(double s) {
    a -= s;
    return *this;
  }
  Jet& operator*=(double s) {
    a *= s;
    v *= s;
    return *this;
  }
  Jet& operator/=(double s) {
    a /= s;
    v /= s;
    return *this;
  }
};

template <int N>
Jet<N> operator-(const Jet<N>& x) {
  return Jet<N>(-x.a, -x.v);
}
template <int N>
Jet<N> operator+(const Jet<N>& x) {
  return x;
}
template <int N>
Jet<N> operator+(Jet<N> x, const Jet<N>& y) {
  return x += y;
}
template <int N>
Jet<N> operator-(Jet<N> x, const Jet<N>& y) {
  return x -= y;
}
template <int N>
Jet<N> operator*(const Jet<N>& x, const Jet<N>& y) {
  return Jet<N>(x.a * y.a, x.v * y.a + y.v * x.a);
}
template <int N>
Jet<N> operator/(const Jet<N>& x, const Jet<N>& y) {
  const double inv = 1.0 / y.a;
  const double q = x.a * inv;
  return Jet<N>(q, (x.v - q * y.v) * inv);
}
template <int N>
Jet<N> operator+(Jet<N> x, double s) {
  return x += s;
}
template <int N>
Jet<N> operator+(double s, Jet<N> x) {
  return x += s;
}
template <int N>
Jet<N> operator-(Jet<N> x, double s) {
  return x -= s;
}
template <int N>
Jet<N> operator-(double s, const Jet<N>& x) {
  return Jet<N>(s - x.a, -x.v);
}
template <int N>
Jet<N> operator*(Jet<N> x, double s) {
  return x *= s;
}
template <int N>
Jet<N> operator*(double s, Jet<N> x) {
  return x *= s;
}
template <int N>
Jet<N> operator/(Jet<N> x, double s) {
  return x /= s;
}
template <int N>
Jet<N> operator/(double s, const Jet<N>& x) {
  const double inv = 1.0 / x.a;
  return Jet<N>(s * inv, -s * inv * inv * x.v);
}

// Comparisons look at the value only.
template <int N>
bool operator<(const Jet<N>& x, const Jet<N>& y) {
  return x.a < y.a;
}
template <int N>
bool operator>(const Jet<N>& x, const Jet<N>& y) {
  return x.a > y.a;
}
template <int N>
bool operator<=(const Jet<N>& x, const Jet<N>& y) {
  return x.a <= y.a;
}
template <int N>
bool operator>=(const Jet<N>& x, const Jet<N>& y) {
  return x.a >= y.a;
}
template <int N>
bool operator==(const Jet<N>& x, const Jet<N>& y) {
  return x.a == y.a;
}
template <int N>
bool operator!=(const Jet<N>& x, const Jet<N>& y) {
  return x.a != y.a;
}
template <int N>
bool operator<(const Jet<N>& x, double y) {
  return x.a < y;
}
template <int N>
bool operator>(const Jet<N>& x, double y) {
  return x.a > y;
}
template <int N>
bool operator<(double x, const Jet<N>& y) {
  return x < y.a;
}
template <int N>
bool operator>(double x, const Jet<N>& y) {
  return x > y.a;
}

template <int N>
Jet<N> sqrt(const Jet<N>& x) {
  const double s = std::sqrt(x.a);
  return Jet<N>(s, x.v * (0.5 / s));
}
template <int N>
Jet<N> sin(const Jet<N>& x) {
  return Jet<N>(std::sin(x.a), x.v * std::cos(x.a));
}
template <int N>
Jet<N> cos(const Jet<N>& x) {
  return Jet<N>(std::cos(x.a), x.v * -std::sin(x.a));
}
template <int N>
Jet<N> tan(const Jet<N>& x) {
  const double t = std::tan(x.a);
  return Jet<N>(t, x.v * (1.0 + t * t));
}
template <int N>
Jet<N> atan(const Jet<N>& x) {
  return Jet<N>(std::atan(x.a), x.v / (1.0 + x.a * x.a));
}
template <int N>
Jet<N> atan2(const Jet<N>& y, const Jet<N>& x) {
  const double r2 = x.a * x.a + y.a * y.a;
  return Jet<N>(std::atan2(y.a, x.a), (y.v * x.a - x.v * y.a) / r2);
}
template <int N>
Jet<N> exp(const Jet<N>& x) {
  const double e = std::exp(x.a);
  return Jet<N>(e, x.v * e);
}
template <int N>
Jet<N> log(const Jet<N>& x) {
  return Jet<N>(std::log(x.a), x.v / x.a);
}
template <int N>
Jet<N> abs(const Jet<N>& x) {
  return x.a < 0.0 ? -x : x;
}
template <int N>
Jet<N> abs2(const Jet<N>& x) {
  return x * x;
}
template <int N>
bool isfinite(const Jet<N>& x) {
  return std::isfinite(x.a) && x.v.allFinite();
}
template <int N>
bool isnan(const Jet<N>& x) {
  return std::isnan(x.a) || x.v.hasNaN();
}
template <int N>
bool isinf(const Jet<N>& x) {
  return std::isinf(x.a);
}

// Value part of a double or a jet, for branches that only look at the value.
inline double ValueOf(double x) { return x; }
template <int N>
double ValueOf(const Jet<N>& x) {
  return x.a;
}

}  // namespace roamlab::estimator

namespace Eigen {

template <int N>
struct NumTraits<roamlab::estimator::Jet<N>> : GenericNumTraits<roamlab::estimator::Jet<N>> {
  using Real = roamlab::estimator::Jet<N>;
  using NonInteger = roamlab::estimator::Jet<N>;
  using Nested = roamlab::estimator::Jet<N>;
  using Literal = roamlab::estimator::Jet<N>;
  enum {
    IsComplex = 0,
    IsInteger = 0,
    IsSigned = 1,
    RequireInitialization = 1,
    ReadCost = 1 + N,
    AddCost = 1 + N,
    MulCost = 1 + 2 * N,
  };
  static inline Real epsilon() { return Real(std::numeric_limits<double>::epsilon()); }
  static inline Real dummy_precision() { return Real(1e-12); }
  static inline Real highest() { return Real(std::numeric_limits<double>::max()); }
  static inline Real lowest() { return Real(-std::numeric_limits<double>::max()); }
  static inline int digits10() { return NumTraits<double>::digits10(); }
};

template <int N, typename BinaryOp>
struct ScalarBinaryOpTraits<roamlab::estimator::Jet<N>, double, BinaryOp> {
  using ReturnType = roamlab::estimator::Jet<N>;
};
template <int N, typename BinaryOp>
struct ScalarBinaryOpTraits<double, roamlab::estimator::Jet<N>, BinaryOp> {
  using ReturnType = roamlab::estimator::Jet<N>;
};

}  // namespace Eigen
