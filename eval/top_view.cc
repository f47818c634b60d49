#include "eval/top_view.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <utility>

#include <Eigen/Geometry>

#include "common/atomic_file.h"
#include "eval/plots.h"

namespace roamlab::eval {
namespace {

namespace fs = std::filesystem;

double Yaw(const Eigen::Quaterniond& q) {
  return std::atan2(2.0 * (q.w() * q.z() + q.x() * q.y()), 1.0 - 2.0 * (q.y() * q.y() + q.z() * q.z()));
}

double WrapAngle(double angle_rad) { return std::atan2(std::sin(angle_rad), std::cos(angle_rad)); }

}  // namespace

bool PlanarPoseAt(const Trajectory& trajectory, Time t, Eigen::Vector3d* x_y_yaw) {
  if (trajectory.size() < 2 || t < trajectory.front().t || t > trajectory.back().t) return false;
  const auto it =
      std::upper_bound(trajectory.begin(), trajectory.end(), t, [](Time q, const StampedPose& p) { return q < p.t; });
  std::size_t i = it == trajectory.begin() ? 0 : static_cast<std::size_t>(it - trajectory.begin()) - 1;
  i = std::min(i, trajectory.size() - 2);
  const double w = SecondsBetween(trajectory[i].t, t) / SecondsBetween(trajectory[i].t, trajectory[i + 1].t);
  const double a = Yaw(trajectory[i].q_world_body);
  const double b = Yaw(trajectory[i + 1].q_world_body);
  const Eigen::Vector3d p = (1.0 - w) * trajectory[i].p_world_body + w * trajectory[i + 1].p_world_body;
  *x_y_yaw = Eigen::Vector3d(p.x(), p.y(), a + w * WrapAngle(b - a));
  return true;
}

Status WriteTopViewFigure(const std::string& dir, const std::string& name, const std::string& title,
                          const std::vector<Eigen::Vector3d>& reference, const std::vector<TopViewSeries>& series,
                          const std::string& reference_label) {
  std::ostringstream data;
  data << "# x_ref_m y_ref_m";
  for (const TopViewSeries& e : series) data << "  x_m y_m (" << e.label << ")";
  data << "\n";
  for (std::size_t k = 0; k < reference.size(); ++k) {
    data << reference[k][0] << ' ' << reference[k][1];
    for (const TopViewSeries& e : series) data << ' ' << e.poses[k][0] << ' ' << e.poses[k][1];
    data << '\n';
  }
  std::ostringstream gp;
  gp << "# Redraw: cd into this directory, then: gnuplot " << name << ".gp\n"
     << "set terminal pngcairo size 900,900 noenhanced font 'sans,11'\nset output '" << name << ".png'\n"
     << "set title '" << title << "'\nset xlabel 'x [m]'\nset ylabel 'y [m]'\nset size ratio -1\nset grid\n"
     << "set key outside below\n"
     << "plot '" << name << ".dat' using 1:2 with lines lw 3 lc rgb 'black' title '" << reference_label << "'";
  // Distinct colours, none black (the reference).
  static const char* kColors[] = {"#d62728", "#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd",
                                  "#8c564b", "#e377c2", "#17becf", "#bcbd22", "#7f7f7f"};
  for (std::size_t i = 0; i < series.size(); ++i) {
    gp << ", \\\n     '' using " << 3 + 2 * i << ":" << 4 + 2 * i << " with lines lw 1.5 lc rgb '" << kColors[i % 10]
       << "' title '" << series[i].label << "'";
  }
  gp << "\n";
  for (const auto& [file, text] : {std::pair{name + ".dat", data.str()}, std::pair{name + ".gp", gp.str()}}) {
    if (Status s = WriteFileAtomic((fs::path(dir) / file).string(), text); !s.ok()) return s;
  }
  return RunGnuplot(dir, name + ".gp");
}

}  // namespace roamlab::eval
