// What the benchmark's steps share: the clocks, the inputs of the run and the sizes of what is measured, child
// processes, and the longer drives of the ATV scenario.
#pragma once

#include <chrono>
#include <cstdarg>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "common/status.h"
#include "estimator/config.h"
#include "estimator/tracking.h"
#include "recording/recording.h"
#include "sim/scenario.h"

namespace roamlab::bench {

namespace est = roamlab::estimator;
using Clock = std::chrono::steady_clock;
using Json = nlohmann::json;

// Wall seconds since t0.
double Since(Clock::time_point t0);
// CPU seconds of this process and of the calling thread.
double ProcessCpu();
double ThreadCpu();
// A field of /proc/self/status in kB (VmRSS, VmHWM), or -1.
long StatusKb(const std::string& key);
// Prints "roamlab_bench: MESSAGE" on stderr; returns the exit code 1.
int Fail(const std::string& message);
// printf to stdout, flushed (progress shows as it comes).
void Say(const char* format, ...);

// What is measured: the full set, or the reduced one of --quick (the same JSON keys; `sizes` says what was run).
struct Sizes {
  double indoor_s = 30.0, render_vo_s = 10.0, indoor_camera_s = 0.0 /* the scenario's */, peer_drive_s = 30.0;
  std::vector<int> windows{10, 40, 160};
  std::vector<double> calibration_s{30.0, 300.0, 1800.0};
  double online_s = 3600.0, montecarlo_drive_s = 30.0;
  int montecarlo_runs_jobs1 = 8, montecarlo_runs_jobs2 = 8;
  double import_mb = 100.0;  // each input of the import step
};
Sizes QuickSizes();

// The inputs of a run.
struct Context {
  bool quick = false;
  Sizes sizes;
  std::string self;  // this program, for the child processes
  std::string root;  // the source tree
  std::string scenario_path, calibration_path, tracking_path;
  sim::Scenario scenario;  // scenarios/atv_hills.yaml
  est::EstimatorConfig calibration_config, tracking_config;
  std::filesystem::path tmp;  // scratch directory, removed at the end
};

// The calibration tracking runs under: values and their joint marginal information.
struct TrackingCalibration {
  std::map<std::string, Eigen::VectorXd> values;
  est::CalibrationPrior prior;
};

// The ATV drive made `duration_s` long (on a closed route beyond 30 s).
sim::Scenario LongerDrive(sim::Scenario scenario, double duration_s);
// Simulates the scenario for `duration_s` and writes the recording to `dir`.
Status SimulateTo(const sim::Scenario& base, double duration_s, const std::string& dir);
// Runs this program with `args` in a new process and reads the JSON it writes.
Result<Json> RunChild(const std::string& self, std::vector<std::string> args, const std::string& json_path);

// The steps (bench/*_bench.cc), in the order main runs them; each returns 0 or the exit code of a failure and adds
// its figures to `j`.
int BenchSimulation(const Context& ctx, Json* j, recording::Recording* recording);  // 1, 1b, 1c
void BenchCgp(Json* j);                                                             // 1d
int BenchIndoorCamera(const Context& ctx, Json* j);                                 // 1e
int BenchReplay(const Context& ctx, const recording::Recording& atv, Json* j);      // 1f
int BenchCeresPeer(const Context& ctx, const recording::Recording& rec, Json* j,
                   TrackingCalibration* peer);  // 2-3
int CalibrateForTracking(const Context& ctx, const recording::Recording& rec, TrackingCalibration* calibrated,
                         std::string* calibration_json);
int BenchTracking(const Context& ctx, const recording::Recording& rec, const TrackingCalibration& calibrated,
                  const TrackingCalibration& peer, Json* j);                                // 4
int BenchCalibrationScaling(const Context& ctx, const recording::Recording& rec, Json* j);  // 5
int BenchOnlineMemory(const Context& ctx, const std::string& calibration_json, Json* j);    // 6
int BenchMonteCarlo(const Context& ctx, const std::string& calibration_json, Json* j);      // 7
int BenchImport(const Context& ctx, Json* j);                                               // 8 (runs first)

// The child processes (own address space: their peak memory is their own).
int ChildCalibrate(const std::string& rec_dir, const std::string& config_path, const std::string& out_path);
int ChildTrack(const std::string& rec_dir, const std::string& config_path, const std::string& calibration_path,
               const std::string& out_path);

}  // namespace roamlab::bench
