// Figures drawn with gnuplot (Debian package gnuplot-nox, terminal pngcairo). Each Write*Plot writes its data files
// (whitespace-separated columns with a '#' header) and a gnuplot script into a directory; the script refers to them by
// relative names, so `cd DIR && gnuplot NAME.gp` redraws NAME.png after editing either. RunGnuplot runs a script.
//
//   trajectory       top view (East, North) of the reference (ground truth), one or several estimates and absolute
//                    fixes (the seed's Fig. 3)
//   position_error   estimate - truth per axis (E, N, U) against time, with the +-3 sigma envelope when known
//   ate_over_time    position error norm (and rotation error) of several estimates against time
//   nees             average NEES against time with the chi-square band lines (the seed's Fig. 4)
//   velocity         forward speed, yaw rate and rotational RPE against time: truth, encoders alone, fused estimate
//                    (the seed's Fig. 6)
//   consistency      a calibration's normalized errors over Monte-Carlo runs per parameter component, and the
//                    coverage of its 1, 2, 3 sigma intervals (eval/calibration_consistency.h)
#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "eval/nees.h"
#include "eval/velocity.h"
#include "recording/trajectory.h"

namespace roamlab::eval {

// What a writer produced, as file names relative to its directory.
struct PlotFiles {
  std::string script;             // NAME.gp
  std::string image;              // NAME.png (written by RunGnuplot)
  std::vector<std::string> data;  // NAME*.dat
};

// Positions of an absolute sensor in the reference world frame (GPS converted to ENU, motion capture, ...).
struct PositionFixes {
  std::string name;   // stream name; the data file is trajectory_fixes_<name>.dat
  std::string label;  // legend text, e.g. "GPS fixes (gps)"
  std::vector<Time> t;
  std::vector<Eigen::Vector3d> p_world;  // [m]
};

// A trajectory to draw and its legend text.
struct PlottedTrajectory {
  std::string label;
  Trajectory poses;
};

// Top view. Estimates are drawn as given (align them first); data files trajectory_reference.dat,
// trajectory_estimate.dat for the first estimate and trajectory_estimate_<k>.dat (k = 2, 3, ...) for the others, one
// per fix stream. Time columns are seconds since t_origin.
Result<PlotFiles> WriteTrajectoryPlot(const std::string& directory, const std::string& title, Time t_origin,
                                      const PlottedTrajectory& reference,
                                      const std::vector<PlottedTrajectory>& estimates,
                                      const std::vector<PositionFixes>& fixes);

// Three stacked panels, East, North, Up. t: one stamp per error; errors [m]; sigma_world: one standard deviation per
// axis [m] per stamp, or empty for no envelope (sizes CHECKed).
Result<PlotFiles> WritePositionErrorPlot(const std::string& directory, const std::string& title, Time t_origin,
                                         const std::vector<Time>& t, const std::vector<Eigen::Vector3d>& error_world,
                                         const std::vector<Eigen::Vector3d>& sigma_world);

// One estimate's errors at its matched poses.
struct ErrorSeries {
  std::string label;
  std::vector<Time> t;
  std::vector<double> position_m;    // |error| per stamp [m]
  std::vector<double> rotation_deg;  // per stamp [deg], or empty (no rotation panel line)
};
// ate_over_time.gp/.png and ate_over_time_<k>.dat (k = 1, 2, ...): the position error of every series against time,
// and a second panel with the rotation errors when any series has them. Sizes CHECKed.
Result<PlotFiles> WriteErrorOverTimePlot(const std::string& directory, const std::string& title, Time t_origin,
                                         const std::vector<ErrorSeries>& series);

// Average NEES and the band [lo, hi] (dashed), with a dotted line at t0_s when it is positive. Files NAME.gp, NAME.dat,
// NAME.png with NAME = `name`.
Result<PlotFiles> WriteNeesPlot(const std::string& directory, const std::string& title, const MonteCarloNees& nees,
                                const std::string& name = "nees");

// What the velocity figure draws; times in seconds since the truth's first stamp, one per twist or RPE pair.
struct VelocityPlotData {
  std::vector<double> fused_t_s;
  std::vector<StampedTwist> truth;  // at fused_t_s
  std::vector<StampedTwist> fused;  // at fused_t_s
  std::vector<double> encoders_t_s;
  std::vector<StampedTwist> encoders;  // at encoders_t_s
  std::vector<double> rpe_fused_t_s, rpe_fused_deg, rpe_encoders_t_s, rpe_encoders_deg;
};
// Three stacked panels: v_x [m/s], omega_z [rad/s], rotational RPE [deg]. Files velocity.gp, velocity_*.dat,
// velocity.png. Sizes CHECKed.
Result<PlotFiles> WriteVelocityPlot(const std::string& directory, const std::string& title,
                                    const VelocityPlotData& data);

// One calibrated parameter component over Monte-Carlo runs.
struct NormalizedErrors {
  std::string label;                    // "gps.lever_arm[2]" (no spaces)
  std::vector<double> error_over_std;   // per run; NaN where the std is unknown
  std::array<double, 3> coverage{};     // share of runs within 1, 2, 3 reported std
};
// Two stacked panels over the components: every run's error / std with the +-2 band, and the coverage of the 1, 2, 3
// sigma intervals [%] as bars beside their nominal shares (68.3, 95.4, 99.7 %). Files consistency.gp,
// consistency_errors.dat, consistency_coverage.dat, consistency.png.
Result<PlotFiles> WriteConsistencyPlot(const std::string& directory, const std::string& title,
                                       const std::vector<NormalizedErrors>& components);

// True when an executable named gnuplot is on PATH.
bool GnuplotAvailable();

// What the information figure draws (`roamlab information`, docs/methods-information.md): per row (a parameter
// component) its share of the information in each time window, and the drive along it.
struct InformationPlotData {
  double window_s = 1.0;
  std::vector<std::string> rows;               // component labels, drawn top to bottom
  std::vector<std::vector<double>> shares;     // [row][window], NaN where undefined (unobservable)
  std::vector<double> t_s;                     // drive samples, seconds since the first window's start
  std::vector<double> speed_mps, yaw_rate_radps, pitch_deg;  // at t_s
};
// A heat map of the shares (rows x windows, one colour scale) above three panels: speed [m/s], yaw rate [deg/s] and
// pitch [deg] on the same time axis. Files information.gp, information_shares.dat, information_drive.dat,
// information.png. Sizes CHECKed.
Result<PlotFiles> WriteInformationPlot(const std::string& directory, const std::string& title,
                                       const InformationPlotData& data);

// Runs `gnuplot SCRIPT` with `directory` as working directory. Its messages go to SCRIPT-without-.gp.log in the
// directory (removed when empty). Errors: gnuplot missing, not started, or exiting non-zero (with its first message).
Status RunGnuplot(const std::string& directory, const std::string& script);

}  // namespace roamlab::eval
