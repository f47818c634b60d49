#include "apps/parser.h"

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "apps/batch.h"
#include "apps/cli.h"
#include "apps/commands.h"
#include "apps/design.h"
#include "apps/diagnose.h"
#include "apps/evaluate.h"
#include "apps/frontend.h"
#include "apps/gap_benchmark.h"
#include "apps/import.h"
#include "apps/information.h"
#include "apps/init.h"
#include "apps/montecarlo.h"
#include "apps/odometry.h"
#include "apps/regress.h"
#include "apps/simulate.h"
#include "apps/sweep.h"
#include "apps/version.h"
#include "experiment/terrain_redraw.h"

namespace roamlab::apps {
namespace {

// The recording a command reads, named alike in every command: positional REC or --recording REC.
constexpr char kRecording[] = "recording,--recording";

// The command's arguments, kept alive by the run function that reads them.
template <typename Args, typename Register>
void Add(Commands* commands, int (*run)(const Args&), Register add_options) {
  auto args = std::make_shared<Args>();
  CLI::App* app = add_options(args.get());
  commands->push_back({app, [args, run] { return run(*args); }});
}

void AddSimulate(CLI::App* app, Commands* commands) {
  auto args = std::make_shared<SimulateArgs>();
  auto seed = std::make_shared<std::uint64_t>(0);
  CLI::App* sim = app->add_subcommand(
      "simulate", "Run a scenario in MuJoCo and write its recording with ground truth and true calibration.");
  sim->add_option("scenario", args->scenario, "Scenario file (SCENARIO.yaml)")->required();
  sim->add_option("--out", args->out, "Output recording directory")->required();
  CLI::Option* seed_option = sim->add_option("--seed", *seed, "Sensor-noise seed (overrides the scenario's)");
  sim->add_flag("--quiet", args->quiet, "No progress and no summary");
  commands->push_back({sim, [args, seed, seed_option] {
                         if (seed_option->count() > 0) args->seed = *seed;
                         return RunSimulate(*args);
                       }});
}

void AddReplay(CLI::App* app, Commands* commands) {
  auto args = std::make_shared<ReplayArgs>();
  auto from = std::make_shared<double>(0.0);
  auto to = std::make_shared<double>(0.0);
  CLI::App* rep = app->add_subcommand(
      "replay", "Drive a scenario's MuJoCo model with a recording's own inputs: the recording's noise-free twin.");
  rep->add_option(kRecording, args->recording, "Recording directory whose drive is replayed")->required();
  rep->add_option("--scenario", args->scenario, "Nominal scenario (NOMINAL.yaml): the model and sensors")->required();
  rep->add_option("--out", args->out, "Output directory: the twin recording")->required();
  CLI::Option* from_option = rep->add_option("--from", *from, "Start of the window, recording time [s]");
  CLI::Option* to_option = rep->add_option("--to", *to, "End of the window, recording time [s]");
  rep->add_flag("--quiet", args->quiet, "No progress and no summary");
  commands->push_back({rep, [args, from, to, from_option, to_option] {
                         if (from_option->count() > 0) args->from_s = *from;
                         if (to_option->count() > 0) args->to_s = *to;
                         return RunReplay(*args);
                       }});
}

void AddCalibrate(CLI::App* app, Commands* commands) {
  Add(commands, RunCalibrate, [app](auto* args) {
    CLI::App* cal = app->add_subcommand(
        "calibrate", "Offline self-calibration of the free parameters over a whole recording (seed 000, Section V).");
    cal->add_option(kRecording, args->recording, "Recording directory (recording.yaml + CSV streams)")->required();
    cal->add_option("--config", args->config, "Estimator configuration (EST.yaml)")->required();
    cal->add_option("--out", args->out, "Output directory: calibration.json, trajectory.tum")->required();
    cal->add_option("--std", args->std_method,
                    "Which standard deviation is `std`: white (inverse information), hac (Newey-West, autocorrelated "
                    "residuals) or auto (hac on imported recordings, white on simulated ones; default)")
        ->check(CLI::IsMember({"auto", "white", "hac"}));
    cal->add_flag("--quiet", args->quiet, "No progress and no summary");
    return cal;
  });
}

void AddTrack(CLI::App* app, Commands* commands) {
  Add(commands, RunTrack, [app](auto* args) {
    CLI::App* trk =
        app->add_subcommand("track", "Online fixed-lag tracking with marginalization (seed 000, Section III-B).");
    trk->add_option(kRecording, args->recording, "Recording directory")->required();
    trk->add_option("--config", args->config, "Estimator configuration (EST.yaml)")->required();
    trk->add_option("--calibration", args->calibration, "calibration.json from `roamlab calibrate` (fixes parameters)");
    trk->add_option("--out", args->out, "Output directory: trajectory.tum, covariance.csv, summary.json")->required();
    trk->add_flag("--quiet", args->quiet, "No progress and no summary");
    return trk;
  });
}

void AddEvaluate(CLI::App* app, Commands* commands) {
  Add(commands, RunEvaluate, [app](auto* args) {
    CLI::App* evl = app->add_subcommand(
        "evaluate",
        "Accuracy (ATE, RPE), consistency (NEES, seed eq. 16) and parameter errors against a reference: the "
        "recording's truth, a trajectory file (TUM, KITTI, EuRoC) or an absolute sensor stream.");
    evl->add_option("--estimate", args->estimates,
                    "Estimate directory (trajectory.tum [, covariance.csv, calibration.json]) or trajectory file; "
                    "several: one comparison table and plot")
        ->required();
    evl->add_option("--recording", args->recording, "Recording directory [with ground_truth.tum, truth.yaml]");
    evl->add_option("--reference", args->reference, "Reference trajectory file (TUM, KITTI poses or EuRoC CSV)");
    evl->add_option("--reference-stream", args->reference_stream,
                    "gps, position or pose stream of the recording as the reference (default without ground truth: "
                    "the first such stream)");
    evl->add_option("--reference-format", args->reference_format, "tum | kitti | euroc (default: detected)");
    evl->add_option("--estimate-format", args->estimate_format, "tum | kitti | euroc (default: detected)");
    evl->add_option("--calibration", args->calibration,
                    "calibration.json for a reference stream's lever arm and the parameter table");
    evl->add_option("--covariance", args->covariance,
                    "covariance.csv of the estimate's position covariances, for the NEES (default: "
                    "DIR/covariance.csv of an estimate directory; none for a file)");
    evl->add_option("--out", args->out, "Output directory: metrics.json, figures (PNG + gnuplot scripts)")->required();
    evl->add_option("--align", args->align,
                    "none | se3 | sim3 | yaw | origin (default: none with gps/position/pose streams or two plain "
                    "files, se3 otherwise)");
    evl->add_option("--align-first", args->align_first, "Align on the first N matched poses (default: all)");
    evl->add_option("--align-window", args->align_window_s,
                    "Align on the poses between S and E seconds after the reference's first pose")
        ->expected(2);
    evl->add_option("--t-max-diff,--max-time-difference", args->max_time_difference_s,
                    "Association tolerance [s] (default 0.01)");
    evl->add_option("--t-offset", args->t_offset_s, "Added to the estimates' stamps before association [s]");
    evl->add_option("--delta,--rpe-delta", args->rpe_delta_s, "RPE pose pairs about this far apart [s] (default 1)");
    evl->add_option("--delta-m,--rpe-distance", args->rpe_distance_m,
                    "RPE segments along the reference [m] (default 10)");
    evl->add_option("--nees-t0", args->nees_t0_s, "Leave the first T0 seconds out of the NEES in-band fraction");
    evl->add_flag("--no-plots", args->no_plots, "Write metrics.json only");
    evl->add_flag("--quiet", args->quiet, "No summary on stdout");
    return evl;
  });
}

// --backend and the Slurm options of a batch command (apps/batch.h, batch/slurm.h).
void AddBackendOptions(CLI::App* app, BackendArgs* b) {
  app->add_option("--backend", b->backend, "local (this host's threads; default) | slurm (one job array)")
      ->check(CLI::IsMember({"local", "slurm"}));
  app->add_option("--partition", b->slurm.partition, "slurm: sbatch --partition (default: the cluster's)");
  app->add_option("--time", b->slurm.time, "slurm: time limit of each task, sbatch --time (e.g. 10:00 or 1-00)");
  app->add_option("--array-parallelism", b->slurm.array_parallelism,
                  "slurm: at most N tasks at once (--array=...%N; default no limit)");
  app->add_option("--runs-per-task", b->slurm.runs_per_task, "slurm: runs each array task runs in turn (default 1)");
  app->add_option("--retries", b->slurm.retries,
                  "slurm: times the runs of a failed, timed-out or cancelled task are submitted again (default 1)");
  app->add_option("--sbatch-arg", b->slurm.sbatch_args,
                  "slurm: one more sbatch argument for every job, as one word (repeatable): --sbatch-arg=--qos=long")
      ->allow_extra_args(false);
  app->add_flag("--wait", b->slurm.wait, "slurm: return once the summary is written (default: after submitting)");
}

void AddMonteCarlo(CLI::App* app, Commands* commands) {
  Add(commands, RunMonteCarlo, [app](auto* args) {
    CLI::App* mc = app->add_subcommand(
        "montecarlo", "NEES consistency of online tracking over noise realizations (seed 000, Section V, Fig. 4).");
    mc->add_option("scenario", args->scenario, "Scenario file (SCENARIO.yaml)")->required();
    mc->add_option("--config", args->config, "Estimator configuration for tracking (EST.yaml); or --command");
    mc->add_option("--command", args->command.command,
                   "An external estimator under test instead of --config: a shell command run on each run's "
                   "recording, {recording} and {out} replaced by the directories (docs/external-estimator.md)");
    mc->add_option("--timeout", args->command.timeout_s,
                   "--command: seconds each run's command may take before it is killed (default 600)");
    mc->add_option("--calibration", args->calibration,
                   "calibration.json whose values tracking uses (default: calibrate once with tracking.calibrate)");
    mc->add_option("--runs", args->runs, "Noise realizations (default 50)");
    mc->add_option("--jobs", args->jobs, "Parallel runs (default: one per core)");
    mc->add_option("--seed-base", args->seed_base, "Run i uses noise seed SEED_BASE + i (default 1000)");
    mc->add_option("--t0", args->t0_s, "Leave the first T0 seconds out of fraction_in_band (default 2)");
    mc->add_flag("--calibrate-each-run", args->calibrate_each_run,
                 "With tracking.calibrate: each run calibrates a drive of its own instead of sharing one calibration");
    mc->add_flag("--calibration-consistency", args->calibration_consistency,
                 "Calibrate each run with --config instead of tracking it: the calibration's std against its errors "
                 "(consistency.json, consistency.png)");
    mc->add_flag("--redraw-terrain", args->redraw_terrain,
                 "With --calibration-consistency: run i also drives its own terrain, the scenario's hills drawn with "
                 "terrain seed TERRAIN_BASE + i; a run that fails on its terrain is counted and named (failed_runs)");
    mc->add_option_function<unsigned long long>(
        "--terrain-base", [args](const unsigned long long& base) { args->terrain_base = base; },
        "With --redraw-terrain: run i draws terrain seed TERRAIN_BASE + i (default " +
            std::to_string(experiment::kDefaultTerrainSeedBase) + ")");
    mc->add_flag("--no-time-budget", args->no_time_budget,
                 "Ignore tracking.time_budget_s: results that do not depend on the machine's speed or load");
    mc->add_flag("--resume", args->resume, "Run only the runs whose result file OUT/runs/NNNNNN.json is missing");
    mc->add_option("--out", args->out, "Output directory: nees.json, runs.json, nees.png, runs/")->required();
    mc->add_flag("--quiet", args->quiet, "No progress bar and no summary");
    AddBackendOptions(mc, &args->backend);
    return mc;
  });
}

void AddInit(CLI::App* app, Commands* commands) {
  Add(commands, RunInit, [app](auto* args) {
    CLI::App* ini = app->add_subcommand(
        "init", "Write a nominal estimator configuration (EST.yaml) from a recording's streams and platform.");
    ini->add_option(kRecording, args->recording, "Recording directory")->required();
    ini->add_option("--out", args->out, "Estimator configuration to write (EST.yaml)")->required();
    ini->add_option("--platform", args->platform_kind,
                    "Platform kind overriding the recording's: differential_drive | skid_steer | omni3 | mecanum | "
                    "ackermann");
    ini->add_flag("--quiet", args->quiet, "No summary");
    return ini;
  });
}

void AddInformation(CLI::App* app, Commands* commands) {
  Add(commands, RunInformation, [app](auto* args) {
    CLI::App* inf = app->add_subcommand(
        "information",
        "The Cramer-Rao bound of every free calibration parameter for a scenario's drive (noise-free, at the truth, "
        "poses marginalized), its weak and unobservable directions, and where its information comes from: shares by "
        "stream and by time window.");
    inf->add_option("scenario", args->scenario, "Scenario file (SCENARIO.yaml), simulated without sensor noise")
        ->required();
    inf->add_option("--config", args->config, "Estimator configuration (EST.yaml): free parameters, noise")->required();
    inf->add_option("--out", args->out, "Output directory: information.json, information.png")->required();
    inf->add_option("--window", args->window_s, "Length of the time windows of the split [s] (default 1)");
    inf->add_flag("--quiet", args->quiet, "No progress and no table");
    return inf;
  });
}

void AddDesign(CLI::App* app, Commands* commands) {
  Add(commands, RunDesign, [app](auto* args) {
    CLI::App* des = app->add_subcommand(
        "design",
        "Choose the drive (the Ackermann weave and start heading, or an indoor robot's forward, yaw-rate and sideways "
        "sines) that minimizes the worst ratio of a calibration parameter's Cramer-Rao std to its target, feasible in "
        "MuJoCo; write it as a scenario. Limits not given are the robot's (docs/commands.md).");
    des->add_option("scenario", args->scenario,
                    "Scenario file (SCENARIO.yaml) with an ackermann or body_velocity driver")
        ->required();
    des->add_option("--config", args->config, "Estimator configuration (EST.yaml): free parameters, noise")->required();
    des->add_option("--out", args->out, "The designed scenario to write (DESIGNED.yaml); design.json beside it")
        ->required();
    des->add_option("--target", args->target_texts,
                    "NAME=STD: the target std of every tangent component of the free parameter NAME (repeatable; "
                    "overrides the configuration's target_std of NAME; at least one target in all)");
    des->add_option("--duration", args->duration_s,
                    "Recorded duration of the designed drive [s] (default: the scenario's)");
    des->add_option("--budget", args->budget, "Drives simulated and analysed (default 60)");
    des->add_option("--speed-range", args->speed_range_mps,
                    "MIN MAX of the forward speed set-point [m/s] (default: ATV 1.5 6, differential drive -0.3 0.6, "
                    "omni -0.5 0.5, mecanum -0.3 0.3)")
        ->expected(2);
    des->add_option("--max-handlebar", args->limits.max_handlebar_rad,
                    "Ackermann: largest |handlebar| set-point [rad] (default 0.45)");
    des->add_option("--max-yaw-rate", args->limits.max_yaw_rate_radps,
                    "Indoor robots: largest |yaw rate| set-point [rad/s] (default: differential drive 1.2, omni 1.5, "
                    "mecanum 0.6)");
    des->add_option("--max-lateral-speed", args->limits.max_lateral_mps,
                    "Omni and mecanum: largest |sideways speed| set-point [m/s] (default: omni 0.4, mecanum 0.3)");
    des->add_option("--period-range", args->period_range_s,
                    "MIN MAX of the profiles' periods [s] (default: ATV 5 30, indoor robots 4 20)")
        ->expected(2);
    des->add_option("--max-roll", args->limits.max_roll_deg,
                    "Feasible: largest |roll| of the vehicle [deg] (default: ATV 25, indoor robots 10)");
    des->add_option("--max-pitch", args->limits.max_pitch_deg,
                    "Feasible: largest |pitch| [deg] (default: ATV 25, indoor robots 10)");
    des->add_option("--max-side-slip", args->limits.max_side_slip_mps,
                    "Feasible: largest lateral speed of O [m/s] (default: ATV 0.3, differential drive 0.05, none for "
                    "omni and mecanum)");
    des->add_option("--max-lateral-accel", args->limits.max_lateral_accel_mps2,
                    "Feasible: largest speed x yaw rate [m/s^2] (default: ATV 4.4, 0.45 g; indoor robots 1)");
    des->add_option("--max-velocity-error", args->limits.max_velocity_error_mps,
                    "Feasible, indoor robots: largest |horizontal velocity of O - its set-point| [m/s] (default 0.1: "
                    "a wall, an obstacle or slip)");
    des->add_flag("--quiet", args->quiet, "No progress and no table");
    return des;
  });
}

// diagnose's options of the twin: the simulator's effects fitted by running it.
void AddTwinOptions(CLI::App* dia, DiagnoseArgs* args) {
  dia->add_flag("--twin", args->twin,
                "Also diagnose against the scenario's noise-free twin, the simulator's effects fitted by running it, "
                "into OUT/twin.json (the twin: the scenario's own drive for a recording of it, else the replay of "
                "the recorded drive)");
  CLI::Option* replay = dia->add_flag_callback(
      "--replay",
      [args] {
        args->drive = gap::TwinDrive::kReplay;
        args->twin = true;
      },
      "The twin replays the recorded drive, whatever the drive (implies --twin)");
  CLI::Option* no_replay = dia->add_flag_callback(
      "--no-replay", [args] { args->drive = gap::TwinDrive::kPlain; },
      "The twin is the scenario's own drive (its plain simulation), whatever the recording's drive");
  replay->excludes(no_replay);
  dia->add_option("--held-out", args->held_out,
                  "With --twin: other recordings of the same robot (held out of the twin's fit) on which the "
                  "twin's patch is shown (twin.json heldout_runs)");
  dia->add_option("--train-with", args->train_with,
                  "With --twin: other recordings of the same robot the twin's patch is fitted on as well, each on its "
                  "own twin, its first 2/3 in the fit and its last 1/3 in the held-out test (twin.json "
                  "training_runs)");
  dia->add_option("--train-weight", args->train_weight,
                  "With --train-with: how the training runs weigh in the twin's fit: windows (default; each residual "
                  "as its stream weighs it, a longer run more) or runs (each run's residuals scaled so that every run "
                  "weighs the same, their total unchanged; twin.json run_weights)");
  dia->add_option("--max-effects", args->max_effects, "With --twin: the twin's effects kept at most (default 2)");
  dia->add_option("--twin-candidates", args->twin_candidates,
                  "With --twin: the candidate effects the twin diagnosis tries, as twin.json names them (e.g. "
                  "wheel_radius_scale, 'axle_misalignment wheel 0'; default every one the scenario supports, "
                  "diff_drive_geometry only with --train-with)");
}

void AddDiagnose(CLI::App* app, Commands* commands) {
  Add(commands, RunDiagnose, [app](auto* args) {
    CLI::App* dia = app->add_subcommand(
        "diagnose",
        "Reality-gap diagnosis: locate where a recording departs from the nominal model, name the physical "
        "effect, fit it and show the held-out fit improve.");
    dia->add_option(std::string(kRecording) + ",--real", args->recording,
                    "Recording directory, also --recording REC or --real REC (its truth.yaml is never read)")
        ->required();
    dia->add_option("--scenario", args->scenario,
                    "The nominal scenario: the robot as believed (optional with --config and --no-baseline)");
    dia->add_option("--config", args->config,
                    "Nominal estimator configuration (default: built from the scenario; without --scenario, "
                    "`roamlab init`'s from the recording, written to OUT/nominal_config.yaml, with --no-baseline)");
    dia->add_option("--out", args->out, "Output directory: gap.json, report.md, scenario_patch.yaml, figures")
        ->required();
    dia->add_flag("--no-baseline", args->no_baseline,
                  "Do not simulate the nominal scenario to learn its levels (compare with chi2/dof 1)");
    dia->add_option("--baseline-seed", args->baseline_seed, "Noise seed of the nominal simulation (default 900001)");
    dia->add_option("--max-shift", args->max_shift_s,
                    "Time-shift search range [s] of gps_latency, imu_time_offset, pose_time_offset and drive_time_offset "
                    "(default 0.5; "
                    "below 1/12 of the recording's span)");
    dia->add_option("--std", args->std_method,
                    "The effects' standard deviations, also the twin's with --replay: white, hac (autocorrelated "
                    "residuals) or auto (hac on imported recordings, white on simulated ones; default)")
        ->check(CLI::IsMember({"auto", "white", "hac"}));
    dia->add_flag("--no-plots", args->no_plots, "No figures");
    AddTwinOptions(dia, args);
    dia->add_flag("--quiet", args->quiet, "No progress and no summary");
    return dia;
  });
}

void AddGapBenchmark(CLI::App* app, Commands* commands) {
  Add(commands, RunGapBenchmark, [app](auto* args) {
    CLI::App* gbm =
        app->add_subcommand("gap-benchmark",
                            "Blind benchmark of the diagnosis: hidden effects (or none, or a decoy) drawn, simulated, "
                            "diagnosed, then scored against truth.yaml.");
    gbm->add_option("--cases", args->cases, "Scored cases (default 16)");
    gbm->add_option("--calibration-cases", args->calibration_cases,
                    "Calibration cases, run first, that fix the thresholds (default 8)");
    gbm->add_option("--seed", args->seed,
                    "Seed of the draws; scored case i uses noise seed SEED * 1000 + i, calibration case i "
                    "SEED * 1000 + 500 + i (default 1)");
    gbm->add_option("--jobs", args->jobs, "Cases in parallel (default 2)");
    gbm->add_option("--other-drive", args->other_drive,
                    "Fraction of the cases whose \"real\" recording is driven by another schedule than the nominal "
                    "scenario's, so that the re-simulation replays it (default 0.5)");
    gbm->add_option("--duration", args->duration_s, "Drive duration [s] of every case (default: the scenarios')");
    gbm->add_option("--atv", args->atv_scenario, "Nominal ATV scenario (default scenarios/atv_hills_sines.yaml)");
    gbm->add_option("--diffdrive", args->diffdrive_scenario,
                    "Nominal differential-drive scenario (default scenarios/indoor_diffdrive_gap.yaml)");
    gbm->add_option("--mecanum", args->mecanum_scenario,
                    "Nominal mecanum scenario (default scenarios/indoor_mecanum_gap.yaml)");
    gbm->add_flag("--resume", args->resume,
                  "Read back the cases whose NNN/case.json exists instead of running them again");
    gbm->add_option("--out", args->out, "Output directory: score.json, timings.json, calibration/NNN, cases/NNN")
        ->required();
    AddBackendOptions(gbm, &args->backend);
    gbm->add_flag("--quiet", args->quiet, "No progress");
    return gbm;
  });
}

void AddRegress(CLI::App* app, Commands* commands) {
  Add(commands, RunRegress, [app](auto* args) {
    CLI::App* reg = app->add_subcommand(
        "regress", "Run a regression suite: cases with checks against bounds and baselines; JUnit XML for CI.");
    reg->add_option("suite", args->suite, "Suite file (SUITE.yaml)")->required();
    reg->add_option("--out", args->out, "Output directory: results.json, junit.xml, cases/NAME/")->required();
    reg->add_option("--baseline", args->baseline, "Baseline directory (default: the suite's `baseline`)");
    reg->add_flag("--update-baseline", args->update_baseline, "Write the values as the new baseline, one file a case");
    reg->add_option("--jobs", args->jobs, "Cases in parallel (default: one per core)");
    reg->add_option("--filter", args->filter, "Only the cases whose name matches this glob");
    reg->add_flag("--quick", args->quick, "Only the cases marked `quick: true`");
    reg->add_flag("--resume", args->resume,
                  "Continue an interrupted run in OUT: finished cases are read from their records, the rest run");
    reg->add_flag("--quiet", args->quiet, "No progress lines");
    return reg;
  });
}

// `odometry learn` and `odometry evaluate`.
void AddOdometry(CLI::App* app, Commands* commands) {
  CLI::App* odo = app->add_subcommand("odometry", "Model-free odometry calibration (seed 001): learn, evaluate.");
  odo->require_subcommand(1);
  Add(commands, RunOdometryLearn, [odo](auto* args) {
    CLI::App* odo_learn = odo->add_subcommand(
        "learn", "Learn an odometry model from wheel encoders and an exteroceptive pose stream (CGP, eq. 9, Censi).");
    odo_learn->add_option("--recording", args->recordings, "Training recording directories")->required();
    odo_learn->add_option("--model", args->model, "gp | linear | parametric (default gp)");
    odo_learn->add_option("--mean", args->mean, "GP mean function: zero | linear (default linear)");
    odo_learn->add_option("--kernel", args->kernel, "GP kernel: rbf | linear | rbf+linear (default rbf)");
    odo_learn->add_option("--interval", args->interval_s, "Key-time interval T [s] (default 0.5)");
    odo_learn->add_option("--encoders", args->encoder_stream, "wheel_encoders stream (default: the only one)");
    odo_learn->add_option("--sensor", args->sensor_stream,
                          "pose stream of the exteroceptive sensor (default: the only one)");
    odo_learn->add_option("--hyperparameter-subset", args->hyperparameter_subset,
                          "GP: pairs used to optimize the hyper-parameters, 0 = all (default 400)");
    odo_learn->add_option("--outlier-threshold", args->outlier_threshold,
                          "gp, parametric: drop pairs beyond this many robust sigmas of the eq. 9 fit, 0 = keep "
                          "(default 5)");
    odo_learn->add_option("--max-pairs", args->max_pairs,
                          "GP: condition on a seeded random subset of at most this many pairs, 0 = all "
                          "(default 6000; memory 3 x 8 n^2 bytes)");
    odo_learn->add_option("--out", args->out, "Model file (JSON)")->required();
    odo_learn->add_flag("--quiet", args->quiet, "No progress lines");
    return odo_learn;
  });
  Add(commands, RunOdometryEvaluate, [odo](auto* args) {
    CLI::App* odo_evaluate = odo->add_subcommand(
        "evaluate",
        "Dead-reckon test recordings with models and the nominal model: ATE (eq. 11), RPE (eq. 10), plots.");
    odo_evaluate->add_option("--model", args->models, "Model files from `odometry learn`")->required();
    odo_evaluate->add_option("--recording", args->recordings, "Test recordings with ground_truth.tum")->required();
    odo_evaluate->add_option("--encoders", args->encoder_stream, "wheel_encoders stream (default: the only one)");
    odo_evaluate->add_option("--out", args->out, "Output directory: table.json, trajectory_NN.png")->required();
    odo_evaluate->add_flag("--no-plots", args->no_plots, "Write table.json only");
    odo_evaluate->add_flag("--quiet", args->quiet, "No table on stdout");
    return odo_evaluate;
  });
}

// `import optiodom`, `import rosbag` and `import csv`.
void AddImport(CLI::App* app, Commands* commands) {
  CLI::App* imp = app->add_subcommand("import", "Convert real recordings into the recording format.");
  imp->require_subcommand(1);
  Add(commands, RunImportOptiOdom, [imp](auto* args) {
    CLI::App* imp_optiodom = imp->add_subcommand("optiodom", "An OptiOdom run (encoder ticks + OptiTrack poses).");
    imp_optiodom->add_option("run", args->run_csv, "<set>_run-NN.csv")->required();
    imp_optiodom->add_option("--metadata", args->metadata, "Metadata file (default <set>_metadata.csv)");
    imp_optiodom->add_option("--out", args->out, "Output recording directory")->required();
    imp_optiodom->add_flag("--quiet", args->quiet, "No summary");
    return imp_optiodom;
  });
  Add(commands, RunImportRosbag, [imp](auto* args) {
    CLI::App* imp_rosbag = imp->add_subcommand(
        "rosbag",
        "A ROS 1 bag, rosbag2 directory or MCAP file: Imu, NavSatFix, MagneticField, JointState, "
        "LaserScan, Image, CompressedImage, Odometry, TwistStamped, PoseStamped, PoseWithCovarianceStamped.");
    imp_rosbag->add_option("bag", args->bag, "BAG.bag, a rosbag2 directory or FILE.mcap")->required();
    imp_rosbag->add_option("--out", args->out, "Output recording directory (required unless --list)");
    imp_rosbag->add_flag("--list", args->list, "Print every topic (type, count, rate, span); import nothing");
    imp_rosbag->add_option(
        "--topic", args->topics,
        "TOPIC=STREAM: import this topic as this stream (repeatable; default every supported topic)");
    imp_rosbag->add_option("--joints", args->joints, "JointState joints to import (repeatable; default all)");
    imp_rosbag->add_flag("--joint-velocities", args->joint_velocities,
                         "JointState: velocities [rad/s] instead of positions [rad]");
    imp_rosbag
        ->add_option("--imu-mounting", args->imu_mounting_wxyz,
                     "IMU mounting q_body_imu as W X Y Z (rotates IMU coordinates into the body frame)")
        ->expected(4);
    imp_rosbag->add_option("--platform", args->platform_kind, "Platform kind (e.g. skid_steer)");
    imp_rosbag->add_option("--geometry", args->geometry, "Nominal geometry KEY=VALUE (repeatable)");
    imp_rosbag->add_flag("--wheels-from-odometry", args->wheels_from_odometry,
                         "Also write wheel angles re-expressed from the odometry (needs wheel_radius_m, baseline_m)");
    imp_rosbag->add_option("--odometry-topic", args->odometry_topic,
                           "The odometry topic the wheels come from, when the bag has several");
    imp_rosbag->add_option("--odometry-wheel-separation", args->odometry_wheel_separation_m,
                           "The odometry controller's wheel separation [m] for the wheels (default baseline_m)");
    imp_rosbag->add_flag("--quiet", args->quiet, "No summary");
    return imp_rosbag;
  });
  Add(commands, RunImportCsv, [imp](auto* args) {
    CLI::App* imp_csv =
        imp->add_subcommand("csv", "CSV/TSV files with a column mapping (units, axes, collapse; docs/import-csv.md).");
    imp_csv->add_option("files", args->files, "CSV files, in the order of the mapping's files entries")->required();
    imp_csv->add_option("--map", args->map, "Mapping (YAML)")->required();
    imp_csv->add_option("--out", args->out, "Output recording directory")->required();
    imp_csv->add_flag("--quiet", args->quiet, "No summary");
    return imp_csv;
  });
}

void AddFrontEnd(CLI::App* app, Commands* commands) {
  Add(commands, RunFrontEnd, [app](auto* args) {
    CLI::App* fe =
        app->add_subcommand("frontend",
                            "Run a sensor front end over a recording: visual odometry on a camera stream (vo) or scan "
                            "matching on a laser_scan stream (scan); writes REC2 with the derived stream.");
    fe->add_option("front_end", args->front_end, "vo | scan")->required()->check(CLI::IsMember({"vo", "scan"}));
    fe->add_option(kRecording, args->recording, "Recording directory")->required();
    fe->add_option("--out", args->out, "Output recording directory (REC's streams plus the derived one)")->required();
    fe->add_option("--input", args->input_stream, "Input stream (default: the only camera or laser_scan stream)");
    fe->add_option("--stream", args->output_stream,
                   "Name of the derived stream (default visual_odometry or scan_matching; replaces one of that name)");
    fe->add_flag("--quiet", args->quiet, "No progress and no summary");
    return fe;
  });
}

void AddSweep(CLI::App* app, Commands* commands) {
  Add(commands, RunSweep, [app](auto* args) {
    CLI::App* swp = app->add_subcommand(
        "sweep", "Monte-Carlo points over scenario and estimator keys (a grid or a list) x N seeds: table and plots.");
    swp->add_option("sweep", args->sweep, "Sweep file (SWEEP.yaml)")->required();
    swp->add_option("--out", args->out, "Output directory: sweep.json, table.csv, plots/, report.html, points/NNN/")
        ->required();
    swp->add_option("--jobs", args->jobs, "local: parallel runs of a point (default: one per core)");
    swp->add_flag("--resume", args->resume, "Run only the runs whose result file is missing");
    swp->add_flag("--quiet", args->quiet, "No progress lines and no summary");
    AddBackendOptions(swp, &args->backend);
    return swp;
  });
}

// `batch status`, and `batch task` and `batch aggregate`, which the Slurm backend's jobs run.
void AddBatch(CLI::App* app, Commands* commands) {
  CLI::App* bat =
      app->add_subcommand("batch", "Batches of runs (montecarlo, sweep): status, and the Slurm jobs' steps.");
  bat->require_subcommand(1);
  Add(commands, RunBatchStatus, [bat](auto* args) {
    CLI::App* sta = bat->add_subcommand("status", "Runs done, pending or running and failed (with their task logs).");
    sta->add_option("out", args->out, "The batch's output directory")->required();
    return sta;
  });
  Add(commands, RunBatchTask, [bat](auto* args) {
    CLI::App* tsk = bat->add_subcommand("task", "Run one Slurm array task's block of runs (the array's job script).");
    tsk->add_option("out", args->out, "The batch's output directory")->required();
    tsk->add_option("--index", args->index, "The array task index (SLURM_ARRAY_TASK_ID)")->required();
    return tsk;
  });
  Add(commands, RunBatchAggregate, [bat](auto* args) {
    CLI::App* agg = bat->add_subcommand(
        "aggregate", "Submit missing runs again while retries remain, else write the summary (the aggregation job).");
    agg->add_option("out", args->out, "The batch's output directory")->required();
    return agg;
  });
}

}  // namespace

Commands AddCommands(CLI::App* app) {
  app->name("roamlab");
  app->description("roamlab: mobile-robot pose tracking and sensor self-calibration testbed");
  app->set_version_flag("--version", std::string("roamlab ") + ROAMLAB_VERSION, "Print the version and exit");
  app->require_subcommand(1);
  Commands commands;
  for (const auto add :
       {AddSimulate, AddReplay, AddCalibrate, AddTrack, AddEvaluate, AddMonteCarlo, AddInit, AddInformation, AddDesign,
        AddDiagnose, AddGapBenchmark, AddRegress, AddOdometry, AddImport, AddFrontEnd, AddSweep, AddBatch})
    add(app, &commands);
  return commands;
}

}  // namespace roamlab::apps
