// Regression suites (`roamlab regress`): the suite file, its cases and their checks, validated as a whole before any
// case runs.
//
//   suite: roamlab                      # optional name (default: the file's stem)
//   baseline: regression_baseline       # optional baseline directory, relative to the suite file
//   cases:
//     - name: atv_calibration           # [A-Za-z0-9_.-]+, unique: names the case's output and baseline files
//       mode: calibrate                 # one of the modes of regress/mode_specs.h (its keys are listed there)
//       quick: true                     # in the quick subset (`--quick`); default false
//       data: data/optiodom             # optional: a directory the case needs (real data); when it is absent the
//                                       # case is skipped (reported as skipped with this path, never as passed)
//       scenario: atv_hills.yaml        # simulated with `seed` (default: the scenario's own); or recording: DIR
//       seed: 1
//       config: atv_calibration.yaml    # paths are relative to the suite file
//       command: "../examples/dead_reckoning/dead_reckoning.sh {recording} {out}"   # track, montecarlo: instead of
//                                       # config, an external estimator under test (experiment/external.h), run
//                                       # in the suite file's directory; timeout_s: its time limit per run [s]
//       faults:                         # calibrate, track: sensor faults injected into the simulated recording,
//         - {type: outage, stream: gps, start_s: 5, duration_s: 20}   # as a scenario's `faults:` (sim/faults.h)
//       checks:
//         - {metric: metrics.parameters.gps.lever_arm.error.norm, bound: "<= 0.10"}
//         - {metric: metrics.ate_m, bound: "<= 1.10 * baseline"}
//         - {metric: metrics.velocity.fused.linear_rmse, bound: "<= 0.5 * metrics.velocity.encoders_only.linear_rmse"}
//         - {metric: gap.verdict, equals: named}
//         - {metric: "gap.effects[name=gps_latency].parameters.latency_s", bound: "<= 0.54"}  # quoted: [ ] , in {}
//         - {metric: metrics.parameters.imu.misalignment.angle_error_deg, bound: "<= 2", open: "needs a longer drive"}
//
// A metric is a dotted path into one of the mode's output files (ModeSpec::outputs): the output's name, then keys
// (parameter names keep their dots: metrics.parameters.gps.lever_arm.error), then for an array of numbers one of
// norm, max_abs, min, max, mean or an index. A key naming an array of objects takes either the column of the next
// key (runs.runs.ate_m.max) or, with a selector KEY[FIELD=VALUE,...], the one row whose string fields equal those
// values (table.rows[model=gp,mean=linear,kernel=linear].ate_m, gap.effects[name=gps_latency].parameters.latency_s;
// a null field matches `null`); no row or several rows is an error of the check. The path is checked against the
// output's key schema when the suite is loaded; timing values (not deterministic) are refused.
//
// A numeric metric takes a bound: a comparator and a threshold:  CMP [-]NUMBER | CMP [K *] REF [(+|-) D]  with CMP
// one of <=, <, >=, >; REF is `baseline` (the metric's value stored in the baseline directory) or another numeric
// metric path of the same case (its value in this run); the threshold is K * REF + D. Every number of a bound, like
// t0_s, interval_s and effect parameters, is finite and within +-1e9. A string metric (gap.verdict,
// a selected row's name) takes `equals: TEXT` instead (a bound on it, or `equals` on a number, is refused).
//
// `open: REASON` marks a target that is known not to be met yet (with the reason): the check is
// evaluated and reported as usual (table, results.json, and junit.xml as a <skipped> testcase whose message holds
// the value, the bound and the reason) but does not fail the run; when it holds it is reported as met, so that the
// marker can be removed. A check without `open` fails the run when it does not hold.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/status.h"
#include "sim/faults.h"

namespace roamlab::regress {

struct Bound {
  enum class Comparator { kLess, kLessEqual, kGreater, kGreaterEqual };
  Comparator comparator = Comparator::kLessEqual;
  bool uses_baseline = false;
  std::string reference;  // the other metric the threshold scales (as written); "" = none
  double scale = 0.0;     // threshold = scale * (baseline or reference) + offset; scale = 0 without either
  double offset = 0.0;
  std::string text;  // as written

