#include "common/chi_square.h"

#include <cmath>
#include <limits>

#include "common/check.h"

namespace roamlab {
namespace {

// Regularized lower incomplete gamma P(a, x): series for x < a + 1, Lentz continued fraction otherwise
// (Numerical Recipes' split; written here from the standard formulas).
double RegularizedGammaP(double a, double x) {
  if (x <= 0.0) return 0.0;
  const double log_prefactor = a * std::log(x) - x - std::lgamma(a);
  if (x < a + 1.0) {
    double term = 1.0 / a;
    double sum = term;
    for (int n = 1; n < 10000; ++n) {
      term *= x / (a + n);
      sum += term;
      if (std::abs(term) < std::abs(sum) * 1e-16) break;
    }
    return sum * std::exp(log_prefactor);
  }
  const double tiny = 1e-300;
  double b = x + 1.0 - a;
  double c = 1.0 / tiny;
  double d = 1.0 / b;
  double h = d;
  for (int i = 1; i < 10000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < tiny) d = tiny;
    c = b + an / c;
    if (std::abs(c) < tiny) c = tiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < 1e-16) break;
  }
  return 1.0 - std::exp(log_prefactor) * h;
}

}  // namespace

double ChiSquareCdf(double x, double dof) {
  ROAMLAB_CHECK(dof > 0.0, "dof must be positive, got " << dof);
  if (x <= 0.0) return 0.0;
  return RegularizedGammaP(0.5 * dof, 0.5 * x);
}

double ChiSquareQuantile(double p, double dof) {
  ROAMLAB_CHECK(p > 0.0 && p < 1.0, "probability must be in (0, 1), got " << p);
  ROAMLAB_CHECK(dof > 0.0, "dof must be positive, got " << dof);
  // Bracket, then bisect on the monotone CDF.
  double lo = 0.0;
  double hi = dof + 10.0 * std::sqrt(2.0 * dof) + 10.0;
  while (ChiSquareCdf(hi, dof) < p) hi *= 2.0;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (ChiSquareCdf(mid, dof) < p) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  return 0.5 * (lo + hi);
}

Interval AverageNeesBand(int runs, int dof, double alpha) {
  ROAMLAB_CHECK(runs > 0 && dof > 0, "runs and dof must be positive");
  const double n = static_cast<double>(runs) * dof;
  return {ChiSquareQuantile(0.5 * alpha, n) / runs, ChiSquareQuantile(1.0 - 0.5 * alpha, n) / runs};
}

}  // namespace roamlab
