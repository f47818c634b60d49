#include "estimator/jet.h"

#include <cmath>
#include <functional>
#include <limits>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Core>

namespace roamlab::estimator {
namespace {

using J2 = Jet<2>;

constexpr double kEps = std::numeric_limits<double>::epsilon();

// A jet of value a whose gradient is (da_dx, da_dy): a function of two seed variables x and y.
J2 MakeJet(double a, double da_dx, double da_dy) { return J2(a, J2::Gradient(da_dx, da_dy)); }

// Value and gradient of `got` against an analytic value and gradient, to a few ulps of their scale.
void ExpectJet(const J2& got, double value, double d_dx, double d_dy) {
  const double scale = 1.0 + std::abs(value) + std::abs(d_dx) + std::abs(d_dy);
  EXPECT_NEAR(got.a, value, 8 * kEps * scale);
  EXPECT_NEAR(got.v[0], d_dx, 8 * kEps * scale);
  EXPECT_NEAR(got.v[1], d_dy, 8 * kEps * scale);
}

TEST(JetTest, ConstructorsSeedTheGradient) {
  const J2 constant(3.0);
  EXPECT_EQ(constant.a, 3.0);
  EXPECT_EQ(constant.v, J2::Gradient::Zero());
  const J2 seeded(2.0, 1);
  EXPECT_EQ(seeded.a, 2.0);
  EXPECT_EQ(seeded.v, J2::Gradient(0.0, 1.0));
  const J2 defaulted;
  EXPECT_EQ(defaulted.a, 0.0);
  EXPECT_EQ(defaulted.v, J2::Gradient::Zero());
}

// With x = 1.5 and y = -0.5 seeded in slots 0 and 1, each operation's derivatives are the textbook ones.
TEST(JetTest, ArithmeticFollowsTheSumProductAndQuotientRules) {
  const double xv = 1.5, yv = -0.5;
  const J2 x(xv, 0), y(yv, 1);
  ExpectJet(x + y, xv + yv, 1.0, 1.0);
  ExpectJet(x - y, xv - yv, 1.0, -1.0);
  ExpectJet(-x, -xv, -1.0, 0.0);
  ExpectJet(+y, yv, 0.0, 1.0);
  ExpectJet(x * y, xv * yv, yv, xv);
  ExpectJet(x / y, xv / yv, 1.0 / yv, -xv / (yv * yv));
  ExpectJet(x + 2.0, xv + 2.0, 1.0, 0.0);
  ExpectJet(2.0 + x, xv + 2.0, 1.0, 0.0);
  ExpectJet(x - 2.0, xv - 2.0, 1.0, 0.0);
  ExpectJet(2.0 - y, 2.0 - yv, 0.0, -1.0);
  ExpectJet(x * 3.0, 3.0 * xv, 3.0, 0.0);
  ExpectJet(3.0 * y, 3.0 * yv, 0.0, 3.0);
  ExpectJet(x / 4.0, xv / 4.0, 0.25, 0.0);
  ExpectJet(4.0 / y, 4.0 / yv, 0.0, -4.0 / (yv * yv));
  // Compound assignments match the binary operators.
  J2 z = x;
  z += y;
  ExpectJet(z, xv + yv, 1.0, 1.0);
  z = x;
  z -= y;
  ExpectJet(z, xv - yv, 1.0, -1.0);
  z = x;
  z *= y;
  ExpectJet(z, xv * yv, yv, xv);
  z = x;
  z /= y;
  ExpectJet(z, xv / yv, 1.0 / yv, -xv / (yv * yv));
  z = x;
  z += 2.0;
  ExpectJet(z, xv + 2.0, 1.0, 0.0);
  z = x;
  z -= 2.0;
  ExpectJet(z, xv - 2.0, 1.0, 0.0);
  z = y;
  z *= 3.0;
  ExpectJet(z, 3.0 * yv, 0.0, 3.0);
  z = y;
  z /= 4.0;
  ExpectJet(z, yv / 4.0, 0.0, 0.25);
}

// Each elementary function applied to u(x, y) = x + 2 y (a jet with gradient (1, 2)): f(u) with gradient f'(u) (1, 2).
TEST(JetTest, ElementaryFunctionsFollowTheChainRule) {
  struct Case {
    const char* name;
    double u;
    std::function<J2(const J2&)> f;
    double value;
    double derivative;
  };
  const std::vector<Case> cases = {
      {"sqrt", 2.0, [](const J2& u) { return sqrt(u); }, std::sqrt(2.0), 0.5 / std::sqrt(2.0)},
      {"sin", 0.7, [](const J2& u) { return sin(u); }, std::sin(0.7), std::cos(0.7)},
      {"cos", 0.7, [](const J2& u) { return cos(u); }, std::cos(0.7), -std::sin(0.7)},
      {"tan", 0.7, [](const J2& u) { return tan(u); }, std::tan(0.7), 1.0 / (std::cos(0.7) * std::cos(0.7))},
      {"atan", -1.3, [](const J2& u) { return atan(u); }, std::atan(-1.3), 1.0 / (1.0 + 1.3 * 1.3)},
      {"exp", 0.4, [](const J2& u) { return exp(u); }, std::exp(0.4), std::exp(0.4)},
      {"log", 2.5, [](const J2& u) { return log(u); }, std::log(2.5), 1.0 / 2.5},
      {"abs of a negative", -0.8, [](const J2& u) { return abs(u); }, 0.8, -1.0},
      {"abs of a positive", 0.8, [](const J2& u) { return abs(u); }, 0.8, 1.0},
      {"abs2", -0.8, [](const J2& u) { return abs2(u); }, 0.64, -1.6},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    ExpectJet(c.f(MakeJet(c.u, 1.0, 2.0)), c.value, c.derivative, 2.0 * c.derivative);
  }
}

// atan2(y, x) has gradient (-y, x) / (x^2 + y^2) in (x, y), in every quadrant.
TEST(JetTest, Atan2HasTheGradientOfTheAngle) {
  for (const double angle : {0.3, 2.0, -2.5, -0.4}) {
    const double r = 1.7;
    const double xv = r * std::cos(angle), yv = r * std::sin(angle);
    const J2 result = atan2(J2(yv, 1), J2(xv, 0));
    ExpectJet(result, angle, -yv / (r * r), xv / (r * r));
  }
}

// Central differences of a composite against its jet: sqrt(x^2 + y^2) sin(x / y) exp(-y) at a few points.
TEST(JetTest, CompositeMatchesCentralDifferences) {
  const auto f = [](const auto& x, const auto& y) {
    using std::exp;
    using std::sin;
    using std::sqrt;
    return sqrt(x * x + y * y) * sin(x / y) * exp(-y);
  };
  const double h = std::cbrt(kEps);
  for (const auto& [xv, yv] : std::vector<std::pair<double, double>>{{0.5, 1.2}, {-1.0, 0.7}, {2.0, -1.5}}) {
    const J2 result = f(J2(xv, 0), J2(yv, 1));
    EXPECT_NEAR(result.a, f(xv, yv), 8 * kEps * (1.0 + std::abs(f(xv, yv))));  // (x / y is x * (1 / y))
    const double d_dx = (f(xv + h, yv) - f(xv - h, yv)) / (2 * h);
    const double d_dy = (f(xv, yv + h) - f(xv, yv - h)) / (2 * h);
    // Truncation h^2/6 f''' plus rounding eps f / h, f and its derivatives of order 10 here.
    const double tolerance = 10.0 * (h * h / 6.0 + kEps / h) * 10.0;
    EXPECT_NEAR(result.v[0], d_dx, tolerance) << xv << ", " << yv;
    EXPECT_NEAR(result.v[1], d_dy, tolerance) << xv << ", " << yv;
  }
}

TEST(JetTest, ComparisonsLookAtTheValueOnly) {
  const J2 a(1.0, 0), b(1.0, 1), c(2.0, 0);
  EXPECT_TRUE(a == b);
  EXPECT_FALSE(a != b);
  EXPECT_TRUE(a < c);
  EXPECT_TRUE(c > a);
  EXPECT_TRUE(a <= b);
  EXPECT_TRUE(a >= b);
  EXPECT_TRUE(a < 1.5);
  EXPECT_TRUE(c > 1.5);
  EXPECT_TRUE(0.5 < a);
  EXPECT_TRUE(2.5 > c);
  EXPECT_EQ(ValueOf(c), 2.0);
  EXPECT_EQ(ValueOf(2.0), 2.0);
}

TEST(JetTest, ClassificationLooksAtValueAndGradient) {
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(isfinite(J2(1.0, 0)));
  EXPECT_FALSE(isfinite(MakeJet(1.0, inf, 0.0)));
  EXPECT_FALSE(isfinite(J2(inf)));
  EXPECT_TRUE(isnan(MakeJet(1.0, nan, 0.0)));
  EXPECT_TRUE(isnan(J2(nan)));
  EXPECT_FALSE(isnan(J2(1.0, 1)));
  EXPECT_TRUE(isinf(J2(-inf)));
  EXPECT_FALSE(isinf(MakeJet(1.0, inf, 0.0)));  // the value only
}

// Jets as Eigen scalars (NumTraits, mixed products with doubles): the derivative of A x with x seeded is A.
TEST(JetTest, WorkAsEigenScalars) {
  Eigen::Matrix2d A;
  A << 1.0, 2.0, -3.0, 0.5;
  const Eigen::Matrix<J2, 2, 1> x(J2(0.3, 0), J2(-0.2, 1));
  const Eigen::Matrix<J2, 2, 1> y = A.cast<J2>() * x;
  for (int i = 0; i < 2; ++i) {
    EXPECT_DOUBLE_EQ(y[i].a, A(i, 0) * 0.3 + A(i, 1) * -0.2);
    EXPECT_EQ(y[i].v.transpose(), A.row(i));
  }
  const J2 n = x.squaredNorm();
  ExpectJet(n, 0.13, 0.6, -0.4);
  EXPECT_EQ(Eigen::NumTraits<J2>::epsilon().a, kEps);
}

}  // namespace
}  // namespace roamlab::estimator