  bool Relative() const { return uses_baseline || !reference.empty(); }
  // The threshold for the baseline's or the reference metric's value (ignored when !Relative()).
  double Threshold(double base) const { return Relative() ? scale * base + offset : offset; }
  // Whether `value` satisfies the bound against `threshold`; false for NaN.
  bool Holds(double value, double threshold) const;
};

// Parses a bound; the error says what is malformed (without file or case).
Result<Bound> ParseBound(const std::string& text);

// A row selector [FIELD=VALUE,...] on a key that names an array of objects.
using Selector = std::vector<std::pair<std::string, std::string>>;

struct MetricPath {
  std::string text;                        // as written
  std::string output;                      // output name (first component)
  std::vector<std::string> keys;           // JSON keys; a key applied to an array of objects selects that column
  std::map<std::size_t, Selector> select;  // keys[i] with a row selector (an array of objects: that one row)
  std::string reduction;                   // "", norm, max_abs, min, max, mean, or a decimal index
  bool is_string = false;                  // the leaf is a string (checked with `equals`)
};

// The metric's value in `output` (the parsed output file). Errors: a key absent from the output, a null (a NaN
// written by the command), an empty array, a selector matching no row or several.
Result<double> ResolveMetric(const nlohmann::json& output, const MetricPath& path);
// The same for a string metric.
Result<std::string> ResolveText(const nlohmann::json& output, const MetricPath& path);

struct Check {
  MetricPath metric;
  Bound bound;                          // numeric metrics
  std::optional<MetricPath> reference;  // the bound's reference metric, when it names one
  std::optional<std::string> equals;    // string metrics: the expected text
  std::string open;                     // "" or why the target is open (not met yet): never fails the run
  int line = 0;                         // 1-based line in the suite file
};

struct Case {
  std::string name;
  std::string mode;
  int line = 0;
  bool quick = false;
  std::string data;  // a directory the case needs; absent: the case is skipped
  // Inputs (paths resolved against the suite file's directory; empty when not given).
  std::string scenario;
  std::string recording;
  std::optional<std::uint64_t> seed;  // noise seed of the simulated recording
  std::string config;
  std::string command;              // track, montecarlo: an external estimator instead of config,
  std::string command_dir;          // run in this directory (the suite file's),
  std::optional<double> timeout_s;  // with this time limit per run [s]
  std::string calibration;         // calibration.json whose values tracking uses
  std::string calibrate;           // or: calibrate first with this configuration, track with its values
  int runs = 0;                    // montecarlo
  std::uint64_t seed_base = 1000;  // montecarlo: run i uses noise seed seed_base + i
  std::optional<double> t0_s;      // NEES in-band fraction from t0_s on (default: the command's)
  // diagnose: the effects hidden in the simulated recording ({name, parameters} as a scenario's `effects:`) and the
  // noise seed of the nominal simulation (default: the command's).
  std::vector<std::pair<std::string, std::map<std::string, double>>> effects;
  std::optional<std::uint64_t> baseline_seed;
  // calibrate, track: sensor faults applied to the simulated recording after the scenario's own (sim/faults.h).
  std::vector<sim::FaultOptions> faults;
  // odometry: training and test inputs (globs relative to `data` when given, else to the suite file: OptiOdom run
  // CSV files, imported; recording directories; scenario YAML files, simulated with `seed`), the models to learn
  // ({model, mean, kernel} of `roamlab odometry learn`) and the key interval.
  std::vector<std::string> train, test;
  struct OdometryModel {
    std::string model, mean, kernel;
  };
  std::vector<OdometryModel> models;
  std::optional<double> interval_s;
  std::vector<Check> checks;
};

struct Suite {
  std::string file;
  std::string name;
  std::string baseline_dir;  // empty when the suite names none
  std::vector<Case> cases;
};

// Loads and validates the whole suite: keys, modes, inputs (files exist and load; each scenario and configuration
// once, however many cases name it), metric paths and bounds. The error is one line "FILE:LINE: case 'NAME': problem"
// (or "FILE: problem" outside a case).
Result<Suite> LoadSuite(const std::string& path);

}  // namespace roamlab::regress
