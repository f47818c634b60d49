#include "gap/internal/report_twin.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iomanip>
#include <limits>
#include <optional>
#include <sstream>

#include "common/atomic_file.h"
#include "common/json.h"
#include "estimator/models/enu.h"
#include "eval/plots.h"
#include "eval/top_view.h"
#include "gap/internal/twin_residuals.h"

namespace roamlab::gap::internal {
namespace {

using recording::Stream;
using recording::StreamType;

std::string Fixed(double x, int digits) {
  std::ostringstream s;
  s << std::setprecision(digits) << x;
  return s.str();
}

Time LastStamp(const recording::Recording& r) {
  Time last = Time::FromNanoseconds(std::numeric_limits<std::int64_t>::min());
  for (const Stream& s : r.streams)
    if (!s.t.empty()) last = std::max(last, s.t.back());
  return last;
}

// The first absolute stream of `real` whose positions can be drawn: a pose stream, else gps (with an origin), else a
// position stream.
const Stream* AbsoluteStream(const recording::Recording& real) {
  for (const StreamType type : {StreamType::kPose, StreamType::kGps, StreamType::kPosition})
    for (const Stream& s : real.streams)
      if (s.info.type == type && s.values.cols() >= 3 && !s.t.empty() && (type != StreamType::kGps || real.origin))
        return &s;
  return nullptr;
}

// The row of `s` stamped `t`, if any.
std::optional<Eigen::Index> RowAt(const Stream& s, Time t) {
  const auto it = std::lower_bound(s.t.begin(), s.t.end(), t);
  if (it == s.t.end() || *it != t) return std::nullopt;
  return static_cast<Eigen::Index>(it - s.t.begin());
}

// The top view's tracks: the real stream's positions and the twins' at its stamps from `from` on (all three there).
struct Tracks {
  std::vector<Eigen::Vector3d> real;
  std::vector<eval::TopViewSeries> twins;
};
Tracks HeldOutTracks(const Stream& r, const recording::Recording& real,
                     const std::vector<std::pair<std::string, const recording::Recording*>>& twins, Time from) {
  std::optional<estimator::EnuConverter> enu;
  if (r.info.type == StreamType::kGps) enu.emplace(*real.origin);
  const auto position = [&](const Stream& s, Eigen::Index row) {
    const Eigen::Vector3d v = s.values.row(row).head(3).transpose();
    const Eigen::Vector3d p = enu ? Eigen::Vector3d(enu->ToEnu(v[0], v[1], v[2])) : v;
    return Eigen::Vector3d(p.x(), p.y(), 0.0);  // x, y and the yaw the figure does not draw
  };
  Tracks out;
  std::vector<const Stream*> streams;
  for (const auto& [label, twin] : twins) {
    out.twins.push_back({label, {}});
    streams.push_back(twin->Find(r.info.name));
    if (!streams.back() || streams.back()->values.cols() < 3) return {};
  }
  for (std::size_t i = 0; i < r.t.size(); ++i) {
    if (r.t[i] < from) continue;
    std::vector<Eigen::Index> rows;
    for (const Stream* s : streams)
      if (const auto row = RowAt(*s, r.t[i])) rows.push_back(*row);
    if (rows.size() != streams.size()) continue;
    out.real.push_back(position(r, static_cast<Eigen::Index>(i)));
    for (std::size_t k = 0; k < streams.size(); ++k) out.twins[k].poses.push_back(position(*streams[k], rows[k]));
  }
  return out;
}

// The component of the held-out whitened residuals `w` (of `layout`) with the largest RMS: its series and component.
std::optional<std::pair<const Series*, int>> WorstComponent(const Layout& layout, const Eigen::VectorXd& w) {
  std::optional<std::pair<const Series*, int>> worst;
  double worst_rms = 0.0;
  for (const Series& s : layout.series) {
    const int n = s.components();
    for (int k = 0; k < n; ++k) {
      double sum = 0.0;
      int count = 0;
      for (std::size_t i = 0; i < s.rows.size(); ++i) {
        const double x = w[s.offset + static_cast<Eigen::Index>(i) * n + k];
        if (!std::isfinite(x)) continue;
        sum += x * x;
        ++count;
      }
      if (count < 10 || !(std::sqrt(sum / count) > worst_rms)) continue;
      worst_rms = std::sqrt(sum / count);
      worst = std::make_pair(&s, k);
    }
  }
  return worst;
}

std::string ResidualVsCondition(const SimulationComparison& c, const recording::Recording& real,
                                const Conditions& conditions, const std::string& dir, std::string* note) {
  const Layout layout = MakeLayout(real, Time::FromSeconds(c.from_s), LastStamp(real));
  const Eigen::VectorXd before = WhitenedResiduals(layout, real, c.twin_before);
  const auto worst = WorstComponent(layout, before);
  if (!worst) {
    *note = "no held-out residuals of the twin to draw against a condition";
    return "";
  }
  const Series* series = worst->first;
  const int component = worst->second;
  std::vector<estimator::MeasurementResidual> residuals;
  for (const estimator::MeasurementResidual& r : MeasurementResiduals(layout, before))
    if (r.stream == series->name) residuals.push_back(r);
  const std::vector<LocatedComponent> located = Locate(residuals, conditions, {});
  const auto it = std::find_if(located.begin(), located.end(), [&](const LocatedComponent& l) {
    return l.component == component && !l.correlates.empty();
  });
  if (it == located.end()) {
    *note = "no motion condition to draw the twin's residual of " + series->name + " against";
    return "";
  }
  const Correlate& k = it->correlates.front();
  const int ci = static_cast<int>(std::find(conditions.names.begin(), conditions.names.end(), k.condition) -
                                  conditions.names.begin());
  const bool patched = c.not_simulated.empty() && !c.twin_after.streams.empty();
  const Eigen::VectorXd after = patched ? WhitenedResiduals(layout, real, c.twin_after) : Eigen::VectorXd();
  std::ostringstream data;
  const int n = series->components();
  const std::string name = series->name + "[" + std::to_string(component) + "]";
  for (const auto& [label, w] : {std::pair{"as believed", &before}, std::pair{"with the effects", &after}}) {
    if (w->size() == 0) continue;
    data << "# " << k.condition << " (at t + " << k.lag_s << " s)  whitened residual of " << name << ", twin " << label
         << "\n";
    for (std::size_t i = 0; i < series->rows.size(); ++i) {
      const double x = (*w)[series->offset + static_cast<Eigen::Index>(i) * n + component];
      const Time t = Time::FromNanoseconds(series->t[i].nanoseconds() + std::llround(k.lag_s * 1e9));
      if (std::isfinite(x)) data << conditions.At(ci, t) << " " << x << "\n";
    }
    data << "\n\n";
  }
  std::ostringstream gp;
  gp << "set terminal pngcairo size 800,500 noenhanced\nset output 'twin_residual_vs_condition.png'\n"
     << "set title \"the twin's held-out residual of " << name << " against " << k.condition << " (rho "
     << Fixed(k.rho, 2) << ")\"\n"
     << "set xlabel '" << k.condition << " at t + " << k.lag_s << " s'\nset ylabel 'whitened residual'\n"
     << "set grid\nset key outside below\n"
     << "plot 'twin_residual_vs_condition.dat' index 0 using 1:2 with points pt 7 ps 0.3 lc rgb '#d62728' "
     << "title 'as believed'";
  if (patched) gp << ", '' index 1 using 1:2 with points pt 7 ps 0.3 lc rgb '#1f77b4' title 'with the effects'";
  gp << "\n";
  if (!WriteFileAtomic(dir + "/twin_residual_vs_condition.dat", data.str()).ok() ||
      !WriteFileAtomic(dir + "/twin_residual_vs_condition.gp", gp.str()).ok() ||
      !eval::RunGnuplot(dir, "twin_residual_vs_condition.gp").ok()) {
    *note = "the twin's residual figure could not be drawn";
    return "";
  }
  return "twin_residual_vs_condition.png";
}

// "name: parameter = value +- std ..." of a fitted effect.
// Its parameters as " name = value +- std" each.
std::string ParametersText(const TwinEffect& e) {
  std::string line;
  for (const auto& [k, v] : e.estimate.parameters) {
    line += " " + k + " = " + Fixed(v, 5);
    if (const auto s = e.estimate.std.find(k); s != e.estimate.std.end()) line += " +- " + Fixed(s->second, 2);
    if (std::find(e.not_informed.begin(), e.not_informed.end(), k) != e.not_informed.end())
      line += " (not informed, held)";
  }
  return line;
}

std::string EffectLine(const TwinEffect& e) { return e.estimate.name + ":" + ParametersText(e); }

}  // namespace

HeldOutDrift TwinHeldOutDrift(const SimulationComparison& c, const recording::Recording& real) {
  HeldOutDrift out;
  const double to_s = LastStamp(real).seconds();
  out.before = CompareTwin(real, c.twin_before, c.from_s, to_s).drift;
  if (c.not_simulated.empty() && !c.twin_after.streams.empty())
    out.after = CompareTwin(real, c.twin_after, c.from_s, to_s).drift;
  return out;
}

nlohmann::json HeldOutDriftJson(const HeldOutDrift& drift) {
  const nlohmann::json before = TwinDriftJson(drift.before), after = TwinDriftJson(drift.after);
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [name, b] : before.items())
    out[name] = {{"before", b}, {"after", after.contains(name) ? after.at(name) : nlohmann::json()}};
  return out;
}

