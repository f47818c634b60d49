// Control profiles (sim/profile.h): each term's formula, sums, windows, and the validation messages.
#include "sim/profile.h"

#include <cmath>

#include <gtest/gtest.h>

namespace roamlab::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;

ProfileTerm Sine(double amplitude, double period_s, double phase_rad) {
  ProfileTerm t;
  t.type = ProfileTerm::Type::kSine;
  t.amplitude = amplitude;
  t.period_s = period_s;
  t.phase_rad = phase_rad;
  return t;
}

TEST(ProfileTest, ConstantAndSineSum) {
  Profile p = Profile::Constant(4.5);
  p.terms.push_back(Sine(1.0, 13.0, 0.0));
  p.terms.push_back(Sine(0.4, 4.7, 0.6));
  for (double t : {0.0, 1.3, 7.77, 29.0}) {
    const double expected = 4.5 + std::sin(2 * kPi * t / 13.0) + 0.4 * std::sin(2 * kPi * t / 4.7 + 0.6);
    EXPECT_NEAR(p.Evaluate(t), expected, 1e-12) << t;
  }
  EXPECT_EQ(Profile{}.Evaluate(3.0), 0.0);
}

TEST(ProfileTest, SquareSwitchesSignEveryHalfPeriod) {
  ProfileTerm t = Sine(0.5, 4.0, 0.0);
  t.type = ProfileTerm::Type::kSquare;
  EXPECT_EQ(t.Evaluate(0.5), 0.5);
  EXPECT_EQ(t.Evaluate(1.9), 0.5);
  EXPECT_EQ(t.Evaluate(2.1), -0.5);
  EXPECT_EQ(t.Evaluate(3.9), -0.5);
  EXPECT_EQ(t.Evaluate(4.1), 0.5);
}

TEST(ProfileTest, RampHoldsItsEndValues) {
  ProfileTerm t;
  t.type = ProfileTerm::Type::kRamp;
  t.start_s = 5.0;
  t.end_s = 8.0;
  t.from = 1.0;
  t.to = -2.0;
  EXPECT_EQ(t.Evaluate(0.0), 1.0);
  EXPECT_NEAR(t.Evaluate(6.5), -0.5, 1e-12);
  EXPECT_EQ(t.Evaluate(100.0), -2.0);
}

TEST(ProfileTest, PiecewiseLinearAndStep) {
  ProfileTerm t;
  t.type = ProfileTerm::Type::kPiecewise;
  t.times_s = {0.0, 10.0, 20.0};
  t.values = {0.0, 1.0, -1.0};
  EXPECT_EQ(t.Evaluate(-1.0), 0.0);
  EXPECT_NEAR(t.Evaluate(5.0), 0.5, 1e-12);
  EXPECT_NEAR(t.Evaluate(15.0), 0.0, 1e-12);
  EXPECT_EQ(t.Evaluate(25.0), -1.0);
  t.interpolation = ProfileTerm::Interpolation::kStep;
  EXPECT_EQ(t.Evaluate(5.0), 0.0);
  EXPECT_EQ(t.Evaluate(10.0), 1.0);
  EXPECT_EQ(t.Evaluate(19.99), 1.0);
}

TEST(ProfileTest, WindowLimitsATerm) {
  ProfileTerm t;
  t.value = 2.0;
  t.windowed = true;
  t.window_begin_s = 1.0;
  t.window_end_s = 3.0;
  EXPECT_EQ(t.Evaluate(0.5), 0.0);
  EXPECT_EQ(t.Evaluate(1.0), 2.0);
  EXPECT_EQ(t.Evaluate(3.0), 0.0);
}

TEST(ProfileTest, ValidateNamesTheField) {
  EXPECT_EQ(Sine(1.0, 2.0, 0.0).Validate(), "");
  EXPECT_NE(Sine(1.0, 0.0, 0.0).Validate().find("period_s"), std::string::npos);
  ProfileTerm piecewise;
  piecewise.type = ProfileTerm::Type::kPiecewise;
  piecewise.times_s = {0.0, 0.0};
  piecewise.values = {1.0, 2.0};
  EXPECT_NE(piecewise.Validate().find("strictly increasing"), std::string::npos);
  piecewise.values = {1.0};
  EXPECT_NE(piecewise.Validate().find("same length"), std::string::npos);
}

}  // namespace
}  // namespace roamlab::sim
