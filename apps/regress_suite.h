// Regression suites (`roamlab regress`): the suite file, its cases and their checks, validated as a whole before any
// case runs.
//
//   suite: roamlab                      # optional name (default: the file's stem)
//   baseline: regression_baseline       # optional baseline directory, relative to the suite file
//   cases:
//     - name: atv_calibration           # [A-Za-z0-9_.-]+, unique: names the case's output and baseline files
//       mode: calibrate                 # one of the modes of apps/regress_modes.h
//       quick: true                     # in the quick subset (`--quick`); default false
//       scenario: atv_hills.yaml        # simulated with `seed` (default: the scenario's own); or recording: DIR
//       seed: 1
//       config: atv_calibration.yaml    # paths are relative to the suite file
//       checks:
//         - {metric: metrics.parameters.gps.lever_arm.error.norm, bound: "<= 0.10"}
//         - {metric: metrics.ate_m, bound: "<= 1.10 * baseline"}
//
// A metric is a dotted path into one of the mode's output files (ModeSpec::outputs): the output's name, then keys
// (parameter names keep their dots: metrics.parameters.gps.lever_arm.error), then for an array of numbers one of
// norm, max_abs, min, max, mean or an index. The path is checked against the output's key schema when the suite is
// loaded; timing values (not deterministic) are refused.
//
// A bound is a comparator and a threshold:  CMP [-]NUMBER | CMP [K *] baseline [(+|-) D]  with CMP one of <=, <,
// >=, >; the threshold is K * baseline + D, baseline being the metric's value stored in the baseline directory.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/status.h"

namespace roamlab::apps::regress {

struct Bound {
  enum class Comparator { kLess, kLessEqual, kGreater, kGreaterEqual };
  Comparator comparator = Comparator::kLessEqual;
  bool uses_baseline = false;
  double scale = 0.0;    // threshold = scale * baseline + offset; scale = 0 without baseline
  double offset = 0.0;
  std::string text;      // as written

  // The threshold for a baseline value (ignored when !uses_baseline).
  double Threshold(double baseline) const { return uses_baseline ? scale * baseline + offset : offset; }
  // Whether `value` satisfies the bound against `threshold`; false for NaN.
  bool Holds(double value, double threshold) const;
};

// Parses a bound; the error says what is malformed (without file or case).
Result<Bound> ParseBound(const std::string& text);

struct MetricPath {
  std::string text;                 // as written
  std::string output;               // output name (first component)
  std::vector<std::string> keys;    // JSON keys; a key applied to an array of objects selects that column
  std::string reduction;            // "", norm, max_abs, min, max, mean, or a decimal index
};

// The metric's value in `output` (the parsed output file). Errors: a key absent from the output, a null (a NaN
// written by the command), an empty array.
Result<double> ResolveMetric(const nlohmann::json& output, const MetricPath& path);

struct Check {
  MetricPath metric;
  Bound bound;
  int line = 0;                     // 1-based line in the suite file
};

struct Case {
  std::string name;
  std::string mode;
  int line = 0;
  bool quick = false;
  // Inputs (paths resolved against the suite file's directory; empty when not given).
  std::string scenario;
  std::string recording;
  std::optional<std::uint64_t> seed;      // noise seed of the simulated recording
  std::string config;
  std::string calibration;                // calibration.json whose values tracking uses
  std::string calibrate;                  // or: calibrate first with this configuration, track with its values
  int runs = 0;                           // montecarlo
  std::uint64_t seed_base = 1000;         // montecarlo: run i uses noise seed seed_base + i
  std::optional<double> t0_s;             // NEES in-band fraction from t0_s on (default: the command's)
  std::vector<Check> checks;
};

struct Suite {
  std::string file;
  std::string name;
  std::string baseline_dir;               // empty when the suite names none
  std::vector<Case> cases;
};

// Loads and validates the whole suite: keys, modes, inputs (files exist and load), metric paths and bounds. The
// error is one line "FILE:LINE: case 'NAME': problem" (or "FILE: problem" outside a case).
Result<Suite> LoadSuite(const std::string& path);

}  // namespace roamlab::apps::regress