std::string TwinChoiceText(const TwinChoice& twin) {
  std::string text = twin.replayed ? "The twin replays the recorded drive" : "The twin is the scenario's own drive";
  text += " (" + twin.reason;
  if (twin.mismatch)
    text += ": the wheel motion of " + twin.stream + " differs from the scenario's own drive by " +
            Fixed(100.0 * *twin.mismatch, 3) + " % of its size over " + Fixed(kDriveWindowS, 2) +
            " s windows; the threshold is " + Fixed(100.0 * kMaxDriveMismatch, 3) + " %";
  return text + ").";
}

html::Table DriftTable(const HeldOutDrift& drift) {
  html::Table t{{"stream", "window [s]", "windows", "mean position drift as believed [m]", "with the effects [m]",
                 "largest as believed [m]", "with the effects [m]", "mean heading drift as believed [rad]",
                 "with the effects [rad]"},
                {}};
  for (const auto& [name, b] : drift.before) {
    const auto a = drift.after.find(name);
    const bool patched = a != drift.after.end();
    t.rows.push_back({name, Fixed(b.window_s, 3), std::to_string(b.windows), Fixed(b.mean_position_m, 3),
                      patched ? Fixed(a->second.mean_position_m, 3) : "-", Fixed(b.max_position_m, 3),
                      patched ? Fixed(a->second.max_position_m, 3) : "-",
                      b.heading_measured ? Fixed(b.mean_heading_rad, 3) : "-",
                      patched && b.heading_measured ? Fixed(a->second.mean_heading_rad, 3) : "-"});
  }
  return t;
}

