// roamlab: the command line. `roamlab --help` and `roamlab <command> --help` describe every command.
#include <iostream>

#include <CLI/CLI.hpp>

#include "apps/commands.h"

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
  return 2;
}
