#include "apps/regress_suite.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <set>

#include <yaml-cpp/yaml.h>

#include "apps/commands.h"
#include "apps/regress_modes.h"
#include "estimator/config.h"
#include "sim/scenario.h"

namespace roamlab::apps::regress {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const char* const kReductions[] = {"norm", "max_abs", "min", "max", "mean"};

// A tiny scanner over a bound's text.
class Scanner {
 public:
  explicit Scanner(const std::string& text) : text_(text) {}
  void SkipSpace() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
  }
  bool AtEnd() {
    SkipSpace();
    return pos_ == text_.size();
  }
  bool Accept(const std::string& token) {
    SkipSpace();
    if (text_.compare(pos_, token.size(), token) != 0) return false;
    pos_ += token.size();
    return true;
  }
  // A finite decimal number (no sign: signs are operators here).
  std::optional<double> Number() {
    SkipSpace();
    if (pos_ == text_.size() || !(std::isdigit(static_cast<unsigned char>(text_[pos_])) || text_[pos_] == '.'))
      return std::nullopt;
    const char* begin = text_.c_str() + pos_;
    char* end = nullptr;
    const double value = std::strtod(begin, &end);
    if (end == begin || !std::isfinite(value)) return std::nullopt;
    pos_ += static_cast<std::size_t>(end - begin);
    return value;
  }
  std::string Rest() const { return text_.substr(pos_); }

 private:
  const std::string& text_;
  std::size_t pos_ = 0;
};

bool IsIndex(const std::string& s) {
  return !s.empty() && s.size() < 9 && std::all_of(s.begin(), s.end(), [](char c) { return std::isdigit(c); });
}

std::string Join(const std::vector<std::string>& parts, std::size_t begin, std::size_t end) {
  std::string out;
  for (std::size_t i = begin; i < end; ++i) out += (i > begin ? "." : "") + parts[i];
  return out;
}

std::vector<std::string> Split(const std::string& text) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  for (std::size_t dot; (dot = text.find('.', start)) != std::string::npos; start = dot + 1)
    parts.push_back(text.substr(start, dot - start));
  parts.push_back(text.substr(start));
  return parts;
}

std::string KeyList(const json& object) {
  std::string keys;
  for (const auto& [key, value] : object.items()) keys += (keys.empty() ? "" : ", ") + key;
  return keys;
}

// Names the schema's placeholders stand for.
struct Names {
  std::set<std::string> parameters;
  std::set<std::string> streams;
};

Names NamesOf(const estimator::EstimatorConfig& config) {
  Names names;
  for (const auto& [name, p] : config.parameters) names.parameters.insert(name);
  for (const auto& [stream, s] : config.streams) {
    names.streams.insert(stream);
    if (const estimator::ModelSpec* model = estimator::FindModelSpec(s.model))
      for (const estimator::SlotSpec& slot : model->slots) {
        const auto mapped = s.parameters.find(slot.name);
        names.parameters.insert(mapped != s.parameters.end() ? mapped->second : stream + "." + slot.name);
      }
  }
  return names;
}

