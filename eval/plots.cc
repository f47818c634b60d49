#include "eval/plots.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/atomic_file.h"
#include "common/check.h"

namespace roamlab::eval {
namespace {

namespace fs = std::filesystem;

constexpr const char* kTerminal = "set terminal pngcairo size %d,%d noenhanced font 'sans,11'\n";

// A number for a data file; gnuplot reads "NaN" as undefined.
std::string Num(double v) {
  if (!std::isfinite(v)) return "NaN";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.10g", v);
  return buffer;
}

// A double-quoted gnuplot string.
std::string Quote(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

std::string Terminal(int width, int height) {
  char buffer[128];
  std::snprintf(buffer, sizeof buffer, kTerminal, width, height);
  return buffer;
}

Status WriteText(const std::string& directory, const std::string& name, const std::string& text) {
  const std::string path = (fs::path(directory) / name).string();
  return WriteFileAtomic(path, text);
}

// "t x y z" rows of a trajectory, t in seconds since t_origin.
std::string TrajectoryData(const std::string& what, Time t_origin, const Trajectory& trajectory) {
  std::ostringstream s;
  s << "# " << what << "\n# t_s east_m north_m up_m\n";
  for (const StampedPose& pose : trajectory)
    s << Num(SecondsBetween(t_origin, pose.t)) << ' ' << Num(pose.p_world_body.x()) << ' ' << Num(pose.p_world_body.y())
      << ' ' << Num(pose.p_world_body.z()) << '\n';
  return s.str();
}

// Line colours of estimates, in order.
constexpr const char* kSeriesColors[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#17becf"};
constexpr std::size_t kSeriesColorCount = sizeof kSeriesColors / sizeof kSeriesColors[0];

// A file-name-safe version of a label.
std::string Slug(const std::string& label) {
  std::string out;
  for (char c : label) out += (std::isalnum(static_cast<unsigned char>(c)) ? c : '_');
  return out;
}

}  // namespace

Result<PlotFiles> WriteTrajectoryPlot(const std::string& directory, const std::string& title, Time t_origin,
                                      const PlottedTrajectory& reference,
                                      const std::vector<PlottedTrajectory>& estimates,
                                      const std::vector<PositionFixes>& fixes) {
  PlotFiles files{"trajectory.gp", "trajectory.png", {"trajectory_reference.dat"}};
  // Data: reference, estimates, one file per fix stream.
  if (Status s = WriteText(directory, files.data[0], TrajectoryData(reference.label, t_origin, reference.poses));
      !s.ok())
    return s;
  std::ostringstream plot;
  plot << "plot " << Quote(files.data[0]) << " using 2:3 with lines lw 2.5 lc rgb '#222222' title "
       << Quote(reference.label);
  for (std::size_t k = 0; k < estimates.size(); ++k) {
    const std::string name =
        k == 0 ? "trajectory_estimate.dat" : "trajectory_estimate_" + std::to_string(k + 1) + ".dat";
    if (Status s = WriteText(directory, name, TrajectoryData(estimates[k].label, t_origin, estimates[k].poses));
        !s.ok())
      return s;
    files.data.push_back(name);
    plot << ", \\\n     " << Quote(name) << " using 2:3 with lines lw 1.5 lc rgb '"
         << kSeriesColors[k % kSeriesColorCount] << "' title " << Quote(estimates[k].label);
  }
  const char* kFixColors[] = {"#d62728", "#2ca02c", "#9467bd", "#ff7f0e"};
  for (std::size_t k = 0; k < fixes.size(); ++k) {
    const PositionFixes& f = fixes[k];
    ROAMLAB_CHECK(f.t.size() == f.p_world.size(), "fixes '" << f.label << "': times and positions differ in size");
    const std::string name = "trajectory_fixes_" + Slug(f.name.empty() ? std::to_string(k) : f.name) + ".dat";
    std::ostringstream s;
    s << "# " << f.label << "\n# t_s east_m north_m up_m\n";
    for (std::size_t i = 0; i < f.t.size(); ++i)
      s << Num(SecondsBetween(t_origin, f.t[i])) << ' ' << Num(f.p_world[i].x()) << ' ' << Num(f.p_world[i].y()) << ' '
        << Num(f.p_world[i].z()) << '\n';
    if (Status st = WriteText(directory, name, s.str()); !st.ok()) return st;
    files.data.push_back(name);
    plot << ", \\\n     " << Quote(name) << " using 2:3 with points pt 7 ps 0.6 lc rgb '" << kFixColors[k % 4]
         << "' title " << Quote(f.label);
  }
  const Trajectory& truth = reference.poses;
  // Script: equal axis scales so that the shape of the path is true, on a canvas shaped like the path.
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(0.0);
  Eigen::Vector2d hi = Eigen::Vector2d::Constant(0.0);
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const Eigen::Vector2d p = truth[i].p_world_body.head<2>();
    lo = i == 0 ? p : Eigen::Vector2d(lo.cwiseMin(p));
    hi = i == 0 ? p : Eigen::Vector2d(hi.cwiseMax(p));
  }
  const Eigen::Vector2d extent = (hi - lo).cwiseMax(1e-3);
  const double aspect = std::clamp(extent.y() / extent.x(), 0.5, 2.0);  // height / width of the plot area
  const int width = static_cast<int>(std::lround(std::clamp(800.0 / aspect + 200.0, 700.0, 1400.0)));
  std::ostringstream gp;
  gp << "# Redraw: cd into this directory, then: gnuplot " << files.script << "\n"
     << Terminal(width, 1000) << "set output " << Quote(files.image) << "\n"
     << "set title " << Quote(title) << "\n"
     << "set xlabel 'East [m]'\nset ylabel 'North [m]'\n"
     << "set size ratio -1\nset grid\n"
     // Legend centred under the x label (with an equal-scale plot `set key below` can overlap the label).
     << "set key at screen 0.5, screen 0.015 center bottom vertical box\n"
     << "set bmargin " << 4 + 2 * static_cast<int>(1 + estimates.size() + fixes.size()) * 4 / 5 << "\n"
     << plot.str() << "\n";
  if (Status s = WriteText(directory, files.script, gp.str()); !s.ok()) return s;
  return files;
}

Result<PlotFiles> WritePositionErrorPlot(const std::string& directory, const std::string& title, Time t_origin,
                                         const std::vector<Time>& t, const std::vector<Eigen::Vector3d>& error_world,
                                         const std::vector<Eigen::Vector3d>& sigma_world) {
  ROAMLAB_CHECK(t.size() == error_world.size(),
                "position error: " << t.size() << " stamps, " << error_world.size() << " errors");
  const bool envelope = !sigma_world.empty();
  ROAMLAB_CHECK(!envelope || sigma_world.size() == t.size(), "position error: sigma size " << sigma_world.size());
  PlotFiles files{"position_error.gp", "position_error.png", {"position_error.dat"}};
  // Data: t, error E N U, sigma E N U.
  std::ostringstream s;
  s << "# position error of the estimate (estimate - truth) [m] and its standard deviation [m]\n"
    << "# t_s err_east_m err_north_m err_up_m sigma_east_m sigma_north_m sigma_up_m\n";
  for (std::size_t i = 0; i < t.size(); ++i) {
    s << Num(SecondsBetween(t_origin, t[i]));
    for (int a = 0; a < 3; ++a) s << ' ' << Num(error_world[i][a]);
    for (int a = 0; a < 3; ++a) s << ' ' << (envelope ? Num(sigma_world[i][a]) : "NaN");
    s << '\n';
  }
  if (Status st = WriteText(directory, files.data[0], s.str()); !st.ok()) return st;
  // Script: one panel per axis, the shaded envelope behind the error line.
  std::ostringstream gp;
  gp << "# Redraw: cd into this directory, then: gnuplot " << files.script << "\n"
     << Terminal(1000, 1000) << "set output " << Quote(files.image) << "\n"
     << "set multiplot layout 3,1 title " << Quote(title) << "\n"
     << "set grid\nset key top right box opaque\nset xlabel 'time since start [s]'\n";
  const char* kAxes[] = {"East", "North", "Up"};
  for (int a = 0; a < 3; ++a) {
    gp << "set ylabel '" << kAxes[a] << " error [m]'\n";
    gp << "plot ";
    if (envelope)
      gp << Quote(files.data[0]) << " using 1:(-3*$" << 5 + a << "):(3*$" << 5 + a
         << ") with filledcurves fc rgb '#1f77b4' fs transparent solid 0.2 noborder title '+-3 sigma (estimated)', \\\n"
         << "     ";
    gp << Quote(files.data[0]) << " using 1:" << 2 + a << " with lines lw 1.5 lc rgb '#1f77b4' title '" << kAxes[a]
       << " error'\n";
  }
  gp << "unset multiplot\n";
  if (Status st = WriteText(directory, files.script, gp.str()); !st.ok()) return st;
  return files;
}

Result<PlotFiles> WriteErrorOverTimePlot(const std::string& directory, const std::string& title, Time t_origin,
                                         const std::vector<ErrorSeries>& series) {
  PlotFiles files{"ate_over_time.gp", "ate_over_time.png", {}};
  bool rotation = false;
  for (std::size_t k = 0; k < series.size(); ++k) {
    const ErrorSeries& e = series[k];
    ROAMLAB_CHECK(e.t.size() == e.position_m.size() && (e.rotation_deg.empty() || e.rotation_deg.size() == e.t.size()),
                  "error series '" << e.label << "': sizes differ");
    rotation = rotation || !e.rotation_deg.empty();
    std::ostringstream s;
    s << "# " << e.label << "\n# t_s position_error_m rotation_error_deg\n";
    for (std::size_t i = 0; i < e.t.size(); ++i)
      s << Num(SecondsBetween(t_origin, e.t[i])) << ' ' << Num(e.position_m[i]) << ' '
        << (e.rotation_deg.empty() ? "NaN" : Num(e.rotation_deg[i])) << '\n';
    files.data.push_back("ate_over_time_" + std::to_string(k + 1) + ".dat");
    if (Status st = WriteText(directory, files.data.back(), s.str()); !st.ok()) return st;
  }
  std::ostringstream gp;
  gp << "# Redraw: cd into this directory, then: gnuplot " << files.script << "\n"
     << Terminal(1000, rotation ? 900 : 500) << "set output " << Quote(files.image) << "\n"
     << "set multiplot layout " << (rotation ? 2 : 1) << ",1 title " << Quote(title) << "\n"
     << "set grid\nset key top right box opaque\nset xlabel 'time since start [s]'\n";
  const auto panel = [&](int column, const char* ylabel) {
    gp << "set ylabel '" << ylabel << "'\nplot ";
    for (std::size_t k = 0; k < series.size(); ++k)
      gp << (k ? ", \\\n     " : "") << Quote(files.data[k]) << " using 1:" << column << " with lines lw 1.2 lc rgb '"
         << kSeriesColors[k % kSeriesColorCount] << "' title " << Quote(series[k].label);
    gp << "\n";
  };
  if (!series.empty()) {
    panel(2, "position error [m]");
    if (rotation) panel(3, "rotation error [deg]");
  }
  gp << "unset multiplot\n";
  if (Status st = WriteText(directory, files.script, gp.str()); !st.ok()) return st;
  return files;
}

Result<PlotFiles> WriteNeesPlot(const std::string& directory, const std::string& title, const MonteCarloNees& nees,
                                const std::string& name) {
  ROAMLAB_CHECK(nees.t.size() == nees.mean_nees.size(), "NEES: time and value sizes differ");
  PlotFiles files{name + ".gp", name + ".png", {name + ".dat"}};
  const Time t_origin = nees.t.empty() ? Time() : nees.t.front();
  std::ostringstream s;
  s << "# average NEES over " << nees.runs << " run(s), dof " << nees.dof << "; band [" << Num(nees.band.lo) << ", "
    << Num(nees.band.hi) << "]\n# t_s mean_nees\n";
  for (std::size_t k = 0; k < nees.t.size(); ++k)
    s << Num(SecondsBetween(t_origin, nees.t[k])) << ' ' << Num(nees.mean_nees[k]) << '\n';
  if (Status st = WriteText(directory, files.data[0], s.str()); !st.ok()) return st;

  char band_label[160];
  std::snprintf(band_label, sizeof band_label, "%g%% band of chi-square(%d) / %d: [%.3f, %.3f]",
                100.0 * (1.0 - nees.alpha), nees.runs * nees.dof, nees.runs, nees.band.lo, nees.band.hi);
  std::ostringstream gp;
  gp << "# Redraw: cd into this directory, then: gnuplot " << files.script << "\n"
     << Terminal(1000, 600) << "set output " << Quote(files.image) << "\n"
     << "set title " << Quote(title) << "\n"
     << "set xlabel 'time since start [s]'\nset ylabel '" << (nees.runs == 1 ? "NEES" : "average NEES") << " [-]'\n"
     << "set grid\nset key top right box opaque\n"
     << "lo = " << Num(nees.band.lo) << "\nhi = " << Num(nees.band.hi) << "\n";
  if (nees.t0_s > 0.0)
    gp << "set arrow from " << Num(nees.t0_s) << ", graph 0 to " << Num(nees.t0_s)
       << ", graph 1 nohead dt 3 lc rgb '#555555'\n"
       << "set label 'T0' at " << Num(nees.t0_s) << ", graph 0.95 offset 0.5,0\n";
  const std::string curve = nees.runs == 1 ? "NEES" : "average NEES over " + std::to_string(nees.runs) + " runs";
  gp << "plot " << Quote(files.data[0]) << " using 1:2 with lines lw 1.5 lc rgb '#1f77b4' title " << Quote(curve)
     << ", \\\n"
     << "     lo with lines dt 2 lw 1.5 lc rgb '#d62728' title " << Quote(band_label) << ", \\\n"
     << "     hi with lines dt 2 lw 1.5 lc rgb '#d62728' notitle\n";
  if (Status st = WriteText(directory, files.script, gp.str()); !st.ok()) return st;
  return files;
}

Result<PlotFiles> WriteVelocityPlot(const std::string& directory, const std::string& title, const VelocityPlotData& d) {
  ROAMLAB_CHECK(d.fused_t_s.size() == d.truth.size() && d.fused_t_s.size() == d.fused.size() &&
                    d.encoders_t_s.size() == d.encoders.size() && d.rpe_fused_t_s.size() == d.rpe_fused_deg.size() &&
                    d.rpe_encoders_t_s.size() == d.rpe_encoders_deg.size(),
                "velocity plot: sizes differ");
  PlotFiles files{
      "velocity.gp",
      "velocity.png",
      {"velocity_fused.dat", "velocity_encoders.dat", "velocity_rpe_fused.dat", "velocity_rpe_encoders.dat"}};
  std::ostringstream fused, encoders, rpe_fused, rpe_encoders;
  fused << "# t_s true_vx_mps true_wz_radps fused_vx_mps fused_wz_radps\n";
  for (std::size_t i = 0; i < d.fused_t_s.size(); ++i)
    fused << Num(d.fused_t_s[i]) << ' ' << Num(d.truth[i].v_body.x()) << ' ' << Num(d.truth[i].omega_body.z()) << ' '
          << Num(d.fused[i].v_body.x()) << ' ' << Num(d.fused[i].omega_body.z()) << '\n';
  encoders << "# t_s encoders_vx_mps encoders_wz_radps\n";
  for (std::size_t i = 0; i < d.encoders_t_s.size(); ++i)
    encoders << Num(d.encoders_t_s[i]) << ' ' << Num(d.encoders[i].v_body.x()) << ' '
             << Num(d.encoders[i].omega_body.z()) << '\n';
  rpe_fused << "# t_s rpe_rot_deg\n";
  for (std::size_t i = 0; i < d.rpe_fused_t_s.size(); ++i)
    rpe_fused << Num(d.rpe_fused_t_s[i]) << ' ' << Num(d.rpe_fused_deg[i]) << '\n';
  rpe_encoders << "# t_s rpe_rot_deg\n";
  for (std::size_t i = 0; i < d.rpe_encoders_t_s.size(); ++i)
    rpe_encoders << Num(d.rpe_encoders_t_s[i]) << ' ' << Num(d.rpe_encoders_deg[i]) << '\n';
  const std::string texts[4] = {fused.str(), encoders.str(), rpe_fused.str(), rpe_encoders.str()};
  for (int k = 0; k < 4; ++k)
    if (Status st = WriteText(directory, files.data[k], texts[k]); !st.ok()) return st;

  const std::string f = Quote(files.data[0]), e = Quote(files.data[1]);
  std::ostringstream gp;
  gp << "# Redraw: cd into this directory, then: gnuplot " << files.script << "\n"
     << Terminal(1100, 1000) << "set output " << Quote(files.image) << "\n"
     << "set multiplot layout 3,1 title " << Quote(title) << "\n"
     << "set grid\nset key top right box opaque\nset xlabel 'time since start [s]'\n"
     << "set ylabel 'forward speed v_x [m/s]'\n"
     << "plot " << f << " using 1:2 with lines lw 2 lc rgb '#d62728' title 'ground truth', \\\n"
     << "     " << e << " using 1:2 with lines lw 1 lc rgb '#1f77b4' title 'encoders (forward kinematics)', \\\n"
     << "     " << f << " using 1:4 with lines lw 1.2 lc rgb '#2ca02c' title 'fused estimate'\n"
     << "set ylabel 'yaw rate omega_z [rad/s]'\n"
     << "plot " << f << " using 1:3 with lines lw 2 lc rgb '#d62728' title 'ground truth', \\\n"
     << "     " << e << " using 1:3 with lines lw 1 lc rgb '#1f77b4' title 'encoders (forward kinematics)', \\\n"
     << "     " << f << " using 1:5 with lines lw 1.2 lc rgb '#2ca02c' title 'fused estimate'\n"
     << "set ylabel 'rotational RPE [deg]'\n"
     << "plot " << Quote(files.data[3]) << " using 1:2 with lines lw 1 lc rgb '#1f77b4' title 'encoders', \\\n"
     << "     " << Quote(files.data[2]) << " using 1:2 with lines lw 1.2 lc rgb '#2ca02c' title 'fused estimate'\n"
     << "unset multiplot\n";
  if (Status st = WriteText(directory, files.script, gp.str()); !st.ok()) return st;
  return files;
}

Result<PlotFiles> WriteConsistencyPlot(const std::string& directory, const std::string& title,
                                       const std::vector<NormalizedErrors>& components) {
  PlotFiles files{"consistency.gp", "consistency.png", {"consistency_errors.dat", "consistency_coverage.dat"}};
  std::ostringstream errors, coverage, tics;
  errors << "# component error_over_std (one row per run)\n";
  coverage << "# component coverage_1sigma_pct coverage_2sigma_pct coverage_3sigma_pct label\n";
  for (std::size_t c = 0; c < components.size(); ++c) {
    for (double e : components[c].error_over_std) errors << c << ' ' << Num(e) << '\n';
    coverage << c;
    for (double f : components[c].coverage) coverage << ' ' << Num(100.0 * f);
    coverage << ' ' << components[c].label << '\n';
    tics << (c == 0 ? "" : ", ") << Quote(components[c].label) << ' ' << c;
  }
  if (Status st = WriteText(directory, files.data[0], errors.str()); !st.ok()) return st;
  if (Status st = WriteText(directory, files.data[1], coverage.str()); !st.ok()) return st;

  const int width = std::max(900, 40 * static_cast<int>(components.size()) + 200);
  std::ostringstream gp;
  gp << "# Redraw: cd into this directory, then: gnuplot " << files.script << "\n"
     << Terminal(width, 900) << "set output " << Quote(files.image) << "\n"
     << "set multiplot layout 2,1 title " << Quote(title) << "\n"
     << "set xrange [-0.5:" << Num(components.size() - 0.5) << "]\nset grid ytics\nset key top right box opaque\n"
     << "set lmargin 10\nset rmargin 3\nset xtics 1\nset format x ''\n"
     << "set ylabel 'error / reported std'\nset yrange [*<-4:4<*]\n"
     << "plot " << Quote(files.data[0]) << " using 1:2 with points pt 7 ps 0.6 lc rgb '#1f77b4' title 'runs', \\\n"
     << "     2 with lines dt 2 lw 1.5 lc rgb '#d62728' title '+-2', \\\n"
     << "     -2 with lines dt 2 lw 1.5 lc rgb '#d62728' notitle\n"
     << "set format x '%g'\nset xtics (" << tics.str() << ") rotate by 45 right\n"
     << "set ylabel 'coverage [%]'\nset yrange [0:130]\nset ytics 0, 20, 100\n"
     << "set key top center horizontal box opaque\n"
     << "set boxwidth 0.25\nset style fill solid 0.8 noborder\n"
     << "plot " << Quote(files.data[1]) << " using ($1-0.27):2 with boxes lc rgb '#9ecae1' title '1 sigma', \\\n"
     << "     '' using 1:3 with boxes lc rgb '#4292c6' title '2 sigma', \\\n"
     << "     '' using ($1+0.27):4 with boxes lc rgb '#08519c' title '3 sigma', \\\n"
     << "     68.27 with lines dt 2 lc rgb '#555555' title 'nominal 68.3, 95.4, 99.7 %', \\\n"
     << "     95.45 with lines dt 2 lc rgb '#555555' notitle, 99.73 with lines dt 2 lc rgb '#555555' notitle\n"
     << "unset multiplot\n";
  if (Status st = WriteText(directory, files.script, gp.str()); !st.ok()) return st;
  return files;
}

bool GnuplotAvailable() {
  const char* path = std::getenv("PATH");
  if (!path) return false;
  std::stringstream dirs(path);
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    if (dir.empty()) continue;
    const std::string candidate = (fs::path(dir) / "gnuplot").string();
    struct stat info {};
    if (::stat(candidate.c_str(), &info) == 0 && S_ISREG(info.st_mode) && ::access(candidate.c_str(), X_OK) == 0)
      return true;
  }
  return false;
}

Result<PlotFiles> WriteInformationPlot(const std::string& directory, const std::string& title,
                                       const InformationPlotData& data) {
  ROAMLAB_CHECK(data.shares.size() == data.rows.size(), "one share row per label");
  ROAMLAB_CHECK(data.speed_mps.size() == data.t_s.size() && data.yaw_rate_radps.size() == data.t_s.size() &&
                data.pitch_deg.size() == data.t_s.size(),
                "one drive value per sample");
  PlotFiles files{"information.gp", "information.png", {"information_shares.dat", "information_drive.dat"}};
  // Shares: one pixel per (window, row), the row index counted down from the top.
  std::ostringstream shares;
  shares << "# variance share of each component per window [%]\n# window_middle_s row share_percent\n";
  std::size_t windows = 0;
  for (std::size_t r = 0; r < data.rows.size(); ++r) {
    windows = std::max(windows, data.shares[r].size());
    for (std::size_t k = 0; k < data.shares[r].size(); ++k)
      shares << Num((static_cast<double>(k) + 0.5) * data.window_s) << ' ' << r << ' '
             << Num(100.0 * data.shares[r][k]) << '\n';
    shares << '\n';
  }
  if (Status st = WriteText(directory, files.data[0], shares.str()); !st.ok()) return st;
  std::ostringstream drive;
  drive << "# the drive (true poses)\n# t_s speed_mps yaw_rate_radps pitch_deg\n";
  for (std::size_t i = 0; i < data.t_s.size(); ++i)
    drive << Num(data.t_s[i]) << ' ' << Num(data.speed_mps[i]) << ' ' << Num(data.yaw_rate_radps[i]) << ' '
          << Num(data.pitch_deg[i]) << '\n';
  if (Status st = WriteText(directory, files.data[1], drive.str()); !st.ok()) return st;

  // Script: the heat map over 55 % of the page, the drive's three panels below it, x axes aligned by fixed margins.
  const double t_end = static_cast<double>(windows) * data.window_s;
  const int height = 700 + 18 * static_cast<int>(data.rows.size());
  std::ostringstream gp;
  gp << "# Redraw: cd into this directory, then: gnuplot " << files.script << "\n"
     << Terminal(1200, height) << "set output " << Quote(files.image) << "\n"
     << "set multiplot title " << Quote(title) << "\n"
     << "set lmargin at screen 0.22\nset rmargin at screen 0.88\nset xrange [0:" << Num(t_end) << "]\n"
     << "set size 1,0.52\nset origin 0,0.45\nset tmargin at screen 0.95\nset bmargin at screen 0.47\n"
     << "set yrange [" << Num(static_cast<double>(data.rows.size()) - 0.5) << ":-0.5]\nset ytics (";
  for (std::size_t r = 0; r < data.rows.size(); ++r) gp << (r ? ", " : "") << Quote(data.rows[r]) << ' ' << r;
  gp << ") font 'sans,9'\nset format x ''\nset cbrange [0:*]\nset cblabel 'variance share [%]'\n"
     << "set palette defined (0 'white', 1 '#9ecae1', 2 '#3182bd', 3 '#08306b')\n"
     << "plot " << Quote(files.data[0]) << " using 1:2:3 with image notitle\n"
     << "unset colorbox\nset ytics auto font 'sans,10'\nset autoscale y\nset grid\n";
  const char* kLabels[] = {"speed [m/s]", "yaw rate [deg/s]", "pitch [deg]"};
  const char* kColumns[] = {"2", "($3*180/pi)", "4"};
  for (int panel = 0; panel < 3; ++panel) {
    const double top = 0.44 - 0.135 * panel;
    gp << "set tmargin at screen " << Num(top) << "\nset bmargin at screen " << Num(top - 0.11) << "\n"
       << "set ylabel '" << kLabels[panel] << "'\n";
    if (panel == 2) gp << "set format x '%g'\nset xlabel 'time since start [s]'\n";
    gp << "plot " << Quote(files.data[1]) << " using 1:" << kColumns[panel]
       << " with lines lw 1.5 lc rgb '#1f77b4' notitle\n";
  }
  gp << "unset multiplot\n";
  if (Status st = WriteText(directory, files.script, gp.str()); !st.ok()) return st;
  return files;
}

Status RunGnuplot(const std::string& directory, const std::string& script) {
  if (!GnuplotAvailable()) return Status::Error("gnuplot not found on PATH");
  const std::string stem = fs::path(script).stem().string();
  const std::string log_path = (fs::path(directory) / (stem + ".log")).string();
  // Child: into the directory, messages to the log, then gnuplot.
  const pid_t pid = ::fork();
  if (pid < 0) return Status::Error("cannot start gnuplot: fork failed");
  if (pid == 0) {
    if (::chdir(directory.c_str()) != 0) ::_exit(126);
    const int log = ::open((stem + ".log").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (log >= 0) {
      ::dup2(log, STDOUT_FILENO);
      ::dup2(log, STDERR_FILENO);
      ::close(log);
    }
    ::execlp("gnuplot", "gnuplot", script.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return Status::Error("gnuplot: waitpid failed");
  }
  // The log: first line for the error message, removed when empty.
  std::string first_line;
  {
    std::ifstream log(log_path);
    std::getline(log, first_line);
  }
  std::error_code ec;
  if (fs::exists(log_path, ec) && fs::file_size(log_path, ec) == 0) fs::remove(log_path, ec);
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return Status::Ok();
  if (WIFEXITED(status) && WEXITSTATUS(status) == 126) return Status::Error(directory + ": cannot enter directory");
  if (WIFEXITED(status) && WEXITSTATUS(status) == 127) return Status::Error("cannot run gnuplot");
  return Status::Error((fs::path(directory) / script).string() + ": gnuplot failed" +
                       (first_line.empty() ? "" : ": " + first_line) + " (see " + log_path + ")");
}

}  // namespace roamlab::eval
