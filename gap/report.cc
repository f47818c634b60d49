#include "gap/report.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "common/atomic_file.h"
#include "common/html.h"
#include "common/json.h"
#include "eval/plots.h"
#include "gap/internal/report_twin.h"

namespace roamlab::gap {
namespace {

using nlohmann::json;

json FitsJson(const std::map<std::string, StreamFit>& fits) {
  json j = json::object();
  for (const auto& [name, f] : fits)
    j[name] = {{"rms", Number(f.rms)},
               {"rms_1s", Number(f.rms_1s)},
               {"chi2_per_dof", Number(f.chi2_per_dof)},
               {"dof", f.dof},
               {"measurements", f.measurements}};
  return j;
}

json EffectJson(const EffectEstimate& e) {
  json p = json::object(), s = json::object(), b = json::object();
  for (const auto& [k, v] : e.parameters) p[k] = Number(v);
  for (const auto& [k, v] : e.baseline_parameters) b[k] = Number(v);
  for (const auto& [k, v] : e.std) s[k] = Number(v);
  return {{"name", e.name},
          {"parameters", p},
          {"std", s},
          {"baseline_parameters", b},
          {"dof", e.dof},
          {"lr_statistic", Number(e.lr)},
          {"chi2_drop", Number(e.lr_raw)},
          {"baseline_lr_statistic", Number(e.baseline_lr)},
          {"lr_pvalue", Number(e.lr_pvalue)},
          {"delta_bic", Number(e.delta_bic)},
          {"heldout_improvement", e.evaluated_heldout ? Number(e.heldout_improvement) : json(nullptr)},
          {"heldout_excess_before", e.evaluated_heldout ? Number(e.heldout_excess_before) : json(nullptr)},
          {"heldout_excess_after", e.evaluated_heldout ? Number(e.heldout_excess_after) : json(nullptr)},
          {"explained_share", e.evaluated_heldout ? Number(e.explained_share) : json(nullptr)},
          {"decision", e.decision}};
}

json LocatedJson(const LocatedComponent& lc) {
  json intervals = json::array(), correlates = json::array();
  for (const auto& [a, b] : lc.intervals) intervals.push_back({a, b});
  for (const Correlate& c : lc.correlates)
    correlates.push_back({{"condition", c.condition}, {"rho", Number(c.rho)}, {"lag_s", c.lag_s}});
  return {{"stream", lc.stream},
          {"component", lc.component},
          {"chi2_per_dof", Number(lc.chi2_per_dof)},
          {"expected_chi2_per_dof", Number(lc.expected_chi2_per_dof)},
          {"inconsistent", lc.inconsistent},
          {"intervals", intervals},
          {"correlates", correlates}};
}

std::string Fixed(double x, int digits) {
  std::ostringstream s;
  s << std::setprecision(digits) << x;
  return s.str();
}

// The located component most out of its level (inconsistent ones first), or null.
const LocatedComponent* Worst(const Diagnosis& d) {
  const LocatedComponent* worst = nullptr;
  for (const LocatedComponent& lc : d.located) {
    const double ratio = lc.chi2_per_dof / lc.expected_chi2_per_dof;
    if (!worst || (lc.inconsistent && !worst->inconsistent) ||
        (lc.inconsistent == worst->inconsistent && ratio > worst->chi2_per_dof / worst->expected_chi2_per_dof))
      worst = &lc;
  }
  return worst;
}

// Figures: the worst component's residuals against the condition it correlates with most (at its lag), and the
// held-out chi2/dof per stream before and after.
std::vector<std::string> WritePlots(const Diagnosis& d, const std::string& dir, std::string* note) {
  std::vector<std::string> images;
  if (!eval::GnuplotAvailable()) {
    *note = "gnuplot is not installed: no figures";
    return images;
  }
  if (const LocatedComponent* lc = Worst(d); lc && !lc->correlates.empty()) {
    const Correlate& c = lc->correlates.front();
    const auto column = std::find(d.conditions.names.begin(), d.conditions.names.end(), c.condition);
    const int ci = static_cast<int>(column - d.conditions.names.begin());
    std::ostringstream data;
    data << "# " << c.condition << " (at t + " << c.lag_s << " s)  whitened residual of " << lc->stream << "["
         << lc->component << "]\n";
    for (const estimator::MeasurementResidual& r : d.residuals) {
      if (!r.active || r.stream != lc->stream || lc->component >= r.whitened.size()) continue;
      const Time t = Time::FromNanoseconds(r.t.nanoseconds() + std::llround(c.lag_s * 1e9));
      data << d.conditions.At(ci, t) << " " << r.whitened[lc->component] << "\n";
    }
    std::ostringstream gp;
    gp << "set terminal pngcairo size 800,500 noenhanced\nset output 'residual_vs_condition.png'\n"
       << "set title \"" << lc->stream << "[" << lc->component << "]: chi2/dof " << Fixed(lc->chi2_per_dof, 3)
       << " (nominal " << Fixed(lc->expected_chi2_per_dof, 3) << "), rho " << Fixed(c.rho, 2) << "\"\n"
       << "set xlabel '" << c.condition << " at t + " << c.lag_s << " s'\nset ylabel 'whitened residual'\n"
       << "set grid\nplot 'residual_vs_condition.dat' using 1:2 with dots lc rgb '#1f77b4' notitle\n";
    if (WriteFileAtomic(dir + "/residual_vs_condition.dat", data.str()).ok() &&
        WriteFileAtomic(dir + "/residual_vs_condition.gp", gp.str()).ok() &&
        eval::RunGnuplot(dir, "residual_vs_condition.gp").ok())
      images.push_back("residual_vs_condition.png");
  }
  {
    std::ostringstream data;
    data << "# stream  chi2_per_dof_before  chi2_per_dof_after (held-out part)\n";
    for (const auto& [name, before] : d.before) {
      const auto after = d.after.find(name);
      data << name << " " << before.chi2_per_dof << " "
           << (after != d.after.end() ? after->second.chi2_per_dof : before.chi2_per_dof) << "\n";
    }
    std::ostringstream gp;
    gp << "set terminal pngcairo size 800,450 noenhanced\nset output 'heldout_fit.png'\n"
       << "set title 'held-out part (after t = " << Fixed(d.train_end_s, 4) << " s): chi2/dof per stream'\n"
       << "set style data histograms\nset style fill solid 0.8\nset yrange [0:*]\nset grid y\nset ylabel 'chi2/dof'\n"
       << "plot 'heldout_fit.dat' using 2:xtic(1) title 'nominal', '' using 3 title 'with the accepted effects'\n";
    if (WriteFileAtomic(dir + "/heldout_fit.dat", data.str()).ok() &&
        WriteFileAtomic(dir + "/heldout_fit.gp", gp.str()).ok() && eval::RunGnuplot(dir, "heldout_fit.gp").ok())
      images.push_back("heldout_fit.png");
  }
  return images;
}

json SimulationJson(const SimulationComparison& c, const recording::Recording* real) {
  const auto fits = [](const std::map<std::string, SimulatedStreamFit>& m) {
    json j = json::object();
    for (const auto& [name, f] : m)
      j[name] = {{"rms", Number(f.rms)},
                 {"rms_1s", Number(f.rms_1s)},
                 {"component_rms", f.component_rms},
                 {"samples", f.samples}};
    return j;
  };
  json effects = json::array();
  for (const sim::EffectOptions& e : c.effects) effects.push_back({{"name", e.name}, {"parameters", e.parameters}});
  return {{"replayed", c.twin.replayed},
          {"twin",
           {{"reason", c.twin.reason},
            {"stream", c.twin.stream.empty() ? json(nullptr) : json(c.twin.stream)},
            {"drive_mismatch", c.twin.mismatch ? Number(*c.twin.mismatch) : json(nullptr)},
            {"max_drive_mismatch", kMaxDriveMismatch}}},
          {"from_s", c.from_s},
          {"duration_s", c.duration_s},
          {"effects", effects},
          {"before", fits(c.before)},
          {"after", fits(c.after)},
          {"drift", real ? internal::HeldOutDriftJson(internal::TwinHeldOutDrift(c, *real)) : json(nullptr)},
          {"left_out", c.left_out},
          {"not_simulated", c.not_simulated.empty() ? json(nullptr) : json(c.not_simulated)}};
}

// A table in Markdown (cells as they are: the tables hold no '|').
std::string MarkdownTable(const html::Table& table) {
  std::string out = "|";
  for (const std::string& h : table.header) out += " " + h + " |";
  out += "\n|";
  for (std::size_t i = 0; i < table.header.size(); ++i) out += "---|";
  out += "\n";
  for (const std::vector<std::string>& row : table.rows) {
    out += "|";
    for (const std::string& cell : row) out += " " + cell + " |";
    out += "\n";
  }
  return out;
}

// The re-simulation (gap/resimulate.h) against the recording's held-out part.
const char kSimulationText[] =
    "The scenario's twin of the recording run again without noise, as believed and with the accepted effects applied "
    "(scenario_patch.yaml: with --twin the twin diagnosis's patch), compared sample by sample with the "
    "recording: RMS of recorded minus twin in units of each stream's stated noise (1 = noise only), and of its 1 s "
    "means (the systematic part); then the drift of its absolute streams over 10 s windows, each window's twin aligned "
    "to the recording at its start.";

// What a replayed twin's sample-by-sample figures measure.
const char kReplayedText[] =
    "The replay is dead-reckoned from the recording's start: its RMS over the held-out part carries the error it "
    "accumulated before, which a small heading error grows, and its wheel encoders follow the recorded angles that "
    "drive it. The 10 s drift is what the twin's fit compares (twin.json).";

html::Table SimulationTable(const SimulationComparison& c) {
  html::Table t{{"stream", "RMS as believed", "RMS with the effects", "change", "1 s RMS as believed",
                 "1 s RMS with the effects"},
                {}};
  for (const auto& [name, b] : c.before) {
    const auto a = c.after.find(name);
    if (a == c.after.end()) {
      t.rows.push_back({name, Fixed(b.rms, 4), "-", "-", Fixed(b.rms_1s, 4), "-"});
      continue;
    }
    t.rows.push_back({name, Fixed(b.rms, 4), Fixed(a->second.rms, 4),
                      b.rms > 0.0 ? Fixed(100.0 * (a->second.rms / b.rms - 1.0), 3) + " %" : std::string("-"),
                      Fixed(b.rms_1s, 4), Fixed(a->second.rms_1s, 4)});
  }
  return t;
}

// The notes under the simulation table.
std::vector<std::string> SimulationNotes(const SimulationComparison& c) {
  std::vector<std::string> notes;
  for (const std::string& l : c.left_out) notes.push_back("Not compared: " + l + ".");
  if (!c.not_simulated.empty()) notes.push_back("The effects could not be simulated: " + c.not_simulated + ".");
  return notes;
}

// The verdict's lines: each accepted effect, or what stays unexplained, or that every stream is consistent.
std::vector<std::string> VerdictLines(const Diagnosis& d, bool baseline) {
  std::vector<std::string> lines;
  if (d.verdict == "named") {
    for (const EffectEstimate& e : d.effects) {
      std::string line = e.name + ":";
      for (const auto& [k, v] : e.parameters) {
        const auto s = e.std.find(k);
        line += " " + k + " = " + Fixed(v, 4);
        if (s != e.std.end() && std::isfinite(s->second)) line += " +- " + Fixed(s->second, 2);
      }
      line += " (likelihood ratio " + Fixed(e.lr, 4) + ", p = " + Fixed(e.lr_pvalue, 3) + ", Delta BIC " +
              Fixed(e.delta_bic, 4) + ", held-out chi2 " + Fixed(100.0 * e.heldout_improvement, 3) + " % lower)";
      lines.push_back(line);
    }
  } else if (d.verdict == "unknown") {
    lines.push_back("No effect of the library explains it; what stays inconsistent:");
    for (const std::string& u : d.unexplained) lines.push_back(u);
  } else {
    lines.push_back(std::string("Every stream is as consistent as the nominal model is on a nominal simulation") +
                    (baseline ? "" : " (no baseline: levels compared with 1)") + ".");
  }
  return lines;
}

html::Table LocatedTable(const std::vector<LocatedComponent>& located) {
  html::Table t{{"stream[component]", "chi2/dof", "nominal level", "inconsistent", "intervals [s]",
                 "strongest condition (rho, lag)"},
                {}};
  for (const LocatedComponent& lc : located) {
    std::string intervals;
    for (std::size_t i = 0; i < lc.intervals.size() && i < 3; ++i)
      intervals += (i ? ", " : "") + Fixed(lc.intervals[i].first, 3) + "-" + Fixed(lc.intervals[i].second, 3);
    if (lc.intervals.size() > 3) intervals += " (+" + std::to_string(lc.intervals.size() - 3) + ")";
    std::string condition;
    if (!lc.correlates.empty())
      condition = lc.correlates.front().condition + " (" + Fixed(lc.correlates.front().rho, 2) + ", " +
                  Fixed(lc.correlates.front().lag_s, 6) + " s)";
    t.rows.push_back({lc.stream + "[" + std::to_string(lc.component) + "]", Fixed(lc.chi2_per_dof, 3),
                      Fixed(lc.expected_chi2_per_dof, 3), lc.inconsistent ? "yes" : "no", intervals, condition});
  }
  return t;
}

html::Table CandidatesTable(const Diagnosis& d) {
  html::Table t{{"effect", "parameters", "LR", "chi2 drop / on baseline", "p", "Delta BIC", "held-out",
                 "share of the held-out mismatch", "decision"},
                {}};
  for (const EffectEstimate& e : d.candidates) {
    std::string parameters;
    for (const auto& [k, v] : e.parameters) parameters += k + " = " + Fixed(v, 4) + " ";
    t.rows.push_back({e.name, parameters, Fixed(e.lr, 4), Fixed(e.lr_raw, 4) + " / " + Fixed(e.baseline_lr, 4),
                      Fixed(e.lr_pvalue, 3), Fixed(e.delta_bic, 4),
                      e.evaluated_heldout ? Fixed(100.0 * e.heldout_improvement, 3) + " %" : std::string("-"),
                      e.evaluated_heldout ? Fixed(e.explained_share, 3) : std::string("-"), e.decision});
  }
  return t;
}

html::Table HeldoutTable(const Diagnosis& d) {
  html::Table t{
      {"stream", "RMS before", "RMS after", "1 s RMS before", "1 s RMS after", "chi2/dof before", "chi2/dof after"},
      {}};
  for (const auto& [name, b] : d.before) {
    const auto a = d.after.count(name) ? d.after.at(name) : b;
    t.rows.push_back({name, Fixed(b.rms, 4), Fixed(a.rms, 4), Fixed(b.rms_1s, 4), Fixed(a.rms_1s, 4),
                      Fixed(b.chi2_per_dof, 4), Fixed(a.chi2_per_dof, 4)});
  }
  return t;
}

const char kHeldoutText[] =
    "Whitened residuals: RMS per sample, RMS of their 1 s means (the systematic part) and chi2/dof.";

// A section of the report: its title, paragraphs, tables, notes and figures (file names in the output directory).
struct Section {
  std::string title;
  std::vector<std::string> lines;  // paragraphs before the tables
  std::vector<html::Table> tables;
  std::vector<std::string> notes;
  std::vector<std::string> images;
};

// The twin against the recording: which twin and why, the held-out RMS and drift before and after.
Section TwinSection(const ReportInputs& in, const ReportFigures& figures) {
  const SimulationComparison& c = *in.simulation;
  Section out;
  out.title = "The twin against the recording (held-out part, after t = " + Fixed(c.from_s, 4) + " s)";
  out.lines = {internal::TwinChoiceText(c.twin), kSimulationText};
  if (c.twin.replayed) out.lines.push_back(kReplayedText);
  out.tables.push_back(SimulationTable(c));
  if (in.real) {
    const internal::HeldOutDrift drift = internal::TwinHeldOutDrift(c, *in.real);
    if (!drift.before.empty()) out.tables.push_back(internal::DriftTable(drift));
  }
  out.notes = SimulationNotes(c);
  out.images = figures.twin_images;
  return out;
}

// The twin diagnosis (its verdict is the report's first): where the nominal twin departs, its candidates round by
// round, its fit of the held-out part before and after the patch, and its held-out runs.
Section TwinDiagnosisSection(const TwinDiagnosis& twin) {
  Section out{"The twin diagnosis",
              {"Where the nominal twin departs from the recording (whole run, whitened by the stated noise); its "
               "candidates round by round, each fitted on the training part (up to t = " +
               Fixed(twin.train_end_s, 4) +
               " s) by running the twin; the held-out part per stream with the nominal twin and with the patch; "
               "the patch on the held-out runs. In full: twin.json."},
              {LocatedTable(twin.located), internal::TwinCandidatesTable(twin), internal::TwinHeldOutTable(twin)},
              {},
              {}};
  if (!twin.heldout_runs.empty()) out.tables.push_back(internal::HeldOutRunsTable(twin));
  return out;
}

// The sections after the verdicts. With a twin diagnosis its sections come first, its values being the accepted
// ones, and the estimator side's follow, titled so; otherwise the estimator side's, then the re-simulation.
std::vector<Section> Sections(const Diagnosis& d, const ReportInputs& in, const ReportFigures& figures) {
  const auto title = [&](const std::string& estimator) {
    return in.twin ? "Estimator side: " + std::string(1, static_cast<char>(std::tolower(estimator[0]))) +
                         estimator.substr(1)
                   : estimator;
  };
  std::vector<Section> out = {
      {title("Fit on the held-out part (after t = " + Fixed(d.train_end_s, 4) + " s), before and after"),
       {kHeldoutText},
       {HeldoutTable(d)},
       {},
       {}},
      {title("Candidates (fitted on the first part)"), {}, {CandidatesTable(d)}, {}, {}},
      {title("Where (whole run, nominal self-calibration)"), {}, {LocatedTable(d.located)}, {}, {}}};
  std::vector<Section> twin;
  if (in.twin) twin.push_back(TwinDiagnosisSection(*in.twin));
  if (in.simulation) twin.push_back(TwinSection(in, figures));
  out.insert(in.twin ? out.begin() : out.end(), twin.begin(), twin.end());
  Section plots{"Figures", {}, {}, {}, figures.images};
  if (figures.images.empty() && figures.twin_images.empty())
    plots.notes = {figures.notes.empty() ? "No figures were drawn." : figures.notes.front()};
  out.push_back(plots);
  return out;
}

// The verdicts, first the one whose values are accepted: with a twin diagnosis the twin's, then the estimator-side
// diagnosis's (its first guess).
struct Verdict {
  std::string title, verdict;
  std::vector<std::string> lines;
  std::size_t plain = 0;  // the lines before the items
};
std::vector<Verdict> Verdicts(const Diagnosis& d, const ReportInputs& in) {
  Verdict estimator{in.twin ? "Estimator-side verdict (the first guess; estimator_patch.yaml)" : "Verdict", d.verdict,
                    VerdictLines(d, in.baseline != nullptr), d.verdict == "named" ? 0u : 1u};
  if (!in.twin) return {estimator};
  std::vector<std::string> lines = internal::TwinVerdictLines(*in.twin);
  lines.push_back("Its patch: scenario_patch.yaml.");
  return {{"Verdict against the twin", in.twin->verdict, lines, 1}, estimator};
}

// report.html: the verdicts first, the sections, their figures embedded.
Status WriteReportHtml(const Diagnosis& d, const ReportInputs& in, const ReportFigures& figures,
                       const std::string& dir) {
  html::Page page("Reality-gap diagnosis");
  for (const Verdict& v : Verdicts(d, in)) {
    page.Paragraph(v.title + ": " + v.verdict, v.verdict == "none" ? "verdict-pass" : "verdict-fail");
    for (const std::string& line : v.lines) page.Paragraph(line, "headline");
  }
  page.Paragraph("Recording " + in.recording + " against the nominal scenario " + in.model + "; " +
                 std::to_string(d.fits) + " calibrations in " + Fixed(d.seconds, 3) + " s.");
  for (const Section& section : Sections(d, in, figures)) {
    page.Heading(2, section.title);
    for (const std::string& line : section.lines) page.Paragraph(line);
    for (const html::Table& table : section.tables) page.AddTable(table);
    for (const std::string& line : section.notes) page.Paragraph(line, "note");
    for (const std::string& image : section.images)
      if (Status s = page.AddImage(dir + "/" + image, image); !s.ok()) return s;
  }
  return page.Write(dir + "/report.html");
}

}  // namespace

std::string ReportMarkdown(const Diagnosis& d, const ReportInputs& in, const ReportFigures& figures) {
  std::ostringstream r;
  r << "# Reality-gap diagnosis\n\nRecording `" << in.recording << "` against the nominal scenario `" << in.model
    << "`.\n";
  for (const Verdict& v : Verdicts(d, in)) {
    r << "\n## " << v.title << ": **" << v.verdict << "**\n\n";
    for (std::size_t i = 0; i < v.lines.size(); ++i) r << (i >= v.plain ? "- " : "") << v.lines[i] << "\n";
  }
  for (const Section& section : Sections(d, in, figures)) {
    r << "\n## " << section.title << "\n\n";
    for (const std::string& line : section.lines) r << line << "\n\n";
    for (const html::Table& table : section.tables) r << MarkdownTable(table) << "\n";
    for (const std::string& note : section.notes) r << note << "\n\n";
    for (const std::string& image : section.images) r << "![" << image << "](" << image << ")\n\n";
  }
  r << d.fits << " calibrations in " << Fixed(d.seconds, 3) << " s.\n";
  return r.str();
}

namespace {

// The twin diagnosis's patch: each kept effect's parts as the simulator applies them, with the std of the kept
// effect's parameter of the same name.
std::string TwinScenarioPatch(const TwinDiagnosis& twin) {
  std::ostringstream y;
  y << "# Accepted effects of `roamlab diagnose --twin` (twin.json \"patch\"), in the form of a scenario's `effects:`\n"
    << "# section (sim/scenario.h). Standard deviations (" << twin.std_method << ") are comments.\neffects:\n";
  if (twin.patch.empty()) y << "  []\n";
  for (const TwinEffect& e : twin.effects)
    for (const sim::EffectOptions& part : e.applied) {
      y << "  - name: " << part.name << "\n    parameters:" << (part.parameters.empty() ? " {}" : "") << "\n";
      for (const auto& [k, v] : part.parameters) {
        y << "      " << k << ": " << std::setprecision(10) << v;
        const auto s = e.estimate.std.find(k);
        if (s != e.estimate.std.end() && std::isfinite(s->second))
          y << "   # +- " << std::setprecision(3) << s->second;
        else if (std::find(e.not_informed.begin(), e.not_informed.end(), k) != e.not_informed.end())
          y << "   # not informed, held";
        y << "\n";
      }
    }
  return y.str();
}

}  // namespace

std::string ScenarioPatch(const Diagnosis& d, const SimulationComparison* simulation, const TwinDiagnosis* twin) {
  if (twin) return TwinScenarioPatch(*twin);
  std::ostringstream y;
  y << "# Accepted effects of `roamlab diagnose`, in the form of a scenario's `effects:` section (sim/scenario.h).\n"
    << "# Standard deviations are comments.\neffects:\n";
  if (d.effects.empty()) y << "  []\n";
  for (std::size_t i = 0; i < d.effects.size(); ++i) {
    const EffectEstimate& e = d.effects[i];
    std::map<std::string, double> std;
    sim::EffectOptions effect = SimulatorEffect(e, &std);
    // As simulated when the re-simulation applied these effects (not the twin diagnosis's patch).
    if (simulation && simulation->effects.size() == d.effects.size() && simulation->effects[i].name == effect.name)
      effect = simulation->effects[i];
    y << "  - name: " << e.name << "\n";
    bool same = effect.parameters.size() == e.parameters.size();
    for (const auto& [k, v] : effect.parameters) same = same && e.parameters.count(k);
    if (!same) {  // parameters the simulator takes in another form (lateral_slip): the diagnosed ones as comments
      y << "    # diagnosed:";
      for (const auto& [k, v] : e.parameters) y << " " << k << " = " << std::setprecision(6) << v;
      y << "\n";
    }
    y << "    parameters:\n";
    for (const auto& [k, v] : effect.parameters) {
      y << "      " << k << ": " << std::setprecision(10) << v;
      if (std.count(k) && std::isfinite(std.at(k))) y << "   # +- " << std::setprecision(3) << std.at(k);
      y << "\n";
    }
  }
  return y.str();
}

std::string EstimatorPatch(const Diagnosis& d) {
  std::ostringstream y;
  y << "# The accepted effects as estimator settings: parameter values to add to the nominal configuration's\n"
    << "# `parameters`, and time shifts [s] to subtract from the named recording streams' stamps.\nparameters:\n";
  if (d.effect_parameters.empty()) y << "  {}\n";
  for (const auto& [name, v] : d.effect_parameters) {
    y << "  " << name << ": {value: [";
    for (int i = 0; i < v.size(); ++i) y << (i ? ", " : "") << std::setprecision(10) << v[i];
    y << "], free: false}\n";
  }
  y << "stream_time_shifts_s:\n";
  if (d.stream_shifts_s.empty()) y << "  {}\n";
  for (const auto& [name, s] : d.stream_shifts_s) y << "  " << name << ": " << std::setprecision(10) << s << "\n";
  return y.str();
}

json DiagnosisJson(const Diagnosis& d, const Baseline* baseline, std::uint64_t baseline_seed,
                   const SimulationComparison* simulation, const recording::Recording* real) {
  json located = json::array(), components = json::array(), effects = json::array(), candidates = json::array();
  for (const LocatedComponent& lc : d.located) {
    components.push_back(LocatedJson(lc));
    if (lc.inconsistent) located.push_back(LocatedJson(lc));
  }
  for (const EffectEstimate& e : d.effects) effects.push_back(EffectJson(e));
  for (const EffectEstimate& e : d.candidates) candidates.push_back(EffectJson(e));
  json base = json::object();
  if (baseline) {
    base["seed"] = baseline_seed;
    base["streams"] = FitsJson(baseline->streams);
    json lr = json::object();
    for (const auto& [name, v] : baseline->candidate_lr) lr[name] = Number(v);
    base["candidate_lr_statistic"] = lr;
  }
  return {{"verdict", d.verdict},
          {"located", located},
          {"effects", effects},
          {"fit",
           {{"before", FitsJson(d.before)},
            {"after", FitsJson(d.after)},
            {"heldout_start_s", d.train_end_s},
            {"whole_run_nominal", FitsJson(d.whole_run)}}},
          {"unexplained", d.unexplained},
          {"candidates", candidates},
          {"components", components},
          {"baseline", base},
          {"simulation", simulation ? SimulationJson(*simulation, real) : json(nullptr)},
          {"std_method", d.std_method},
          {"run", {{"fits", d.fits}, {"seconds", d.seconds}}}};
}

Status WriteReport(const Diagnosis& d, const ReportInputs& in, const std::string& dir) {
  json gap_json = DiagnosisJson(d, in.baseline, in.baseline_seed, in.simulation, in.real);
  if (in.simulation) gap_json["simulation"]["twin_diagnosis"] = in.twin ? json("twin.json") : json(nullptr);
  if (Status s = WriteFileAtomic(dir + "/gap.json", gap_json.dump(2) + "\n"); !s.ok()) return s;
  if (Status s = WriteFileAtomic(dir + "/scenario_patch.yaml", ScenarioPatch(d, in.simulation, in.twin)); !s.ok())
    return s;
  if (Status s = WriteFileAtomic(dir + "/estimator_patch.yaml", EstimatorPatch(d)); !s.ok()) return s;
  ReportFigures figures;
  if (in.plots) {
    std::string note;
    figures.images = WritePlots(d, dir, &note);
    if (!note.empty()) figures.notes.push_back(note);
    if (in.simulation && in.real && eval::GnuplotAvailable())
      figures.twin_images = internal::WriteTwinFigures(*in.simulation, *in.real, d.conditions, dir, &figures.notes);
  }
  if (in.progress)
    for (const std::string& note : figures.notes) in.progress(note);
  if (Status s = WriteFileAtomic(dir + "/report.md", ReportMarkdown(d, in, figures)); !s.ok()) return s;
  return WriteReportHtml(d, in, figures, dir);
}

}  // namespace roamlab::gap