// Checks a metric path against the mode's output schemas; returns the parsed path or what is wrong.
Result<MetricPath> ParseMetricPath(const std::string& text, const ModeSpec& mode, const Names& names) {
  const std::vector<std::string> parts = Split(text);
  MetricPath path;
  path.text = text;
  path.output = parts[0];
  const ModeOutput* output = nullptr;
  std::string outputs;
  for (const ModeOutput& o : mode.outputs) {
    outputs += (outputs.empty() ? "" : ", ") + o.name;
    if (o.name == parts[0]) output = &o;
  }
  if (!output)
    return Status::Error("metric '" + text + "': mode " + mode.name + " writes no output '" + parts[0] + "' (" +
                         outputs + ")");
  const json* node = &output->schema;
  std::size_t i = 1;
  bool column = false;
  while (node->is_object() || node->is_array()) {
    if (node->is_array()) {  // a column of an array of objects: numbers
      node = &(*node)[0];
      column = true;
    }
    if (i == parts.size())
      return Status::Error("metric '" + text + "' names an object; continue with one of: " + KeyList(*node));
    if (node->contains(parts[i])) {
      path.keys.push_back(parts[i]);
      node = &(*node)[parts[i]];
      ++i;
      continue;
    }
    // A placeholder: the longest configured name that the next parts spell (names may contain dots).
    const char* placeholder = node->contains("<parameter>") ? "<parameter>"
                              : node->contains("<stream>")  ? "<stream>"
                                                            : nullptr;
    if (!placeholder)
      return Status::Error("metric '" + text + "': unknown key '" + parts[i] + "' after '" + Join(parts, 0, i) +
                           "' (known: " + KeyList(*node) + ")");
    const std::set<std::string>& known =
        std::string(placeholder) == "<parameter>" ? names.parameters : names.streams;
    std::size_t matched = 0;
    for (std::size_t j = parts.size(); j > i && matched == 0; --j)
      if (known.count(Join(parts, i, j))) matched = j;
    if (matched == 0) {
      std::string list;
      for (const std::string& n : known) list += (list.empty() ? "" : ", ") + n;
      return Status::Error("metric '" + text + "': '" + Join(parts, i, parts.size()) + "' does not start with a " +
                           std::string(placeholder).substr(1, std::string(placeholder).size() - 2) +
                           " of the case's configuration (" + list + ")");
    }
    path.keys.push_back(Join(parts, i, matched));
    node = &(*node)[placeholder];
    i = matched;
  }
  std::string leaf = node->get<std::string>();
  if (column && leaf == "number") leaf = "numbers";
  if (leaf == "timing")
    return Status::Error("metric '" + text + "' is a timing value (not deterministic) and cannot be a check");
  const std::size_t rest = parts.size() - i;
  if (leaf == "numbers") {
    const std::string hint = "add .norm, .max_abs, .min, .max, .mean or an index";
    if (rest == 0) return Status::Error("metric '" + text + "' is an array: " + hint);
    const bool known = IsIndex(parts[i]) || std::find(std::begin(kReductions), std::end(kReductions), parts[i]) !=
                                                 std::end(kReductions);
    if (rest > 1 || !known)
      return Status::Error("metric '" + text + "': '" + Join(parts, i, parts.size()) + "' is not a reduction (" +
                           hint + ")");
    path.reduction = parts[i];
    return path;
  }
  if (rest > 0)
    return Status::Error("metric '" + text + "': '" + Join(parts, 0, i) + "' is a number; nothing follows it");
  return path;
}

double Reduce(const std::vector<double>& v, const std::string& reduction) {
  double out = reduction == "min" ? v[0] : reduction == "max" ? v[0] : 0.0;
  for (double x : v) {
    if (reduction == "norm") out += x * x;
    if (reduction == "max_abs") out = std::max(out, std::abs(x));
    if (reduction == "min") out = std::min(out, x);
    if (reduction == "max") out = std::max(out, x);
    if (reduction == "mean") out += x / static_cast<double>(v.size());
  }
  return reduction == "norm" ? std::sqrt(out) : out;
}

Result<std::vector<double>> Numbers(const json& node, const std::string& where) {
  if (!node.is_array()) return Status::Error(where + " is not an array");
  std::vector<double> v;
  for (const json& x : node) {
    if (!x.is_number()) return Status::Error(where + " holds a null or a non-number");
    v.push_back(x.get<double>());
  }
  if (v.empty()) return Status::Error(where + " is empty");
  return v;
}

// Derived "relative_error" of a parameter row: max_i |error_i / truth_i|.
Result<double> RelativeError(const json& row, const std::string& where) {
  if (!row.contains("error") || !row.contains("truth")) return Status::Error(where + ": no error or truth");
  const auto error = Numbers(row["error"], where + ".error");
  if (!error.ok()) return error.status();
  const auto truth = Numbers(row["truth"], where + ".truth");
  if (!truth.ok()) return truth.status();
  if (error.value().size() != truth.value().size())
    return Status::Error(where + ": error and truth differ in size (a rotation has no relative error)");
  double worst = 0.0;
  for (std::size_t k = 0; k < truth.value().size(); ++k) {
    if (truth.value()[k] == 0.0) return Status::Error(where + ": a true value is 0 (no relative error)");
    worst = std::max(worst, std::abs(error.value()[k] / truth.value()[k]));
  }
  return worst;
}

