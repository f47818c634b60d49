// The step of `roamlab diagnose` as a library call: the reality-gap diagnosis of a recording against the nominal
// robot (gap/diagnose.h), with its baseline and re-simulation, into an output directory. The command line and the
// regression suite call it.
//
// Reads the recording's streams only (never truth.yaml). Unless `no_baseline`, first simulates the nominal scenario
// (its effects removed, the recording's duration, seed `baseline_seed`) and diagnoses that, to learn the levels and
// candidate gains the nominal model reaches on MuJoCo data without any hidden effect (gap/learn_baseline.h). With a
// scenario, the scenario's twin of the recording (its plain simulation for a recording of its own drive, else the
// replay of the recorded drive) is run again without noise, as believed and with the accepted effects, and compared
// with the recording's held-out part (gap/resimulate.h; gap.json "simulation"). Writes gap.json, report.md, the
// patches and the figures (gap/report.h). Without a scenario and a configuration, the nominal model is the one
// `roamlab init` writes (experiment/init.h), saved as out/nominal_config.yaml, and there is no baseline. With `twin`,
// the recording is also diagnosed against the twin (gap/twin.h) into out/twin.json (gap.json's "simulation" names the
// file), and the twin's patch is shown on the held-out recordings.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "experiment/steps.h"
#include "gap/diagnose.h"
#include "gap/learn_baseline.h"
#include "gap/resimulate.h"
#include "gap/twin.h"

namespace roamlab::experiment {

// The nominal configuration written beside the outputs when neither a scenario nor a configuration is given.
inline constexpr const char* kInitConfigFile = "nominal_config.yaml";

struct DiagnoseRequest {
  std::string recording;  // REC
  std::string scenario;   // SCENARIO.yaml (the nominal robot); "" for a robot without a MuJoCo twin:
                          // then no_baseline is required with a config, and implied without one
  std::string config;     // EST.yaml: nominal estimator configuration (default: from the scenario,
                          // gap::NominalConfig; without a scenario, experiment/init.h's from the recording, written
                          // to out/kInitConfigFile)
  std::string out;        // output directory
  bool no_baseline = false;
  std::uint64_t baseline_seed = gap::kDefaultBaselineSeed;  // noise seed of the nominal simulation
  std::optional<double> max_shift_s;  // the time-shift search range (default gap::DiagnoseOptions')
  std::string std_method = "auto";    // the effects' std: auto | white | hac (gap/diagnose.h, gap/twin.h)
  bool no_plots = false;              // no figures beside report.md
  // The scenario's twin of the recording (gap/resimulate.h ChooseTwin): detected (the plain noise-free simulation for a
  // recording of the scenario's own drive, else the replay of the recorded drive, sim/replay.h), or forced: kReplay
  // (bad input when the recording has no drive inputs), kPlain. The re-simulation (gap.json "simulation") runs on it.
  gap::TwinDrive drive = gap::TwinDrive::kDetect;
  // Also diagnose against the twin (gap/twin.h), the simulator's effects fitted by running it, into out/twin.json;
  // the re-simulation then applies the twin's patch. Needs a scenario.
  bool twin = false;
  // Recordings held out of the twin's fit (other runs of the same robot; needs twin): the patch fitted on `recording`
  // is shown on each (gap::ShowOnHeldOut; twin.json's heldout_runs), each on its own twin (chosen as `drive` says).
  // Each is read like `recording` and must have its platform kind (and drive inputs when replayed).
  std::vector<std::string> held_out;
  // Further recordings the twin's patch is fitted on (other runs of the same robot; needs twin), each on its own twin
  // and checked as `held_out` (gap::DiagnoseTwin's training runs; twin.json's training_runs).
  std::vector<std::string> train_with;
  std::optional<int> max_effects;  // the twin's effects kept at most (default gap::TwinDiagnoseOptions')
  // How the training runs weigh in the twin's fit (gap::TwinDiagnoseOptions::train_weight): "windows" (default) or
  // "runs"; another value is bad input.
  std::string train_weight = "windows";
  // The twin's candidate effects (gap::TwinCandidateNames' labels; empty: every one the scenario supports). A label the
  // scenario does not support is bad input.
  std::vector<std::string> twin_candidates;
  std::function<void(const std::string& line)> progress;  // optional
};

// Diagnoses the recording and writes the outputs. Inputs that do not load or do not fit each other (a stream the
// nominal model reads missing, the platform kind not the scenario's robot) are bad input; a fit or a simulation that
// fails, or a file that cannot be written, is a failure. `diagnosis` (optional) receives the result, and `twin`
// (optional) the diagnosis against the twin when `request.twin` (else it is left as it is).
Outcome DiagnoseToDirectory(const DiagnoseRequest& request, gap::Diagnosis* diagnosis = nullptr,
                            gap::TwinDiagnosis* twin = nullptr);

}  // namespace roamlab::experiment
