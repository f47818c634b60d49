// The diagnosis's last step on the simulator's side (gap/diagnose.h, step 5, shown by simulation): the nominal
// scenario is run again without sensor noise over the recording's span as its twin, once as believed and once with the
// accepted effects applied as the simulator applies them, and each of the recording's streams is compared sample by
// sample with both twins on the held-out part.
//
// The twin (ChooseTwin): for a recording of the scenario's own drive (a simulated recording with hidden effects, or a
// real robot driven by the same command schedule) the scenario's plain simulation; for a recording of another drive,
// which the plain simulation would miss everywhere, before and after, the replay of the recorded drive (sim/replay.h).
// Streams are matched by name and sample time; a residual is recorded minus simulated, in units of the stream's stated
// noise (recording.yaml `noise`: the imu's gyro_sigma_radps and accel_sigma_mps2, sigma_m of a GPS fix per ENU axis,
// sigma_mps, sigma_rad, ...; a wheel encoder's tick / sqrt(12)); streams with no stated noise are left out. With the
// drive reproduced, what is left before is the recording's noise plus the effect's signature, after the noise plus
// what the fitted effect misses.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/status.h"
#include "gap/diagnose.h"
#include "recording/recording.h"
#include "sim/scenario.h"

namespace roamlab::gap {

// An accepted effect as the simulator's scenario effect (sim/scenario.h): the parameters the simulator knows, and
// lateral_slip's rear cornering compliance as the tires' contact time scale (+0.0203 s per unit above 1, measured on
// atv_hills_sines.yaml, sim/scenario.h), within the simulator's [1, 4]. With `physics_step_s` > 0 the time shifts
// (gps_latency, imu_time_offset, pose_time_offset) are rounded to whole physics steps, as the simulator takes them.
// `std` gets the parameters' standard deviations in the same units (may be null).
sim::EffectOptions SimulatorEffect(const EffectEstimate& effect, std::map<std::string, double>* std = nullptr,
                                   double physics_step_s = 0.0);

struct SimulatedStreamFit {
  double rms = 0.0;                   // over the compared samples and components, in units of the stated noise
  double rms_1s = 0.0;                // of the 1 s means per component (the systematic part, as StreamFit::rms_1s)
  std::vector<double> component_rms;  // per component (a GPS stream's East, North, Up)
  int samples = 0;                    // samples matched in time
};

// Which twin the nominal scenario runs as for a recording: detected (the plain simulation when its wheel motion follows
// the recording's, gap/twin.h CompareDrive, else the replay), or forced either way.
enum class TwinDrive { kDetect, kPlain, kReplay };

struct TwinChoice {
  bool replayed = false;
  std::string reason;  // "own drive detected", "other drive detected", "forced", or why the replay is not possible
  std::string stream;  // detected: the wheel stream that differs most ("" when none could tell)
  std::optional<double> mismatch;  // detected: its relative difference (gap/twin.h CompareDrive)
};

// The twin of `recording` for `nominal` (its effects removed). Detecting runs the plain simulation over the
// recording's span; a recording of another drive without the drive inputs a replay needs keeps the plain simulation
// (reason says so). Errors: forced replay of a recording without drive inputs (sim/replay.h's one line), a plain
// simulation that fails.
Result<TwinChoice> ChooseTwin(const sim::Scenario& nominal, const recording::Recording& recording, TwinDrive drive);

struct SimulationComparison {
  double from_s = 0.0;                                      // compared from here to the end of the recording
  double duration_s = 0.0;                                  // of the twins
  TwinChoice twin;                                          // the twins' drive
  std::map<std::string, SimulatedStreamFit> before, after;  // as believed; with the effects. The imu's columns as
                                                            // "gyroscope" and "accelerometer"
  std::vector<std::string> left_out;                        // streams not compared, with the reason
  std::vector<sim::EffectOptions> effects;       // as applied (SimulatorEffect, time shifts in whole physics steps)
  std::string not_simulated;                     // why the twin with the effects failed (then `after` is empty)
  recording::Recording twin_before, twin_after;  // the twins themselves (the report's figures)
};

// Runs `nominal`'s twin `twin` (its effects replaced) without noise, without and with the effects, and compares them
// with `recording` from `from_s` on. The effects: `effects` as the simulator takes them (SimulatorEffect), or
// `patch` when given (the twin diagnosis's, gap/twin.h). Errors: a recording of another robot kind, a failed nominal
// twin.
Result<SimulationComparison> CompareWithSimulation(const sim::Scenario& nominal,
                                                   const std::vector<EffectEstimate>& effects,
                                                   const recording::Recording& recording, double from_s,
                                                   const TwinChoice& twin = {},
                                                   const std::optional<std::vector<sim::EffectOptions>>& patch = {});

}  // namespace roamlab::gap