// YAML helpers: every error names the suite file and line.
struct Context {
  std::string file;
  std::string case_name;
  std::string Where(const YAML::Node& node) const {
    std::string where = file + ":" + std::to_string(node.Mark().line + 1) + ":";
    if (!case_name.empty()) where += " case '" + case_name + "':";
    return where;
  }
  Status Error(const YAML::Node& node, const std::string& problem) const {
    return Status::Error(Where(node) + " " + problem);
  }
};

std::string ResolvePath(const std::string& suite_file, const std::string& path) {
  if (path.empty() || fs::path(path).is_absolute()) return path;
  return (fs::path(suite_file).parent_path() / path).lexically_normal().string();
}

// Loads and validates one case; `seen` holds the names of the cases before it.
Result<Case> LoadCase(const YAML::Node& node, const Context& suite, std::set<std::string>* seen) {
  Context ctx = suite;
  if (!node.IsMap()) return ctx.Error(node, "a case must be a map");
  if (!node["name"] || !node["name"].IsScalar()) return ctx.Error(node, "a case needs a 'name'");
  Case c;
  c.name = node["name"].as<std::string>();
  c.line = node.Mark().line + 1;
  ctx.case_name = c.name;
  if (c.name.empty() || !std::all_of(c.name.begin(), c.name.end(), [](char ch) {
        return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-' || ch == '.';
      }))
    return ctx.Error(node["name"], "a case name may only hold letters, digits, '_', '-' and '.'");
  if (!seen->insert(c.name).second) return ctx.Error(node["name"], "a second case of this name");

  // Mode.
  if (!node["mode"] || !node["mode"].IsScalar())
    return ctx.Error(node, "no 'mode' (" + AvailableModeNames() + ")");
  c.mode = node["mode"].as<std::string>();
  const ModeSpec* mode = FindMode(c.mode);
  if (!mode) return ctx.Error(node["mode"], "unknown mode '" + c.mode + "' (" + AvailableModeNames() + ")");
  if (!mode->run) return ctx.Error(node["mode"], "mode " + c.mode + " is not available in this build");

  // Keys.
  for (const auto& entry : node) {
    const std::string key = entry.first.as<std::string>();
    const bool common = key == "name" || key == "mode" || key == "quick" || key == "checks";
    if (!common && std::find(mode->keys.begin(), mode->keys.end(), key) == mode->keys.end()) {
      std::string allowed = "name, mode, quick, checks";
      for (const std::string& k : mode->keys) allowed += ", " + k;
      return ctx.Error(entry.first, "unknown key '" + key + "' for mode " + c.mode + " (" + allowed + ")");
    }
  }
  for (const std::string& required : mode->required) {
    const std::size_t bar = required.find('|');
    if (bar == std::string::npos) {
      if (!node[required]) return ctx.Error(node, "mode " + c.mode + " needs '" + required + "'");
      continue;
    }
    const std::string a = required.substr(0, bar), b = required.substr(bar + 1);
    if (static_cast<bool>(node[a]) == static_cast<bool>(node[b]))
      return ctx.Error(node, "mode " + c.mode + " needs exactly one of '" + a + "' and '" + b + "'");
  }
  if (node["calibration"] && node["calibrate"])
    return ctx.Error(node, "give 'calibration' (a file) or 'calibrate' (a configuration), not both");

  // Values.
  try {
    if (node["quick"]) c.quick = node["quick"].as<bool>();
    if (node["seed"]) c.seed = node["seed"].as<std::uint64_t>();
    if (node["runs"]) c.runs = node["runs"].as<int>();
    if (node["seed_base"]) c.seed_base = node["seed_base"].as<std::uint64_t>();
    if (node["t0_s"]) c.t0_s = node["t0_s"].as<double>();
    for (auto [key, field] : {std::pair{"scenario", &c.scenario}, {"recording", &c.recording},
                              {"config", &c.config}, {"calibration", &c.calibration}, {"calibrate", &c.calibrate}})
      if (node[key]) *field = ResolvePath(suite.file, node[key].as<std::string>());
  } catch (const YAML::Exception& e) {
    return ctx.Error(node, std::string("malformed value: ") + e.msg);
  }
  if (node["runs"] && c.runs < 1) return ctx.Error(node["runs"], "runs must be at least 1");

  // Inputs exist and load.
  if (!c.scenario.empty()) {
    if (!fs::is_regular_file(c.scenario)) return ctx.Error(node["scenario"], "missing scenario " + c.scenario);
    const auto scenario = sim::LoadScenario(c.scenario);
    if (!scenario.ok()) return ctx.Error(node["scenario"], "bad scenario: " + scenario.status().message());
  }
  if (!c.recording.empty() && !fs::is_regular_file(fs::path(c.recording) / "recording.yaml"))
    return ctx.Error(node["recording"], "missing recording " + c.recording + " (no recording.yaml)");
  Names names;
  if (!c.config.empty()) {
    const auto config = estimator::LoadEstimatorConfig(c.config);
    if (!config.ok()) return ctx.Error(node["config"], "bad config: " + config.status().message());
    names = NamesOf(config.value());
  }
  if (!c.calibrate.empty()) {
    const auto config = estimator::LoadEstimatorConfig(c.calibrate);
    if (!config.ok()) return ctx.Error(node["calibrate"], "bad config: " + config.status().message());
  }
  if (!c.calibration.empty()) {
    const auto values = ReadCalibrationValues(c.calibration);
    if (!values.ok()) return ctx.Error(node["calibration"], "bad calibration: " + values.status().message());
  }

  // Checks.
  const YAML::Node checks = node["checks"];
  if (!checks || !checks.IsSequence() || checks.size() == 0)
    return ctx.Error(node, "no 'checks' (a list of {metric: PATH, bound: \"<= 0.5\"})");
  for (const YAML::Node& check : checks) {
    if (!check.IsMap() || !check["metric"] || !check["bound"] || check.size() != 2)
      return ctx.Error(check, "a check is {metric: PATH, bound: BOUND} and nothing else");
    Check k;
    k.line = check.Mark().line + 1;
    auto metric = ParseMetricPath(check["metric"].as<std::string>(), *mode, names);
    if (!metric.ok()) return ctx.Error(check["metric"], metric.status().message());
    k.metric = std::move(metric).value();
    auto bound = ParseBound(check["bound"].as<std::string>());
    if (!bound.ok()) return ctx.Error(check["bound"], bound.status().message());
    k.bound = std::move(bound).value();
    c.checks.push_back(std::move(k));
  }
  return c;
}

}  // namespace

