// roamlab: the command line. `roamlab --help` and `roamlab <command> --help` describe every command.
#include <cstdint>
#include <iostream>

#include <CLI/CLI.hpp>

#include "apps/commands.h"
#include "apps/diagnose.h"
#include "apps/evaluate.h"
#include "apps/frontend.h"
#include "apps/gap_benchmark.h"
#include "apps/import.h"
#include "apps/montecarlo.h"
#include "apps/regress.h"
#include "apps/odometry.h"
#include "apps/simulate.h"

int main(int argc, char** argv) {
  CLI::App app{"roamlab: mobile-robot pose tracking and sensor self-calibration testbed"};
  app.require_subcommand(1);

  roamlab::apps::SimulateArgs simulate;
  std::uint64_t simulate_seed = 0;
  CLI::App* sim = app.add_subcommand(
      "simulate", "Run a scenario in MuJoCo and write its recording with ground truth and true calibration.");
  sim->add_option("scenario", simulate.scenario, "Scenario file (SCENARIO.yaml)")->required();
  sim->add_option("--out", simulate.out, "Output recording directory")->required();
  CLI::Option* seed_option = sim->add_option("--seed", simulate_seed, "Sensor-noise seed (overrides the scenario's)");
  sim->add_flag("--quiet", simulate.quiet, "No progress and no summary");

  roamlab::apps::CalibrateArgs calibrate;
  CLI::App* cal = app.add_subcommand(
      "calibrate", "Offline self-calibration of the free parameters over a whole recording (seed 000, Section V).");
  cal->add_option("recording", calibrate.recording, "Recording directory (recording.yaml + CSV streams)")
      ->required();
  cal->add_option("--config", calibrate.config, "Estimator configuration (EST.yaml)")->required();
  cal->add_option("--out", calibrate.out, "Output directory: calibration.json, trajectory.tum")->required();
  cal->add_flag("--quiet", calibrate.quiet, "No progress and no summary");

  roamlab::apps::TrackArgs track;
  CLI::App* trk = app.add_subcommand(
      "track", "Online fixed-lag tracking with marginalization (seed 000, Section III-B).");
  trk->add_option("recording", track.recording, "Recording directory")->required();
  trk->add_option("--config", track.config, "Estimator configuration (EST.yaml)")->required();
  trk->add_option("--calibration", track.calibration, "calibration.json from `roamlab calibrate` (fixes parameters)");
  trk->add_option("--out", track.out, "Output directory: trajectory.tum, covariance.csv, summary.json")->required();
  trk->add_flag("--quiet", track.quiet, "No progress and no summary");

  roamlab::apps::EvaluateArgs evaluate;
  CLI::App* evl = app.add_subcommand(
      "evaluate", "Accuracy (ATE, RPE), consistency (NEES, seed eq. 16) and parameter errors against the truth.");
  evl->add_option("--estimate", evaluate.estimate,
                  "Estimate directory: trajectory.tum [, covariance.csv, calibration.json]")->required();
  evl->add_option("--recording", evaluate.recording, "Recording directory with ground_truth.tum [, truth.yaml]")
      ->required();
  evl->add_option("--out", evaluate.out, "Output directory: metrics.json, figures (PNG + gnuplot scripts)")
      ->required();
  evl->add_option("--align", evaluate.align,
                  "none | se3 | yaw_translation (default: none with gps/position/pose streams, se3 otherwise)");
  evl->add_option("--max-time-difference", evaluate.max_time_difference_s,
                  "Association tolerance [s] (default 0.01)");
  evl->add_option("--rpe-delta", evaluate.rpe_delta_s, "RPE pose pairs about this far apart [s] (default 1)");
  evl->add_option("--rpe-distance", evaluate.rpe_distance_m, "RPE segments along the truth [m] (default 10)");
  evl->add_option("--nees-t0", evaluate.nees_t0_s, "Leave the first T0 seconds out of the NEES in-band fraction");
  evl->add_flag("--no-plots", evaluate.no_plots, "Write metrics.json only");
  evl->add_flag("--quiet", evaluate.quiet, "No summary on stdout");

  roamlab::apps::MonteCarloArgs montecarlo;
  CLI::App* mc = app.add_subcommand(
      "montecarlo", "NEES consistency of online tracking over noise realizations (seed 000, Section V, Fig. 4).");
  mc->add_option("scenario", montecarlo.scenario, "Scenario file (SCENARIO.yaml)")->required();
  mc->add_option("--config", montecarlo.config, "Estimator configuration for tracking (EST.yaml)")->required();
  mc->add_option("--calibration", montecarlo.calibration,
                 "calibration.json whose values tracking uses (default: calibrate once with tracking.calibrate)");
  mc->add_option("--runs", montecarlo.runs, "Noise realizations (default 50)");
  mc->add_option("--jobs", montecarlo.jobs, "Parallel runs (default: one per core)");
  mc->add_option("--seed-base", montecarlo.seed_base, "Run i uses noise seed SEED_BASE + i (default 1000)");
  mc->add_option("--t0", montecarlo.t0_s, "Leave the first T0 seconds out of fraction_in_band (default 2)");
  mc->add_flag("--calibrate-each-run", montecarlo.calibrate_each_run,
               "With tracking.calibrate: each run calibrates a drive of its own instead of sharing one calibration");
  mc->add_option("--out", montecarlo.out, "Output directory: nees.json, runs.json, nees.png")->required();
  mc->add_flag("--quiet", montecarlo.quiet, "No progress bar and no summary");

  roamlab::apps::DiagnoseArgs diagnose;
  CLI::App* dia = app.add_subcommand(
      "diagnose", "Reality-gap diagnosis: locate where a recording departs from the nominal model, name the physical "
                  "effect, fit it and show the held-out fit improve (issue 6).");
  dia->add_option("--real", diagnose.recording, "Recording directory (its truth.yaml is never read)")->required();
  dia->add_option("--scenario", diagnose.scenario,
                  "The nominal scenario: the robot as believed (optional with --config and --no-baseline)");
  dia->add_option("--config", diagnose.config, "Nominal estimator configuration (default: built from the scenario)");
  dia->add_option("--out", diagnose.out, "Output directory: gap.json, report.md, scenario_patch.yaml, figures")
      ->required();
  dia->add_flag("--no-baseline", diagnose.no_baseline,
                "Do not simulate the nominal scenario to learn its levels (compare with chi2/dof 1)");
  dia->add_option("--baseline-seed", diagnose.baseline_seed, "Noise seed of the nominal simulation (default 900001)");
  dia->add_option("--max-shift", diagnose.max_shift_s,
                  "Time-shift search range [s] of gps_latency, imu_time_offset and pose_time_offset (default 0.5; "
                  "below 1/12 of the recording's span)");
  dia->add_flag("--no-plots", diagnose.no_plots, "No figures");
  dia->add_flag("--quiet", diagnose.quiet, "No progress and no summary");

  roamlab::apps::GapBenchmarkArgs benchmark;
  CLI::App* gbm = app.add_subcommand(
      "gap-benchmark", "Blind benchmark of the diagnosis: hidden effects (or none, or a decoy) drawn, simulated, "
                       "diagnosed, then scored against truth.yaml.");
  gbm->add_option("--cases", benchmark.cases, "Scored cases (default 16)");
  gbm->add_option("--calibration-cases", benchmark.calibration_cases,
                  "Calibration cases, run first, that fix the thresholds (default 8)");
  gbm->add_option("--seed", benchmark.seed,
                  "Seed of the draws; scored case i uses noise seed SEED * 1000 + i, calibration case i "
                  "SEED * 1000 + 500 + i (default 1)");
  gbm->add_option("--jobs", benchmark.jobs, "Cases in parallel (default 2)");
  gbm->add_option("--duration", benchmark.duration_s, "Drive duration [s] of every case (default: the scenarios')");
  gbm->add_option("--atv", benchmark.atv_scenario, "Nominal ATV scenario (default scenarios/atv_hills_sines.yaml)");
  gbm->add_option("--diffdrive", benchmark.diffdrive_scenario,
                  "Nominal differential-drive scenario (default scenarios/indoor_diffdrive_gap.yaml)");
  gbm->add_option("--mecanum", benchmark.mecanum_scenario,
                  "Nominal mecanum scenario (default scenarios/indoor_mecanum_gap.yaml)");
  gbm->add_option("--out", benchmark.out, "Output directory: score.json, calibration/NNN, cases/NNN")->required();
  gbm->add_flag("--quiet", benchmark.quiet, "No progress");

  roamlab::apps::RegressArgs regress;
  CLI::App* reg = app.add_subcommand(
      "regress", "Run a regression suite: cases with checks against bounds and baselines; JUnit XML for CI.");
  reg->add_option("suite", regress.suite, "Suite file (SUITE.yaml)")->required();
  reg->add_option("--out", regress.out, "Output directory: results.json, junit.xml, cases/NAME/")->required();
  reg->add_option("--baseline", regress.baseline, "Baseline directory (default: the suite's `baseline`)");
  reg->add_flag("--update-baseline", regress.update_baseline, "Write the values as the new baseline, one file a case");
  reg->add_option("--jobs", regress.jobs, "Cases in parallel (default: one per core)");
  reg->add_option("--filter", regress.filter, "Only the cases whose name matches this glob");
  reg->add_flag("--quick", regress.quick, "Only the cases marked `quick: true`");
  reg->add_flag("--quiet", regress.quiet, "No progress lines");

  roamlab::apps::OdometryLearnArgs learn;
  roamlab::apps::OdometryEvaluateArgs odo_eval;
  CLI::App* odo = app.add_subcommand("odometry", "Model-free odometry calibration (seed 001): learn, evaluate.");
  odo->require_subcommand(1);
  CLI::App* odo_learn = odo->add_subcommand(
      "learn", "Learn an odometry model from wheel encoders and an exteroceptive pose stream (CGP, eq. 9, Censi).");
  odo_learn->add_option("--recording", learn.recordings, "Training recording directories")->required();
  odo_learn->add_option("--model", learn.model, "gp | linear | parametric (default gp)");
  odo_learn->add_option("--mean", learn.mean, "GP mean function: zero | linear (default linear)");
  odo_learn->add_option("--kernel", learn.kernel, "GP kernel: rbf | linear | rbf+linear (default rbf)");
  odo_learn->add_option("--interval", learn.interval_s, "Key-time interval T [s] (default 0.5)");
  odo_learn->add_option("--encoders", learn.encoder_stream, "wheel_encoders stream (default: the only one)");
  odo_learn->add_option("--sensor", learn.sensor_stream,
                        "pose stream of the exteroceptive sensor (default: the only one)");
  odo_learn->add_option("--hyperparameter-subset", learn.hyperparameter_subset,
                        "GP: pairs used to optimize the hyper-parameters, 0 = all (default 400)");
  odo_learn->add_option("--outlier-threshold", learn.outlier_threshold,
                        "gp, parametric: drop pairs beyond this many robust sigmas of the eq. 9 fit, 0 = keep "
                        "(default 5)");
  odo_learn->add_option("--max-pairs", learn.max_pairs,
                        "GP: condition on a seeded random subset of at most this many pairs, 0 = all "
                        "(default 6000; memory 3 x 8 n^2 bytes)");
  odo_learn->add_option("--out", learn.out, "Model file (JSON)")->required();
  odo_learn->add_flag("--quiet", learn.quiet, "No progress lines");
  CLI::App* odo_evaluate = odo->add_subcommand(
      "evaluate", "Dead-reckon test recordings with models and the nominal model: ATE (eq. 11), RPE (eq. 10), plots.");
  odo_evaluate->add_option("--model", odo_eval.models, "Model files from `odometry learn`")->required();
  odo_evaluate->add_option("--recording", odo_eval.recordings, "Test recordings with ground_truth.tum")->required();
  odo_evaluate->add_option("--encoders", odo_eval.encoder_stream, "wheel_encoders stream (default: the only one)");
  odo_evaluate->add_option("--out", odo_eval.out, "Output directory: table.json, trajectory_NN.png")->required();
  odo_evaluate->add_flag("--no-plots", odo_eval.no_plots, "Write table.json only");
  odo_evaluate->add_flag("--quiet", odo_eval.quiet, "No table on stdout");

  roamlab::apps::ImportOptiOdomArgs import_optiodom;
  CLI::App* imp = app.add_subcommand("import", "Convert real recordings into the recording format.");
  imp->require_subcommand(1);
  CLI::App* imp_optiodom = imp->add_subcommand("optiodom", "An OptiOdom run (encoder ticks + OptiTrack poses).");
  imp_optiodom->add_option("run", import_optiodom.run_csv, "<set>_run-NN.csv")->required();
  imp_optiodom->add_option("--metadata", import_optiodom.metadata, "Metadata file (default <set>_metadata.csv)");
  imp_optiodom->add_option("--out", import_optiodom.out, "Output recording directory")->required();
  imp_optiodom->add_flag("--quiet", import_optiodom.quiet, "No summary");
  roamlab::apps::ImportRosbagArgs import_rosbag;
  CLI::App* imp_rosbag = imp->add_subcommand("rosbag", "A ROS1 bag (v2.0): sensor_msgs/Imu, nav_msgs/Odometry, "
                                                       "sensor_msgs/NavSatFix.");
  imp_rosbag->add_option("bag", import_rosbag.bag, "BAG.bag")->required();
  imp_rosbag->add_option("--out", import_rosbag.out, "Output recording directory")->required();
  imp_rosbag->add_option("--imu-mounting", import_rosbag.imu_mounting_wxyz,
                         "IMU mounting q_body_imu as W X Y Z (rotates IMU coordinates into the body frame)")
      ->expected(4);
  imp_rosbag->add_option("--platform", import_rosbag.platform_kind, "Platform kind (e.g. skid_steer)");
  imp_rosbag->add_option("--geometry", import_rosbag.geometry, "Nominal geometry KEY=VALUE (repeatable)");
  imp_rosbag->add_flag("--wheels-from-odometry", import_rosbag.wheels_from_odometry,
                       "Also write wheel angles re-expressed from the odometry (needs wheel_radius_m, baseline_m)");
  imp_rosbag->add_flag("--quiet", import_rosbag.quiet, "No summary");

  roamlab::apps::FrontEndArgs front_end;
  CLI::App* fe = app.add_subcommand(
      "frontend", "Run a sensor front end over a recording: visual odometry on a camera stream (vo) or scan "
                  "matching on a laser_scan stream (scan); writes REC2 with the derived stream.");
  fe->add_option("front_end", front_end.front_end, "vo | scan")->required()->check(CLI::IsMember({"vo", "scan"}));
  fe->add_option("recording", front_end.recording, "Recording directory")->required();
  fe->add_option("--out", front_end.out, "Output recording directory (REC's streams plus the derived one)")
      ->required();
  fe->add_option("--input", front_end.input_stream, "Input stream (default: the only camera or laser_scan stream)");
  fe->add_option("--stream", front_end.output_stream,
                 "Name of the derived stream (default visual_odometry or scan_matching; replaces one of that name)");
  fe->add_flag("--quiet", front_end.quiet, "No summary");

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::string what = e.what();
    std::cerr << "roamlab: " << what << " (see roamlab --help)\n";
    return 2;
  }
  if (*sim) {
    if (seed_option->count() > 0) simulate.seed = simulate_seed;
    return roamlab::apps::RunSimulate(simulate);
  }
  if (*cal) return roamlab::apps::RunCalibrate(calibrate);
  if (*trk) return roamlab::apps::RunTrack(track);
  if (*evl) return roamlab::apps::RunEvaluate(evaluate);
  if (*mc) return roamlab::apps::RunMonteCarlo(montecarlo);
  if (*dia) return roamlab::apps::RunDiagnose(diagnose);
  if (*gbm) return roamlab::apps::RunGapBenchmark(benchmark);
  if (*reg) return roamlab::apps::RunRegress(regress);
  if (*odo_learn) return roamlab::apps::RunOdometryLearn(learn);
  if (*odo_evaluate) return roamlab::apps::RunOdometryEvaluate(odo_eval);
  if (*imp_optiodom) return roamlab::apps::RunImportOptiOdom(import_optiodom);
  if (*imp_rosbag) return roamlab::apps::RunImportRosbag(import_rosbag);
  if (*fe) return roamlab::apps::RunFrontEnd(front_end);
  return 2;
}