std::vector<std::string> TwinVerdictLines(const TwinDiagnosis& d) {
  std::vector<std::string> lines = {"The twin's verdict: " + d.verdict + " (std " + d.std_method + ", " +
                                    std::to_string(d.runs) + " twin runs in " + Fixed(d.seconds, 3) + " s)."};
  for (const TwinEffect& e : d.effects)
    lines.push_back(EffectLine(e) + " (training chi2 " + Fixed(e.chi2_before, 5) + " -> " + Fixed(e.chi2_after, 5) +
                    (e.refitted                ? "; refitted with the other kept effects: std marginal over them)"
                     : d.joint.effects.empty() ? ")"
                                               : "; std conditional on the effects kept before it)"));
  if (!d.joint.failed.empty()) lines.push_back("The kept effects' joint refit failed: " + d.joint.failed + ".");
  if (d.joint.effects.empty()) return lines;
  std::string held;
  for (const std::string& h : d.joint.held) held += (held.empty() ? "; held at their values: " : ", ") + h;
  lines.push_back("Refitted jointly (training chi2 " + Fixed(d.joint.chi2_before, 5) + " -> " +
                  Fixed(d.joint.chi2_after, 5) + held + "), each std marginal over the others:");
  for (const TwinEffect& e : d.joint.effects) lines.push_back("joint " + EffectLine(e));
  return lines;
}

