#include "experiment/sweep.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>
#include <nlohmann/json.hpp>

#include "common/atomic_file.h"
#include "common/html.h"
#include "common/json.h"
#include "common/yaml_keys.h"
#include "eval/plots.h"

namespace roamlab::experiment {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// The metrics of a point: sweep.json's and table.csv's columns, with their axis labels.
struct Metric {
  const char* key;
  const char* label;
};
constexpr Metric kMetrics[] = {{"fraction_in_band", "time steps with the mean NEES in its 95 % band"},
                               {"mean_nees", "mean NEES (3 when consistent)"},
                               {"ate_m", "ATE [m]"},
                               {"rpe_m", "RPE over 1 s [m]"},
                               {"track_seconds", "tracking time per run [s]"}};

// `node` read as T; false when it is not one.
template <typename T>
bool As(const YAML::Node& node, T* value) {
  try {
    *value = node.as<T>();
    return true;
  } catch (const YAML::Exception&) {
    return false;
  }
}

// The value as YAML text in flow style: "0.1", "[1, 0, 0]".
std::string ValueText(const YAML::Node& node) {
  YAML::Emitter emitter;
  emitter << YAML::Flow << node;
  return emitter.c_str();
}

// `path` relative to `dir` unless absolute.
std::string Resolve(const fs::path& dir, const std::string& path) {
  const fs::path p(path);
  return p.is_absolute() ? path : (dir / p).lexically_normal().string();
}

// A key names its file (scenario. or config.) and a path inside it.
std::string KeyProblem(const std::string& key) {
  const bool scenario = key.rfind("scenario.", 0) == 0, config = key.rfind("config.", 0) == 0;
  if ((!scenario && !config) || key.back() == '.' || key.find("..") != std::string::npos)
    return "key '" + key + "' is not scenario.PATH or config.PATH";
  return "";
}

// grid: every combination of the keys' values, the first key varying slowest.
Status ReadGrid(const std::string& file, const YAML::Node& grid, SweepPlan* plan) {
  if (!grid.IsMap() || grid.size() == 0) return Status::Error(file + ": grid: not a mapping of keys to value lists");
  std::vector<std::vector<std::string>> lists;
  for (const auto& entry : grid) {
    const std::string key = entry.first.as<std::string>();
    if (const std::string problem = KeyProblem(key); !problem.empty())
      return Status::Error(file + ": grid: " + problem);
    if (!entry.second.IsSequence() || entry.second.size() == 0)
      return Status::Error(file + ": grid: " + key + ": not a non-empty list of values");
    plan->keys.push_back(key);
    lists.emplace_back();
    for (const YAML::Node& value : entry.second) lists.back().push_back(ValueText(value));
  }
  std::vector<std::vector<std::string>> points{{}};
  for (const std::vector<std::string>& list : lists) {
    std::vector<std::vector<std::string>> longer;
    for (const std::vector<std::string>& point : points)
      for (const std::string& value : list) {
        longer.push_back(point);
        longer.back().push_back(value);
      }
    points = std::move(longer);
  }
  plan->values = std::move(points);
  return Status::Ok();
}

// list: the points one by one, each naming the first point's keys.
Status ReadList(const std::string& file, const YAML::Node& list, SweepPlan* plan) {
  if (!list.IsSequence() || list.size() == 0) return Status::Error(file + ": list: not a non-empty list of points");
  for (std::size_t p = 0; p < list.size(); ++p) {
    const YAML::Node& point = list[p];
    const std::string where = file + ": list[" + std::to_string(p) + "]";
    if (!point.IsMap() || point.size() == 0) return Status::Error(where + ": not a mapping of keys to values");
    std::vector<std::string> keys, values;
    for (const auto& entry : point) {
      keys.push_back(entry.first.as<std::string>());
      if (const std::string problem = KeyProblem(keys.back()); !problem.empty())
        return Status::Error(where + ": " + problem);
      values.push_back(ValueText(entry.second));
    }
    if (p == 0) plan->keys = keys;
    if (keys != plan->keys) return Status::Error(where + ": names other keys than list[0]");
    plan->values.push_back(values);
  }
  return Status::Ok();
}

// The Monte-Carlo settings of SWEEP.yaml (every key but grid and list).
Status ReadSettings(const std::string& file, const YAML::Node& root, SweepPlan* plan) {
  static const std::set<std::string> kKeys = {"scenario", "config",         "calibration",        "seeds", "seed_base",
                                              "t0_s",     "no_time_budget", "calibrate_each_run", "grid",  "list"};
  for (const auto& entry : root)
    if (!kKeys.count(entry.first.as<std::string>()))
      return Status::Error(file + ": unknown key '" + entry.first.as<std::string>() + "'");
  const fs::path dir = fs::path(file).parent_path();
  MonteCarloOptions& mc = plan->montecarlo;
  std::string scenario, config, calibration;
  if (!root["scenario"] || !As(root["scenario"], &scenario)) return Status::Error(file + ": no scenario file");
  if (!root["config"] || !As(root["config"], &config)) return Status::Error(file + ": no config file");
  if (!root["seeds"] || !As(root["seeds"], &mc.runs) || mc.runs < 1)
    return Status::Error(file + ": seeds: not an integer >= 1");
  mc.scenario = Resolve(dir, scenario);
  mc.config = Resolve(dir, config);
  if (root["calibration"] && !As(root["calibration"], &calibration))
    return Status::Error(file + ": calibration: not a file name");
  if (!calibration.empty()) mc.calibration = Resolve(dir, calibration);
  const bool ok = (!root["seed_base"] || As(root["seed_base"], &mc.seed_base)) &&
                  (!root["t0_s"] || As(root["t0_s"], &mc.t0_s)) &&
                  (!root["no_time_budget"] || As(root["no_time_budget"], &mc.no_time_budget)) &&
                  (!root["calibrate_each_run"] || As(root["calibrate_each_run"], &mc.calibrate_each_run));
  if (!ok) return Status::Error(file + ": seed_base, t0_s, no_time_budget or calibrate_each_run: wrong type");
  if (static_cast<bool>(root["grid"]) == static_cast<bool>(root["list"]))
    return Status::Error(file + ": needs either grid or list");
  return Status::Ok();
}

// Sets the value of `key` (without its file prefix, dotted) in `root`, where it must exist.
Status Patch(YAML::Node root, const std::string& file, const std::string& path, const std::string& value) {
  std::vector<std::string> parts;
  std::stringstream split(path);
  for (std::string part; std::getline(split, part, '.');) parts.push_back(part);
  YAML::Node node = root;
  for (std::size_t k = 0; k + 1 < parts.size(); ++k) {
    const YAML::Node& view = node;
    if (!view.IsMap() || !view[parts[k]]) return Status::Error(file + ": has no key " + path);
    node.reset(node[parts[k]]);
  }
  const YAML::Node& view = node;
  if (!view.IsMap() || !view[parts.back()]) return Status::Error(file + ": has no key " + path);
  try {
    node[parts.back()] = YAML::Load(value);
  } catch (const YAML::Exception& e) {
    return Status::Error(file + ": " + path + ": value '" + value + "' is not YAML");
  }
  return Status::Ok();
}

// The file reference at root[a][b] made absolute relative to `dir`.
void MakeAbsolute(YAML::Node root, const char* a, const char* b, const fs::path& dir) {
  const YAML::Node& view = root;
  if (!view.IsMap() || !view[a] || !view[a].IsMap() || !view[a][b] || !view[a][b].IsScalar()) return;
  root[a][b] = Resolve(dir, view[a][b].as<std::string>());
}

Result<YAML::Node> LoadYaml(const std::string& file) {
  try {
    YAML::Node root = YAML::LoadFile(file);
    if (!root.IsMap()) return Status::Error(file + ": not a YAML mapping");
    return root;
  } catch (const YAML::Exception& e) {
    return Status::Error(file + ": " + e.what());
  }
}

std::string Emit(const YAML::Node& root) {
  YAML::Emitter emitter;
  emitter << root;
  return std::string(emitter.c_str()) + "\n";
}

// The mean of the runs' `key` (null counts as NaN); NaN without runs.
double MeanOver(const json& runs, const char* key) {
  double sum = 0.0;
  for (const json& run : runs) {
    const auto it = run.find(key);
    sum += it != run.end() && it->is_number() ? it->get<double>() : std::numeric_limits<double>::quiet_NaN();
  }
  return runs.empty() ? std::numeric_limits<double>::quiet_NaN() : sum / static_cast<double>(runs.size());
}

// The file's JSON; discarded (not an object) when it cannot be read or parsed.
json ReadJsonFile(const std::string& path) {
  const Result<std::string> text = ReadWholeFile(path);
  return text.ok() ? json::parse(text.value(), nullptr, false) : json();
}

// Point p's row of sweep.json from its nees.json and runs.json.
Result<json> PointRow(const SweepPlan& plan, int p) {
  const MonteCarloOptions options = SweepPointOptions(plan, p);
  const json nees = ReadJsonFile(options.out + "/nees.json");
  json runs = ReadJsonFile(options.out + "/runs.json");
  if (!nees.is_object() || !nees.contains("fraction_in_band") || !runs.is_object() || !runs.contains("runs") ||
      !runs["runs"].is_array())
    return Status::Error(options.out + ": no Monte-Carlo summary (nees.json, runs.json)");
  json values = json::object();
  for (std::size_t k = 0; k < plan.keys.size(); ++k) values[plan.keys[k]] = plan.values[p][k];
  const json& fraction = nees["fraction_in_band"];
  return json{{"point", p},
              {"values", values},
              {"dir", fs::path(options.out).lexically_relative(plan.out).string()},
              {"fraction_in_band", fraction.is_number() ? fraction : json()},
              {"mean_nees", Number(MeanOver(runs["runs"], "mean_nees"))},
              {"ate_m", Number(MeanOver(runs["runs"], "ate_m"))},
              {"rpe_m", Number(MeanOver(runs["runs"], "rpe_m"))},
              {"track_seconds", Number(MeanOver(runs["runs"], "track_seconds"))}};
}

std::string FormatNumber(const json& value) {
  if (!value.is_number()) return "nan";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.6g", value.get<double>());
  return buffer;
}

// A CSV field, quoted when it holds a comma or a quote.
std::string CsvField(const std::string& text) {
  if (text.find_first_of(",\"") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

std::string TableCsv(const SweepPlan& plan, const json& rows) {
  std::string csv = "point";
  for (const std::string& key : plan.keys) csv += "," + CsvField(key);
  for (const Metric& m : kMetrics) csv += std::string(",") + m.key;
  csv += "\n";
  for (const json& row : rows) {
    csv += std::to_string(row["point"].get<int>());
    for (const std::string& key : plan.keys) csv += "," + CsvField(row["values"][key].get<std::string>());
    for (const Metric& m : kMetrics) csv += "," + FormatNumber(row[m.key]);
    csv += "\n";
  }
  return csv;
}

// The value as a number when all of `texts` are numbers; false otherwise.
bool AllNumbers(const std::vector<std::string>& texts) {
  for (const std::string& t : texts) {
    char* end = nullptr;
    std::strtod(t.c_str(), &end);
    if (t.empty() || *end != '\0') return false;
  }
  return true;
}

// A file name part from a key: letters, digits and _ only.
std::string FileName(const std::string& key) {
  std::string name;
  for (const char c : key) name += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return name;
}

// gnuplot's single-quoted string.
std::string GnuplotString(const std::string& text) {
  std::string quoted = "'";
  for (const char c : text) quoted += c == '\'' ? std::string("''") : std::string(1, c);
  return quoted + "'";
}

// OUT/plots/METRIC_vs_KEY.gp and .dat: the metric against key k, one line per value of the other keys.
Result<std::string> WritePlot(const SweepPlan& plan, const json& rows, std::size_t k, const Metric& metric) {
  std::vector<std::string> distinct;
  for (const std::vector<std::string>& point : plan.values)
    if (std::find(distinct.begin(), distinct.end(), point[k]) == distinct.end()) distinct.push_back(point[k]);
  const bool numeric = AllNumbers(distinct);
  std::map<std::string, std::vector<std::pair<double, double>>> lines;  // other keys' values -> (x, y)
  for (std::size_t p = 0; p < plan.values.size(); ++p) {
    std::string others;
    for (std::size_t j = 0; j < plan.keys.size(); ++j)
      if (j != k) others += (others.empty() ? "" : ", ") + plan.keys[j] + " = " + plan.values[p][j];
    const std::string& v = plan.values[p][k];
    const double x = numeric ? std::strtod(v.c_str(), nullptr)
                             : static_cast<double>(std::find(distinct.begin(), distinct.end(), v) - distinct.begin());
    const json& y = rows[p][metric.key];
    lines[others].push_back({x, y.is_number() ? y.get<double>() : std::numeric_limits<double>::quiet_NaN()});
  }
  const std::string name = std::string(metric.key) + "_vs_" + FileName(plan.keys[k]);
  std::string dat, plot;
  int index = 0;
  for (auto& [label, points] : lines) {
    std::sort(points.begin(), points.end());
    for (const auto& [x, y] : points) dat += FormatNumber(x) + " " + FormatNumber(y) + "\n";
    dat += "\n\n";
    plot += std::string(index ? ", " : "plot ") + "'" + name + ".dat' index " + std::to_string(index) +
            " using 1:2 with linespoints title " + GnuplotString(label.empty() ? metric.key : label);
    ++index;
  }
  std::string script = "set terminal pngcairo size 800,500 noenhanced font 'sans,11'\nset output '" + name +
                       ".png'\nset grid\nset offsets graph 0.05, graph 0.05, graph 0.05, graph 0.05\nset key outside "
                       "below\nset xlabel " +
                       GnuplotString(plan.keys[k]) + "\nset ylabel " + GnuplotString(metric.label) + "\n";
  if (!numeric) {
    script += "set xtics (";
    for (std::size_t d = 0; d < distinct.size(); ++d)
      script += (d ? ", " : "") + GnuplotString(distinct[d]) + " " + std::to_string(d);
    script += ")\nset xrange [-0.5:" + std::to_string(distinct.size() - 0.5) + "]\n";
  }
  const std::string dir = plan.out + "/plots";
  if (Status s = WriteFileAtomic(dir + "/" + name + ".dat", dat); !s.ok()) return s;
  if (Status s = WriteFileAtomic(dir + "/" + name + ".gp", script + plot + "\n"); !s.ok()) return s;
  return name;
}

// Every plot drawn; the PNGs written, and a note when gnuplot is missing or failed.
std::vector<std::string> WritePlots(const SweepPlan& plan, const json& rows, std::string* note) {
  std::vector<std::string> images;
  if (const Status made = MakeOutputDirectory(plan.out + "/plots"); !made.ok()) {
    *note = " (" + made.message() + ")";
    return images;
  }
  const bool gnuplot = eval::GnuplotAvailable();
  if (!gnuplot) *note = " (gnuplot not found: no plots)";
  for (std::size_t k = 0; k < plan.keys.size(); ++k)
    for (const Metric& metric : kMetrics) {
      Result<std::string> name = WritePlot(plan, rows, k, metric);
      Status drawn = name.ok() ? (gnuplot ? eval::RunGnuplot(plan.out + "/plots", name.value() + ".gp") : Status::Ok())
                               : name.status();
      if (!drawn.ok() && note->empty()) *note = " (plot failed: " + drawn.message() + ")";
      if (drawn.ok() && gnuplot) images.push_back(plan.out + "/plots/" + name.value() + ".png");
    }
  return images;
}

void WriteReport(const SweepPlan& plan, const json& rows, const std::vector<std::string>& images) {
  html::Page page("Sweep: " + plan.montecarlo.scenario);
  page.Paragraph(std::to_string(rows.size()) + " points x " + std::to_string(plan.montecarlo.runs) + " seeds over " +
                     std::to_string(plan.keys.size()) + " keys",
                 "headline");
  html::Table table;
  table.header.push_back("point");
  for (const std::string& key : plan.keys) table.header.push_back(key);
  for (const Metric& m : kMetrics) table.header.push_back(m.label);
  for (const json& row : rows) {
    table.rows.push_back({std::to_string(row["point"].get<int>())});
    for (const std::string& key : plan.keys) table.rows.back().push_back(row["values"][key].get<std::string>());
    for (const Metric& m : kMetrics) table.rows.back().push_back(FormatNumber(row[m.key]));
  }
  page.AddTable(table);
  for (const std::string& image : images)
    if (Status s = page.AddImage(image, fs::path(image).stem().string()); !s.ok()) page.Paragraph(s.message(), "note");
  (void)page.Write(plan.out + "/report.html");
}

}  // namespace

Result<SweepPlan> ReadSweep(const std::string& file, const std::string& out) {
  auto root = LoadYaml(file);
  if (!root.ok()) return root.status();
  if (const std::string problem = DuplicateKeyProblem(root.value()); !problem.empty())
    return Status::Error(file + ":" + problem);
  SweepPlan plan;
  plan.out = out;
  try {
    if (Status s = ReadSettings(file, root.value(), &plan); !s.ok()) return s;
    const YAML::Node& view = root.value();
    const Status points = view["grid"] ? ReadGrid(file, view["grid"], &plan) : ReadList(file, view["list"], &plan);
    if (!points.ok()) return points;
  } catch (const YAML::Exception& e) {
    return Status::Error(file + ": " + e.what());
  }
  if (plan.values.size() > 999) return Status::Error(file + ": more than 999 points");
  plan.montecarlo.out = out;
  return plan;
}

Status WriteSweepPoints(const SweepPlan& plan) {
  auto scenario = LoadYaml(plan.montecarlo.scenario);
  if (!scenario.ok()) return scenario.status();
  auto config = LoadYaml(plan.montecarlo.config);
  if (!config.ok()) return config.status();
  for (int p = 0; p < static_cast<int>(plan.values.size()); ++p) {
    YAML::Node s = YAML::Clone(scenario.value()), c = YAML::Clone(config.value());
    for (std::size_t k = 0; k < plan.keys.size(); ++k) {
      const bool in_scenario = plan.keys[k].rfind("scenario.", 0) == 0;
      const std::string path = plan.keys[k].substr(plan.keys[k].find('.') + 1);
      const Status patched = in_scenario ? Patch(s, plan.montecarlo.scenario, path, plan.values[p][k])
                                         : Patch(c, plan.montecarlo.config, path, plan.values[p][k]);
      if (!patched.ok()) return patched;
    }
    MakeAbsolute(s, "robot", "model", fs::path(plan.montecarlo.scenario).parent_path());
    MakeAbsolute(c, "tracking", "calibrate", fs::path(plan.montecarlo.config).parent_path());
    const MonteCarloOptions options = SweepPointOptions(plan, p);
    if (Status made = MakeOutputDirectory(options.out); !made.ok()) return made;
    if (Status w = WriteFileAtomic(options.scenario, Emit(s)); !w.ok()) return w;
    if (Status w = WriteFileAtomic(options.config, Emit(c)); !w.ok()) return w;
  }
  return Status::Ok();
}

MonteCarloOptions SweepPointOptions(const SweepPlan& plan, int p) {
  char dir[32];
  std::snprintf(dir, sizeof dir, "/points/%03d", p);
  MonteCarloOptions options = plan.montecarlo;
  options.out = plan.out + dir;
  options.scenario = options.out + "/scenario.yaml";
  options.config = options.out + "/config.yaml";
  return options;
}

Outcome WriteSweepSummary(const SweepPlan& plan, std::string* headline) {
  json rows = json::array();
  for (int p = 0; p < static_cast<int>(plan.values.size()); ++p) {
    Result<json> row = PointRow(plan, p);
    if (!row.ok()) return Outcome::Failed(row.status());
    rows.push_back(std::move(row).value());
  }
  const json sweep = {{"keys", plan.keys}, {"seeds", plan.montecarlo.runs}, {"points", rows}};
  if (Status s = WriteFileAtomic(plan.out + "/sweep.json", sweep.dump(2) + "\n"); !s.ok())
    return Outcome::Failed(s);
  if (Status s = WriteFileAtomic(plan.out + "/table.csv", TableCsv(plan, rows)); !s.ok()) return Outcome::Failed(s);
  std::string note;
  WriteReport(plan, rows, WritePlots(plan, rows, &note));
  *headline = std::to_string(rows.size()) + " points x " + std::to_string(plan.montecarlo.runs) + " seeds; wrote " +
              plan.out + "/table.csv" + note;
  return Outcome::Ok();
}

Outcome RunSweep(const SweepPlan& plan, bool resume, int jobs, const std::function<void(const std::string&)>& log,
                 const std::function<void(int finished, int runs)>& progress, std::string* headline) {
  const int points = static_cast<int>(plan.values.size());
  if (Status written = WriteSweepPoints(plan); !written.ok()) return Outcome::BadInput(written);
  for (int p = 0; p < points; ++p) {
    MonteCarloOptions options = SweepPointOptions(plan, p);
    options.resume = resume;
    options.jobs = jobs;
    // Runs over all points; with `resume` the runs a point already has count as finished.
    if (progress)
      options.progress = [&progress, runs = options.runs, total = points * options.runs, p](int finished, int todo) {
        progress(p * runs + runs - todo + finished, total);
      };
    if (log) {
      std::string values;
      for (std::size_t k = 0; k < plan.keys.size(); ++k)
        values += (k ? ", " : "") + plan.keys[k] + " = " + plan.values[p][k];
      log("point " + std::to_string(p + 1) + "/" + std::to_string(points) + ": " + values);
    }
    Outcome outcome = RunMonteCarlo(options);
    if (!outcome.ok()) {
      outcome.status = Status::Error(options.out + ": " + outcome.status.message());
      return outcome;
    }
  }
  return WriteSweepSummary(plan, headline);
}

}  // namespace roamlab::experiment
