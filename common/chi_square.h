// Chi-square distribution: CDF and quantile, for outlier gating (estimator), consistency bands (eval) and
// per-stream residual tests (gap diagnosis).
#pragma once

namespace roamlab {

// P(X <= x) for X ~ chi-square(dof). dof > 0, x >= 0. Regularized lower incomplete gamma P(dof/2, x/2).
double ChiSquareCdf(double x, double dof);

// The x with ChiSquareCdf(x, dof) = p, for 0 < p < 1. Accurate to about 1e-10 relative.
double ChiSquareQuantile(double p, double dof);

// Two-sided (1 - alpha) interval of the average NEES over `runs` runs of a `dof`-dimensional state:
// [Q(alpha/2), Q(1 - alpha/2)] of chi-square(runs * dof), divided by runs. For runs = 50, dof = 3, alpha = 0.05
// this is [2.359, 3.716] (Bar-Shalom et al., 5.4.2).
struct Interval {
  double lo;
  double hi;
};
Interval AverageNeesBand(int runs, int dof, double alpha = 0.05);

}  // namespace roamlab
