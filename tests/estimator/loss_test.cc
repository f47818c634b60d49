#include "estimator/loss.h"

#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

namespace roamlab::estimator {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

double Rho(const Loss& loss, double s) {
  double rho = 0.0, rho_prime = 0.0;
  loss.Evaluate(s, &rho, &rho_prime);
  return rho;
}
double RhoPrime(const Loss& loss, double s) {
  double rho = 0.0, rho_prime = 0.0;
  loss.Evaluate(s, &rho, &rho_prime);
  return rho_prime;
}

std::vector<Loss> AllLosses() {
  return {Loss::Trivial(), Loss::Huber(1.0), Loss::Huber(2.5), Loss::Cauchy(1.0), Loss::Cauchy(0.5)};
}

const char* Name(const Loss& loss) {
  switch (loss.type) {
    case Loss::Type::kTrivial:
      return "trivial";
    case Loss::Type::kHuber:
      return "huber";
    case Loss::Type::kCauchy:
      return "cauchy";
  }
  return "?";
}

// Every loss is s near zero: rho(0) = 0 and rho'(0) = 1, so that small errors keep their Gaussian weight.
TEST(LossTest, EveryLossIsTheSquaredNormNearZero) {
  for (const Loss& loss : AllLosses()) {
    SCOPED_TRACE(::testing::Message() << Name(loss) << " " << loss.scale);
    EXPECT_EQ(Rho(loss, 0.0), 0.0);
    EXPECT_EQ(RhoPrime(loss, 0.0), 1.0);
  }
}

// rho' against central differences of rho (step h = cbrt(eps) s, away from Huber's knee at s = c^2 where rho''
// jumps), and rho'' (not provided) through central differences of rho': a robust loss is concave, rho'' <= 0, with
// 0 < rho' <= 1.
TEST(LossTest, DerivativeMatchesCentralDifferencesAndLossesAreConcave) {
  for (const Loss& loss : AllLosses()) {
    SCOPED_TRACE(::testing::Message() << Name(loss) << " " << loss.scale);
    const double c2 = loss.scale * loss.scale;
    for (const double s : {0.01, 0.3, 0.9, 1.7, 4.0, 10.0, 50.0, 400.0}) {
      if (loss.type == Loss::Type::kHuber && std::abs(s - c2) < 0.01 * c2) continue;
      const double h = std::cbrt(kEps) * s;
      const double numeric = (Rho(loss, s + h) - Rho(loss, s - h)) / (2.0 * h);
      // Truncation h^2/6 |rho'''| (rho''' ~ rho' / s^2 for these losses) plus rounding eps |rho| / h.
      const double tolerance = 10.0 * (h * h / 6.0 / (s * s) + kEps * (1.0 + Rho(loss, s)) / h);
      EXPECT_NEAR(RhoPrime(loss, s), numeric, tolerance) << "s = " << s;
      EXPECT_GT(RhoPrime(loss, s), 0.0) << "s = " << s;
      EXPECT_LE(RhoPrime(loss, s), 1.0) << "s = " << s;
      const double rho_second = (RhoPrime(loss, s + h) - RhoPrime(loss, s - h)) / (2.0 * h);
      EXPECT_LE(rho_second, 10.0 * kEps / h) << "s = " << s;
      EXPECT_LE(Rho(loss, s), s) << "s = " << s;
    }
  }
}

TEST(LossTest, ClosedForms) {
  const double s = 7.3;
  EXPECT_EQ(Rho(Loss::Trivial(), s), s);
  EXPECT_EQ(RhoPrime(Loss::Trivial(), s), 1.0);
  // Huber with c = 2: quadratic up to |r| = c, then linear in |r| = sqrt(s): rho = 2 c |r| - c^2, rho' = c / |r|.
  const Loss huber = Loss::Huber(2.0);
  EXPECT_EQ(Rho(huber, 3.0), 3.0);
  EXPECT_EQ(RhoPrime(huber, 3.0), 1.0);
  EXPECT_DOUBLE_EQ(Rho(huber, s), 4.0 * std::sqrt(s) - 4.0);
  EXPECT_DOUBLE_EQ(RhoPrime(huber, s), 2.0 / std::sqrt(s));
  // Cauchy with c = 2: rho = c^2 log(1 + s / c^2), rho' = 1 / (1 + s / c^2).
  const Loss cauchy = Loss::Cauchy(2.0);
  EXPECT_DOUBLE_EQ(Rho(cauchy, s), 4.0 * std::log(1.0 + s / 4.0));
  EXPECT_DOUBLE_EQ(RhoPrime(cauchy, s), 1.0 / (1.0 + s / 4.0));
}

// Huber's rho and rho' are continuous at the knee s = c^2.
TEST(LossTest, HuberIsContinuousAtItsKnee) {
  for (const double c : {0.5, 1.0, 3.0}) {
    const Loss huber = Loss::Huber(c);
    const double knee = c * c;
    const double above = knee * (1.0 + 1e-12);
    EXPECT_NEAR(Rho(huber, above), Rho(huber, knee), 4e-12 * knee);
    EXPECT_NEAR(RhoPrime(huber, above), RhoPrime(huber, knee), 4e-12);
  }
}

}  // namespace
}  // namespace roamlab::estimator