html::Table TwinCandidatesTable(const TwinDiagnosis& d) {
  html::Table t{{"round", "effect", "parameters", "LR", "p", "Delta BIC", "held-out chi2 drop", "decision"}, {}};
  for (std::size_t round = 0; round < d.rounds.size(); ++round)
    for (const TwinEffect& e : d.rounds[round]) {
      const std::string parameters = ParametersText(e).substr(e.estimate.parameters.empty() ? 0 : 1);
      const EffectEstimate& x = e.estimate;
      t.rows.push_back(
          {std::to_string(round + 1), x.name, parameters, Fixed(x.lr, 4), Fixed(x.lr_pvalue, 3), Fixed(x.delta_bic, 4),
           x.evaluated_heldout ? Fixed(100.0 * x.heldout_improvement, 3) + " %" : std::string("-"), x.decision});
    }
  return t;
}

html::Table TwinHeldOutTable(const TwinDiagnosis& d) {
  html::Table t{
      {"stream", "RMS with the nominal twin", "with the patch", "1 s RMS with the nominal twin", "with the patch"}, {}};
  for (const auto& [name, b] : d.heldout_before.streams) {
    const auto a = d.heldout_after.streams.find(name);
    const bool patched = a != d.heldout_after.streams.end();
    t.rows.push_back({name, Fixed(b.rms, 4), patched ? Fixed(a->second.rms, 4) : "-", Fixed(b.rms_1s, 4),
                      patched ? Fixed(a->second.rms_1s, 4) : "-"});
  }
  return t;
}

html::Table HeldOutRunsTable(const TwinDiagnosis& d) {
  html::Table t{{"recording", "twin", "stream", "mean drift before [m]", "after [m]", "chi2 before", "chi2 after"}, {}};
  for (const TwinHeldOutRun& h : d.heldout_runs) {
    const std::string twin = h.replayed ? "replayed" : "own drive";
    if (h.before.drift.empty())
      t.rows.push_back({h.recording, twin, "-", "-", "-", Fixed(h.before.chi2, 5), Fixed(h.after.chi2, 5)});
    for (const auto& [name, b] : h.before.drift) {
      const auto a = h.after.drift.find(name);
      t.rows.push_back({h.recording, twin, name, Fixed(b.mean_position_m, 3),
                        a != h.after.drift.end() ? Fixed(a->second.mean_position_m, 3) : "-", Fixed(h.before.chi2, 5),
                        Fixed(h.after.chi2, 5)});
    }
  }
  return t;
}

std::vector<std::string> WriteTwinFigures(const SimulationComparison& c, const recording::Recording& real,
                                          const Conditions& conditions, const std::string& dir,
                                          std::vector<std::string>* notes) {
  std::vector<std::string> images;
  const Stream* absolute = AbsoluteStream(real);
  const bool patched = c.not_simulated.empty() && !c.twin_after.streams.empty();
  std::vector<std::pair<std::string, const recording::Recording*>> twins = {{"twin as believed", &c.twin_before}};
  if (patched) twins.push_back({"twin with the effects", &c.twin_after});
  const Tracks tracks = absolute ? HeldOutTracks(*absolute, real, twins, Time::FromSeconds(c.from_s)) : Tracks{};
  if (tracks.real.size() < 2) {
    notes->push_back("no absolute stream (motion capture, GPS, position) in the recording and its twin to draw");
  } else if (eval::WriteTopViewFigure(
                 dir, "twin_top_view",
                 "the twin against " + absolute->info.name + ", held-out part (after t = " + Fixed(c.from_s, 4) + " s)",
                 tracks.real, tracks.twins, "recorded " + absolute->info.name)
                 .ok()) {
    images.push_back("twin_top_view.png");
  } else {
    notes->push_back("the twin's top view could not be drawn");
  }
  std::string note;
  const std::string residual = ResidualVsCondition(c, real, conditions, dir, &note);
  if (!residual.empty()) images.push_back(residual);
  if (!note.empty()) notes->push_back(note);
  return images;
}

}  // namespace roamlab::gap::internal
