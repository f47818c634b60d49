#include "sim/profile.h"

#include <algorithm>
#include <cmath>

namespace roamlab::sim {
namespace {
constexpr double kPi = 3.14159265358979323846;
}  // namespace

double ProfileTerm::Evaluate(double t) const {
  if (windowed && (t < window_begin_s || t >= window_end_s)) return 0.0;
  switch (type) {
    case Type::kConstant:
      return value;
    case Type::kSine:
      return amplitude * std::sin(2.0 * kPi * t / period_s + phase_rad);
    case Type::kSquare: {
      const double s = std::sin(2.0 * kPi * t / period_s + phase_rad);
      return s >= 0.0 ? amplitude : -amplitude;
    }
    case Type::kRamp:
      if (t <= start_s) return from;
      if (t >= end_s) return to;
      return from + (to - from) * (t - start_s) / (end_s - start_s);
    case Type::kPiecewise: {
      if (t <= times_s.front()) return values.front();
      if (t >= times_s.back()) return values.back();
      // The segment [times_s[i], times_s[i + 1]) that holds t.
      const auto it = std::upper_bound(times_s.begin(), times_s.end(), t);
      const std::size_t i = static_cast<std::size_t>(it - times_s.begin()) - 1;
      if (interpolation == Interpolation::kStep) return values[i];
      const double f = (t - times_s[i]) / (times_s[i + 1] - times_s[i]);
      return values[i] + f * (values[i + 1] - values[i]);
    }
  }
  return 0.0;
}

std::string ProfileTerm::Validate() const {
  const auto finite = [](double x) { return std::isfinite(x); };
  if (windowed && !(finite(window_begin_s) && finite(window_end_s) && window_begin_s < window_end_s))
    return "window_s must be [begin, end] with begin < end";
  switch (type) {
    case Type::kConstant:
      return finite(value) ? "" : "value must be finite";
    case Type::kSine:
    case Type::kSquare:
      if (!(finite(period_s) && period_s > 0.0)) return "period_s must be > 0";
      if (!finite(amplitude) || !finite(phase_rad)) return "amplitude and phase_rad must be finite";
      return "";
    case Type::kRamp:
      if (!(finite(start_s) && finite(end_s) && end_s > start_s)) return "end_s must be > start_s";
      if (!finite(from) || !finite(to)) return "from and to must be finite";
      return "";
    case Type::kPiecewise:
      if (times_s.empty()) return "times_s must not be empty";
      if (times_s.size() != values.size()) return "times_s and values must have the same length";
      for (std::size_t i = 0; i < times_s.size(); ++i) {
        if (!finite(times_s[i]) || !finite(values[i])) return "times_s and values must be finite";
        if (i > 0 && !(times_s[i] > times_s[i - 1])) return "times_s must be strictly increasing";
      }
      return "";
  }
  return "unknown term type";
}

Profile Profile::Constant(double value) {
  Profile profile;
  ProfileTerm term;
  term.type = ProfileTerm::Type::kConstant;
  term.value = value;
  profile.terms.push_back(term);
  return profile;
}

double Profile::Evaluate(double t) const {
  double sum = 0.0;
  for (const ProfileTerm& term : terms) sum += term.Evaluate(t);
  return sum;
}

}  // namespace roamlab::sim
