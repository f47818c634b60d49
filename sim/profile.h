// Control profiles: a set-point (speed, handlebar angle, wheel speed, ...) as a function of time, written in a scenario
// as a sum of terms. The time t [s] is recording time: the recording starts at t = 0.
//
//   speed_mps: 4.5                                 # a bare number: a constant
//   speed_mps:                                     # or a list of terms, summed
//     - constant: 4.5
//     - sine: {amplitude: 1.0, period_s: 13.0, phase_rad: 0.0}           # amplitude sin(2 pi t / period + phase)
//     - square: {amplitude: 0.5, period_s: 4.0, phase_rad: 0.0}          # amplitude sign(sin(2 pi t / period + phase))
//     - ramp: {start_s: 5.0, end_s: 8.0, from: 0.0, to: -1.5}            # from before start, to after end, linear
//     - piecewise: {times_s: [0, 10, 20], values: [0, 1, 0], interpolation: linear}   # or step (hold the last value)
//
// Every term may also carry `window_s: [begin, end]`: outside [begin, end) the term contributes 0. Piecewise profiles
// hold their first value before the first time and their last value after the last time.
#pragma once

#include <string>
#include <vector>

namespace roamlab::sim {

struct ProfileTerm {
  enum class Type { kConstant, kSine, kSquare, kRamp, kPiecewise };
  enum class Interpolation { kLinear, kStep };

  Type type = Type::kConstant;
  double value = 0.0;           // constant
  double amplitude = 0.0;       // sine, square
  double period_s = 1.0;        // sine, square; > 0
  double phase_rad = 0.0;       // sine, square
  double start_s = 0.0;         // ramp
  double end_s = 0.0;           // ramp; >= start_s
  double from = 0.0;            // ramp
  double to = 0.0;              // ramp
  std::vector<double> times_s;  // piecewise; strictly increasing, at least one
  std::vector<double> values;   // piecewise; same size as times_s
  Interpolation interpolation = Interpolation::kLinear;
  bool windowed = false;
  double window_begin_s = 0.0;  // when windowed: active on [begin, end)
  double window_end_s = 0.0;

  double Evaluate(double t) const;
  // Empty when usable; otherwise the problem, naming the field (e.g. "period_s must be > 0").
  std::string Validate() const;
};

struct Profile {
  std::vector<ProfileTerm> terms;  // summed; empty = 0

  static Profile Constant(double value);
  double Evaluate(double t) const;
};

}  // namespace roamlab::sim
