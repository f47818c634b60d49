// roamlab: the command line. `roamlab --help` and `roamlab <command> --help` describe every command.
#include <iostream>

#include <CLI/CLI.hpp>

#include "apps/commands.h"
#include "apps/evaluate.h"

int main(int argc, char** argv) {
  CLI::App app{"roamlab: mobile-robot pose tracking and sensor self-calibration testbed"};
  app.require_subcommand(1);

  roamlab::apps::CalibrateArgs calibrate;
  CLI::App* cal = app.add_subcommand(
      "calibrate", "Offline self-calibration of the free parameters over a whole recording (seed 000, Section V).");
  cal->add_option("recording", calibrate.recording, "Recording directory (recording.yaml + CSV streams)")
      ->required();
  cal->add_option("--config", calibrate.config, "Estimator configuration (EST.yaml)")->required();
  cal->add_option("--out", calibrate.out, "Output directory: calibration.json, trajectory.tum")->required();
  cal->add_flag("--quiet", calibrate.quiet, "No progress lines");

  roamlab::apps::TrackArgs track;
  CLI::App* trk = app.add_subcommand(
      "track", "Online fixed-lag tracking with marginalization (seed 000, Section III-B).");
  trk->add_option("recording", track.recording, "Recording directory")->required();
  trk->add_option("--config", track.config, "Estimator configuration (EST.yaml)")->required();
  trk->add_option("--calibration", track.calibration, "calibration.json from `roamlab calibrate` (fixes parameters)");
  trk->add_option("--out", track.out, "Output directory: trajectory.tum, covariance.csv, summary.json")->required();
  trk->add_flag("--quiet", track.quiet, "No progress lines");

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
  if (*cal) return roamlab::apps::RunCalibrate(calibrate);
  if (*trk) return roamlab::apps::RunTrack(track);
  if (*evl) return roamlab::apps::RunEvaluate(evaluate);
  return 2;
}