bool Bound::Holds(double value, double threshold) const {
  if (std::isnan(value) || std::isnan(threshold)) return false;
  switch (comparator) {
    case Comparator::kLess: return value < threshold;
    case Comparator::kLessEqual: return value <= threshold;
    case Comparator::kGreater: return value > threshold;
    case Comparator::kGreaterEqual: return value >= threshold;
  }
  return false;
}

Result<Bound> ParseBound(const std::string& text) {
  Bound b;
  b.text = text;
  Scanner s(text);
  const std::string prefix = "bound '" + text + "': ";
  if (s.Accept("<=")) {
    b.comparator = Bound::Comparator::kLessEqual;
  } else if (s.Accept(">=")) {
    b.comparator = Bound::Comparator::kGreaterEqual;
  } else if (s.Accept("<")) {
    b.comparator = Bound::Comparator::kLess;
  } else if (s.Accept(">")) {
    b.comparator = Bound::Comparator::kGreater;
  } else {
    return Status::Error(prefix + "must start with <=, <, >= or >");
  }
  // [-]NUMBER | [K *] baseline [(+|-) D]
  const bool negative = s.Accept("-");
  std::optional<double> first = s.Number();
  if (negative && !first) return Status::Error(prefix + "expected a number after '-'");
  if (first && negative) first = -*first;
  if (first && !s.Accept("*")) {
    b.offset = *first;
    if (!s.AtEnd()) return Status::Error(prefix + "unexpected '" + s.Rest() + "' after the number");
    return b;
  }
  if (!s.Accept("baseline"))
    return Status::Error(prefix + (first ? "expected 'baseline' after '*'"
                                         : "expected a number, 'baseline' or 'K * baseline' after the comparator"));
  b.uses_baseline = true;
  b.scale = first.value_or(1.0);
  if (s.AtEnd()) return b;
  const bool plus = s.Accept("+");
  if (!plus && !s.Accept("-")) return Status::Error(prefix + "unexpected '" + s.Rest() + "' after 'baseline'");
  const std::optional<double> d = s.Number();
  if (!d) return Status::Error(prefix + "expected a number after '" + (plus ? "+" : "-") + "'");
  b.offset = plus ? *d : -*d;
  if (!s.AtEnd()) return Status::Error(prefix + "unexpected '" + s.Rest() + "' at the end");
  return b;
}

