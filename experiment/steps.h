// The steps of the `roamlab` commands that write files, as library calls: simulate a scenario into a recording
// directory, replay a recording's drive in a scenario's model (its MuJoCo twin), calibrate a recording into
// calibration.json, track it into trajectory.tum, covariance.csv and summary.json, import an OptiOdom run. The command
// line, the Monte-Carlo runner and the regression suite call them.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "common/status.h"
#include "estimator/calibration.h"
#include "estimator/tracking.h"
#include "recording/recording.h"
#include "sim/simulator.h"

namespace roamlab::experiment {

// How a step ended: ok, bad input (a file that does not load, an output directory that cannot be made: the command's
// exit code 2) or a failure at run time (exit code 1). The message is one line naming the file and the problem.
struct Outcome {
  Status status = Status::Ok();
  bool bad_input = false;
  // The command whose step failed inside a larger one ("simulate", "calibrate"), for the message's prefix; "" when
  // it is the caller's own.
  std::string step;

  bool ok() const { return status.ok(); }
  static Outcome Ok() { return {}; }
  static Outcome BadInput(const Status& status) { return {status, true, ""}; }
  static Outcome Failed(const Status& status) { return {status, false, ""}; }
};

// Creates `dir` and its parents (bad input when it cannot).
Status MakeOutputDirectory(const std::string& dir);

struct SimulateRequest {
  std::string scenario;                           // SCENARIO.yaml
  std::string out;                                // recording directory; also where sensors.camera.store_images writes
  std::optional<std::uint64_t> seed;              // overrides the scenario's noise seed
  std::function<void(double fraction)> progress;  // optional
  std::vector<sim::FaultOptions> faults;          // applied after the scenario's own (sim/faults.h)
};
// Simulates the scenario and writes the recording with ground_truth.tum and truth.yaml. A bad scenario or model is
// bad input; a simulation that fails or a recording that cannot be written is a failure. `simulation` (optional)
// receives the run.
Outcome SimulateToDirectory(const SimulateRequest& request, sim::Simulation* simulation = nullptr);

struct ReplayRequest {
  std::string recording;                          // REC, the recording whose drive is replayed
  std::string scenario;                           // NOMINAL.yaml
  std::string out;                                // the twin's recording directory
  std::optional<double> from_s, to_s;             // the window, in the recording's time [s]
  std::function<void(double fraction)> progress;  // optional
};
// Replays the recording's drive in the nominal scenario's model (sim/replay.h) and writes the twin with
// ground_truth.tum and truth.yaml. A recording or scenario that does not load, a recording without drive inputs, an
// empty window are bad input; a replay that fails or a twin that cannot be written is a failure. `simulation`
// (optional) receives the run.
Outcome ReplayToDirectory(const ReplayRequest& request, sim::Simulation* simulation = nullptr);

struct CalibrateRequest {
  std::string recording;
  std::string config;
  std::string out;                                        // receives calibration.json and trajectory.tum
  std::string std_method = "auto";                        // auto | white | hac (estimator/calibration.h)
  std::function<void(const std::string& line)> progress;  // optional
  // Optional: receives each warning about the inputs, one line naming the file (an empty stream, samples outside the
  // master's span). A source stream with no sample within the master's span is bad input.
  std::function<void(const std::string& line)> warning;
};
// Offline self-calibration of the recording (estimator/calibration.h). `result` (optional) receives it.
Outcome CalibrateToDirectory(const CalibrateRequest& request, estimator::CalibrationResult* result = nullptr);

struct TrackRequest {
  std::string recording;
  std::string config;
  std::string calibration;      // optional calibration.json: its values (and prior) for tracking
  std::string out;              // receives trajectory.tum, covariance.csv and summary.json (estimator/tracking_io.h)
  bool no_time_budget = false;  // ignore tracking.time_budget_s: results that do not depend on the machine's speed
  std::function<void(double fraction)> progress;         // optional
  std::function<void(const std::string& line)> warning;  // optional, as CalibrateRequest::warning
};
// Online fixed-lag tracking of the recording (estimator/tracking.h). `result` (optional) receives it.
Outcome TrackToDirectory(const TrackRequest& request, estimator::TrackingResult* result = nullptr);

// Imports an OptiOdom run (importers/optiodom.h) into the recording directory `out`; `metadata` "" = the
// <set>_metadata.csv next to the run. `imported` (optional) receives the recording.
Outcome ImportOptiOdomToDirectory(const std::string& run_csv, const std::string& metadata, const std::string& out,
                                  recording::Recording* imported = nullptr);

}  // namespace roamlab::experiment