Result<double> ResolveMetric(const json& output, const MetricPath& path) {
  const json* node = &output;
  std::string where = path.output;
  std::vector<double> column;
  bool is_column = false;
  for (std::size_t i = 0; i < path.keys.size(); ++i) {
    const std::string& key = path.keys[i];
    if (node->is_array() && i + 1 == path.keys.size()) {
      // The last key of an array of objects: that column, reduced below.
      for (const json& row : *node) {
        if (!row.is_object() || !row.contains(key) || !row[key].is_number())
          return Status::Error(where + "[]." + key + ": missing or not a number in a row");
        column.push_back(row[key].get<double>());
      }
      if (column.empty()) return Status::Error(where + " is empty");
      is_column = true;
      where += "[]." + key;
      break;
    }
    if (key == "relative_error" && i + 1 == path.keys.size() && node->is_object() && !node->contains(key))
      return RelativeError(*node, where);
    if (!node->is_object() || !node->contains(key)) return Status::Error(where + " has no key '" + key + "'");
    node = &(*node)[key];
    where += "." + key;
  }
  if (path.reduction.empty()) {
    if (is_column) return Status::Error(where + " is a column: it needs a reduction");
    if (node->is_null()) return Status::Error(where + " is null (not a number)");
    if (!node->is_number()) return Status::Error(where + " is not a number");
    return node->get<double>();
  }
  if (!is_column) {
    auto v = Numbers(*node, where);
    if (!v.ok()) return v.status();
    column = std::move(v).value();
  }
  if (IsIndex(path.reduction)) {
    const std::size_t index = std::stoul(path.reduction);
    if (index >= column.size())
      return Status::Error(where + " has " + std::to_string(column.size()) + " elements, no index " +
                           path.reduction);
    return column[index];
  }
  return Reduce(column, path.reduction);
}

Result<Suite> LoadSuite(const std::string& path) {
  Suite suite;
  suite.file = path;
  if (!fs::is_regular_file(path)) return Status::Error(path + ": cannot open the suite file");
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    return Status::Error(path + ":" + std::to_string(e.mark.line + 1) + ": not valid YAML: " + e.msg);
  }
  const Context ctx{path, ""};
  if (!root.IsMap()) return Status::Error(path + ": the suite must be a map with 'cases'");
  for (const auto& entry : root) {
    const std::string key = entry.first.as<std::string>();
    if (key != "suite" && key != "baseline" && key != "cases")
      return ctx.Error(entry.first, "unknown key '" + key + "' (suite, baseline, cases)");
  }
  try {
    suite.name = root["suite"] ? root["suite"].as<std::string>() : fs::path(path).stem().string();
    if (root["baseline"]) suite.baseline_dir = ResolvePath(path, root["baseline"].as<std::string>());
  } catch (const YAML::Exception& e) {
    return Status::Error(path + ":" + std::to_string(e.mark.line + 1) + ": 'suite' and 'baseline' are strings");
  }
  const YAML::Node cases = root["cases"];
  if (!cases || !cases.IsSequence() || cases.size() == 0)
    return Status::Error(path + ": no 'cases' (a list of cases)");
  std::set<std::string> seen;
  for (const YAML::Node& node : cases) {
    try {
      auto c = LoadCase(node, ctx, &seen);
      if (!c.ok()) return c.status();
      suite.cases.push_back(std::move(c).value());
    } catch (const YAML::Exception& e) {
      return Status::Error(path + ":" + std::to_string(e.mark.line + 1) + ": malformed case: " + e.msg);
    }
  }
  return suite;
}

}  // namespace roamlab::apps::regress
