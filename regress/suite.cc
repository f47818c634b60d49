#include "regress/suite.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <set>

#include <yaml-cpp/yaml.h>

#include "common/yaml_keys.h"
#include "estimator/calibration_io.h"
#include "estimator/config.h"
#include "regress/mode_specs.h"
#include "sim/scenario.h"

namespace roamlab::regress {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Bound, time and effect numbers beyond this magnitude are refused as no physical value (as in scenarios).
constexpr double kMaxSuiteNumber = 1e9;
bool InRange(double x) { return std::isfinite(x) && std::abs(x) <= kMaxSuiteNumber; }
// An external command's time limit per run [s] (as experiment/external.h).
constexpr double kMaxTimeoutS = 1e6;

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
  // A metric path: letters, digits, '_' and '.', with selectors in brackets; "" when none starts here.
  std::string Path() {
    SkipSpace();
    const std::size_t start = pos_;
    if (pos_ == text_.size() || !std::isalpha(static_cast<unsigned char>(text_[pos_]))) return "";
    while (pos_ < text_.size()) {
      const char ch = text_[pos_];
      if (ch == '[') {
        const std::size_t close = text_.find(']', pos_);
        pos_ = close == std::string::npos ? text_.size() : close + 1;
      } else if (std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '.') {
        ++pos_;
      } else {
        break;
      }
    }
    return text_.substr(start, pos_ - start);
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

// Splits a metric path at the dots outside row selectors.
std::vector<std::string> Split(const std::string& text) {
  std::vector<std::string> parts(1);
  int depth = 0;
  for (const char ch : text) {
    depth += ch == '[' ? 1 : ch == ']' ? -1 : 0;
    if (ch == '.' && depth == 0) {
      parts.emplace_back();
    } else {
      parts.back() += ch;
    }
  }
  return parts;
}

// A path component "key[field=value,...]": the key and its selector; an error when the brackets are malformed.
Result<std::pair<std::string, Selector>> SplitSelector(const std::string& part) {
  const std::size_t open = part.find('[');
  if (open == std::string::npos) {
    if (part.find(']') != std::string::npos) return Status::Error("'" + part + "': ']' without '['");
    return std::pair<std::string, Selector>{part, {}};
  }
  if (open == 0 || part.back() != ']' || part.find('[', open + 1) != std::string::npos)
    return Status::Error("'" + part + "': a selector is KEY[FIELD=VALUE,...] at the end of a component");
  Selector selector;
  const std::string inside = part.substr(open + 1, part.size() - open - 2);
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = inside.find(',', start);
    const std::string item = inside.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    const std::size_t eq = item.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == item.size())
      return Status::Error("'" + part + "': selector item '" + item + "' is not FIELD=VALUE");
    selector.emplace_back(item.substr(0, eq), item.substr(eq + 1));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return std::pair<std::string, Selector>{part.substr(0, open), selector};
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
    const auto split = SplitSelector(parts[i]);
    if (!split.ok()) return Status::Error("metric '" + text + "': " + split.status().message());
    const auto& [key, selector] = split.value();
    if (node->contains(key)) {
      path.keys.push_back(key);
      node = &(*node)[key];
      ++i;
      if (selector.empty()) continue;
      if (!node->is_array())
        return Status::Error("metric '" + text + "': '" + key + "' is not an array of objects (no selector)");
      node = &(*node)[0];
      for (const auto& [field, value] : selector)
        if (!node->contains(field) || (*node)[field] != "string")
          return Status::Error("metric '" + text + "': a row of '" + key + "' has no text field '" + field +
                               "' to select by");
      path.select[path.keys.size() - 1] = selector;
      continue;
    }
    if (!selector.empty())
      return Status::Error("metric '" + text + "': unknown key '" + key + "' after '" + Join(parts, 0, i) +
                           "' (known: " + KeyList(*node) + ")");
    if (node->contains("<any>")) {  // any one key (an effect's parameter names): checked when the case has run
      path.keys.push_back(key);
      node = &(*node)["<any>"];
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
    const std::set<std::string>& known = std::string(placeholder) == "<parameter>" ? names.parameters : names.streams;
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
  if (leaf == "string") {
    if (column) return Status::Error("metric '" + text + "' is a column of texts: select one row with [FIELD=VALUE]");
    if (rest > 0)
      return Status::Error("metric '" + text + "': '" + Join(parts, 0, i) + "' is a text; nothing follows it");
    path.is_string = true;
    return path;
  }
  if (leaf == "numbers") {
    const std::string hint = "add .norm, .max_abs, .min, .max, .mean or an index";
    if (rest == 0) return Status::Error("metric '" + text + "' is an array: " + hint);
    const bool known = IsIndex(parts[i]) ||
                       std::find(std::begin(kReductions), std::end(kReductions), parts[i]) != std::end(kReductions);
    if (rest > 1 || !known)
      return Status::Error("metric '" + text + "': '" + Join(parts, i, parts.size()) + "' is not a reduction (" + hint +
                           ")");
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

// The scenarios and estimator configurations the suite names, each loaded once per suite: the cases of a suite name
// the same few files again and again.
class InputFiles {
 public:
  const Result<sim::Scenario>& Scenario(const std::string& path) {
    auto it = scenarios_.find(path);
    if (it == scenarios_.end()) it = scenarios_.emplace(path, sim::LoadScenario(path)).first;
    return it->second;
  }
  const Result<estimator::EstimatorConfig>& Config(const std::string& path) {
    auto it = configs_.find(path);
    if (it == configs_.end()) it = configs_.emplace(path, estimator::LoadEstimatorConfig(path)).first;
    return it->second;
  }

 private:
  std::map<std::string, Result<sim::Scenario>> scenarios_;
  std::map<std::string, Result<estimator::EstimatorConfig>> configs_;
};

std::string ResolvePath(const std::string& suite_file, const std::string& path) {
  if (path.empty() || fs::path(path).is_absolute()) return path;
  return (fs::path(suite_file).parent_path() / path).lexically_normal().string();
}

// The case's name (unique, [A-Za-z0-9_.-]+) and mode; `ctx` receives the case name for later messages.
Result<const ModeSpec*> LoadNameAndMode(const YAML::Node& node, Context* ctx, std::set<std::string>* seen, Case* c) {
  if (!node.IsMap()) return ctx->Error(node, "a case must be a map");
  if (!node["name"] || !node["name"].IsScalar()) return ctx->Error(node, "a case needs a 'name'");
  c->name = node["name"].as<std::string>();
  c->line = node.Mark().line + 1;
  ctx->case_name = c->name;
  if (c->name.empty() || !std::all_of(c->name.begin(), c->name.end(), [](char ch) {
        return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-' || ch == '.';
      }))
    return ctx->Error(node["name"], "a case name may only hold letters, digits, '_', '-' and '.'");
  if (!seen->insert(c->name).second) return ctx->Error(node["name"], "a second case of this name");

  if (!node["mode"] || !node["mode"].IsScalar()) return ctx->Error(node, "no 'mode' (" + ModeNames() + ")");
  c->mode = node["mode"].as<std::string>();
  const ModeSpec* mode = FindMode(c->mode);
  if (!mode) return ctx->Error(node["mode"], "unknown mode '" + c->mode + "' (" + ModeNames() + ")");
  return mode;
}

// Every key is one the mode reads; the required ones are there ("a|b": exactly one of them).
Status CheckKeys(const YAML::Node& node, const Context& ctx, const ModeSpec& mode) {
  for (const auto& entry : node) {
    const std::string key = entry.first.as<std::string>();
    const bool common = key == "name" || key == "mode" || key == "quick" || key == "data" || key == "checks";
    if (!common && std::find(mode.keys.begin(), mode.keys.end(), key) == mode.keys.end()) {
      std::string allowed = "name, mode, quick, data, checks";
      for (const std::string& k : mode.keys) allowed += ", " + k;
      return ctx.Error(entry.first, "unknown key '" + key + "' for mode " + mode.name + " (" + allowed + ")");
    }
  }
  for (const std::string& required : mode.required) {
    const std::size_t bar = required.find('|');
    if (bar == std::string::npos) {
      if (!node[required]) return ctx.Error(node, "mode " + mode.name + " needs '" + required + "'");
      continue;
    }
    const std::string a = required.substr(0, bar), b = required.substr(bar + 1);
    if (static_cast<bool>(node[a]) == static_cast<bool>(node[b]))
      return ctx.Error(node, "mode " + mode.name + " needs exactly one of '" + a + "' and '" + b + "'");
  }
  if (node["calibration"] && node["calibrate"])
    return ctx.Error(node, "give 'calibration' (a file) or 'calibrate' (a configuration), not both");
  if (node["command"] && (node["calibration"] || node["calibrate"]))
    return ctx.Error(node, "'calibration' and 'calibrate' are for 'config'; an external 'command' calibrates itself");
  if (node["timeout_s"] && !node["command"]) return ctx.Error(node["timeout_s"], "'timeout_s' is for a 'command'");
  return Status::Ok();
}

// The scalar values and the paths (resolved against the suite file, or `data` for train and test).
Status LoadValues(const YAML::Node& node, const Context& ctx, const std::string& suite_file, Case* c) {
  try {
    if (node["quick"]) c->quick = node["quick"].as<bool>();
    if (node["seed"]) c->seed = node["seed"].as<std::uint64_t>();
    if (node["runs"]) c->runs = node["runs"].as<int>();
    if (node["seed_base"]) c->seed_base = node["seed_base"].as<std::uint64_t>();
    if (node["t0_s"]) c->t0_s = node["t0_s"].as<double>();
    if (node["baseline_seed"]) c->baseline_seed = node["baseline_seed"].as<std::uint64_t>();
    if (node["interval_s"]) c->interval_s = node["interval_s"].as<double>();
    if (node["timeout_s"]) c->timeout_s = node["timeout_s"].as<double>();
    if (node["command"]) {
      c->command = node["command"].as<std::string>();
      std::error_code ec;
      const fs::path dir = fs::path(suite_file).parent_path();
      c->command_dir = fs::absolute(dir.empty() ? fs::path(".") : dir, ec).lexically_normal().string();
    }
    for (auto [key, field] : {std::pair{"scenario", &c->scenario},
                              {"recording", &c->recording},
                              {"config", &c->config},
                              {"calibration", &c->calibration},
                              {"calibrate", &c->calibrate},
                              {"data", &c->data}})
      if (node[key]) *field = ResolvePath(suite_file, node[key].as<std::string>());
    for (auto [key, field] : {std::pair{"train", &c->train}, {"test", &c->test}})
      if (node[key]) {
        if (!node[key].IsSequence() || node[key].size() == 0)
          return ctx.Error(node[key], std::string("'") + key + "' is a non-empty list of paths or globs");
        for (const YAML::Node& entry : node[key])
          field->push_back(ResolvePath(c->data.empty() ? suite_file : c->data + "/.", entry.as<std::string>()));
      }
  } catch (const YAML::Exception& e) {
    return ctx.Error(node, std::string("malformed value: ") + e.msg);
  }
  if (node["runs"] && c->runs < 1) return ctx.Error(node["runs"], "runs must be at least 1");
  if (c->t0_s && !InRange(*c->t0_s)) return ctx.Error(node["t0_s"], "t0_s must be finite, |t0_s| <= 1e9");
  if (c->interval_s && !(*c->interval_s > 0.0 && InRange(*c->interval_s)))
    return ctx.Error(node["interval_s"], "interval_s must be positive and at most 1e9");
  if (node["command"] && c->command.find_first_not_of(" \t") == std::string::npos)
    return ctx.Error(node["command"], "the estimator command is empty");
  if (c->timeout_s && !(*c->timeout_s > 0.0 && *c->timeout_s <= kMaxTimeoutS))
    return ctx.Error(node["timeout_s"], "timeout_s must be positive and at most 1e6 s");
  return Status::Ok();
}

// Effects hidden in a simulated recording (diagnose): names and parameters the simulator knows.
Status LoadEffects(const YAML::Node& effects, const Context& ctx, Case* c) {
  if (!effects) return Status::Ok();
  if (!effects.IsSequence()) return ctx.Error(effects, "'effects' is a list of {name: EFFECT, PARAMETER: value}");
  for (const YAML::Node& effect : effects) {
    if (!effect.IsMap() || !effect["name"] || !effect["name"].IsScalar())
      return ctx.Error(effect, "an effect is {name: EFFECT, PARAMETER: value, ...}");
    const std::string name = effect["name"].as<std::string>();
    const auto known = sim::KnownEffects().find(name);
    if (known == sim::KnownEffects().end()) {
      std::string list;
      for (const auto& [n, p] : sim::KnownEffects()) list += (list.empty() ? "" : ", ") + n;
      return ctx.Error(effect["name"], "unknown effect '" + name + "' (" + list + ")");
    }
    std::map<std::string, double> parameters;
    for (const auto& entry : effect) {
      const std::string key = entry.first.as<std::string>();
      if (key == "name") continue;
      if (!known->second.count(key)) return ctx.Error(entry.first, "effect " + name + " has no parameter " + key);
      try {
        parameters[key] = entry.second.as<double>();
      } catch (const YAML::Exception&) {
        return ctx.Error(entry.second, "effect parameter " + key + " is not a number");
      }
      if (!InRange(parameters[key]))
        return ctx.Error(entry.second, "effect parameter " + key + " is beyond any physical value (|value| <= 1e9)");
    }
    c->effects.emplace_back(name, parameters);
  }
  return Status::Ok();
}

// Sensor faults injected into the simulated recording (calibrate, track): as a scenario's `faults:` (sim/faults.h),
// checked against the case's scenario (its streams and duration).
Status LoadFaults(const YAML::Node& faults, const Context& ctx, InputFiles* inputs, Case* c) {
  if (!faults) return Status::Ok();
  if (!faults.IsSequence()) return ctx.Error(faults, "'faults' is a list of {type: FAULT, stream: NAME, ...}");
  if (c->scenario.empty()) return ctx.Error(faults, "'faults' need a 'scenario' to simulate");
  const Result<sim::Scenario>& scenario = inputs->Scenario(c->scenario);
  if (!scenario.ok()) return ctx.Error(faults, scenario.status().message());
  const std::vector<std::string> streams = scenario.value().StreamNames();
  for (const YAML::Node& node : faults) {
    if (!node.IsMap() || !node["type"] || !node["type"].IsScalar() || !node["stream"] || !node["stream"].IsScalar())
      return ctx.Error(node, "a fault is {type: FAULT, stream: NAME, KEY: value, ...}");
    sim::FaultOptions fault;
    fault.type = node["type"].as<std::string>();
    fault.stream = node["stream"].as<std::string>();
    const std::vector<std::string>& keys = sim::FaultKeys(fault.type);
    std::map<std::string, double*> fields = {{"fraction", &fault.fraction}, {"size", &fault.size},
                                             {"start_s", &fault.start_s},   {"duration_s", &fault.duration_s},
                                             {"at_s", &fault.at_s},         {"jump_s", &fault.jump_s}};
    for (const auto& entry : node) {
      const std::string key = entry.first.as<std::string>();
      if (key == "type" || key == "stream") continue;
      if (std::find(keys.begin(), keys.end(), key) == keys.end())
        return ctx.Error(entry.first, "fault " + fault.type + " has no key " + key);
      try {
        *fields.at(key) = entry.second.as<double>();
      } catch (const YAML::Exception&) {
        return ctx.Error(entry.second, "fault key " + key + " is not a number");
      }
    }
    for (const std::string& key : keys)
      if (!node[key]) return ctx.Error(node, "fault " + fault.type + " needs " + key);
    if (const auto problem = sim::CheckFault(fault, scenario.value().duration_s, streams))
      return ctx.Error(node, "fault " + problem->key + ": " + problem->message);
    c->faults.push_back(fault);
  }
  return Status::Ok();
}

// Odometry models (`roamlab odometry learn` options).
Status LoadOdometryModels(const YAML::Node& models, const Context& ctx, Case* c) {
  if (!models) return Status::Ok();
  if (!models.IsSequence() || models.size() == 0)
    return ctx.Error(models, "'models' is a non-empty list of {model: gp|linear|parametric, mean, kernel}");
  for (const YAML::Node& m : models) {
    if (!m.IsMap() || !m["model"]) return ctx.Error(m, "a model is {model: gp|linear|parametric[, mean, kernel]}");
    Case::OdometryModel model;
    for (const auto& entry : m) {
      const std::string key = entry.first.as<std::string>();
      const std::string value = entry.second.IsScalar() ? entry.second.as<std::string>() : "";
      const bool ok = key == "model"    ? (value == "gp" || value == "linear" || value == "parametric")
                      : key == "mean"   ? (value == "zero" || value == "linear")
                      : key == "kernel" ? (value == "rbf" || value == "linear" || value == "rbf+linear")
                                        : false;
      if (!ok)
        return ctx.Error(entry.first, "bad model entry '" + key + ": " + value +
                                          "' (model: gp|linear|parametric, mean: zero|linear, kernel: rbf|linear|"
                                          "rbf+linear)");
      (key == "model" ? model.model : key == "mean" ? model.mean : model.kernel) = value;
    }
    if (model.model != "gp" && (!model.mean.empty() || !model.kernel.empty()))
      return ctx.Error(m, "mean and kernel are options of the gp model only");
    c->models.push_back(model);
  }
  return Status::Ok();
}

// Inputs exist and load (a case's `data` may be absent: the case is then skipped, and its inputs are not checked);
// `names` receives the parameter and stream names of the case's configuration.
Status CheckInputs(const YAML::Node& node, const Context& ctx, const Case& c, InputFiles* inputs, Names* names) {
  const bool data_absent = !c.data.empty() && !fs::is_directory(c.data);
  if (!c.scenario.empty()) {
    if (!fs::is_regular_file(c.scenario)) return ctx.Error(node["scenario"], "missing scenario " + c.scenario);
    const Result<sim::Scenario>& scenario = inputs->Scenario(c.scenario);
    if (!scenario.ok()) return ctx.Error(node["scenario"], "bad scenario: " + scenario.status().message());
  }
  if (!c.recording.empty() && !data_absent && !fs::is_regular_file(fs::path(c.recording) / "recording.yaml"))
    return ctx.Error(node["recording"], "missing recording " + c.recording + " (no recording.yaml)");
  if (!c.config.empty()) {
    const Result<estimator::EstimatorConfig>& config = inputs->Config(c.config);
    if (!config.ok()) return ctx.Error(node["config"], "bad config: " + config.status().message());
    *names = NamesOf(config.value());
  }
  if (!c.calibrate.empty()) {
    const Result<estimator::EstimatorConfig>& config = inputs->Config(c.calibrate);
    if (!config.ok()) return ctx.Error(node["calibrate"], "bad config: " + config.status().message());
  }
  if (!c.calibration.empty()) {
    const auto values = estimator::ReadCalibrationValues(c.calibration);
    if (!values.ok()) return ctx.Error(node["calibration"], "bad calibration: " + values.status().message());
  }
  return Status::Ok();
}

// One check: a metric path with a bound (and the bound's reference metric) or, for a text, `equals`.
Result<Check> LoadCheck(const YAML::Node& check, const Context& ctx, const ModeSpec& mode, const Names& names) {
  const bool is_map = check.IsMap() && check["metric"] && check["metric"].IsScalar();
  const bool one_test = is_map && (static_cast<bool>(check["bound"]) != static_cast<bool>(check["equals"]));
  const std::size_t keys = 2 + (is_map && check["open"] ? 1 : 0);
  if (!is_map || !one_test || check.size() != keys)
    return ctx.Error(check,
                     "a check is {metric: PATH, bound: BOUND} or {metric: PATH, equals: TEXT}, "
                     "optionally with open: REASON, and nothing else");
  Check k;
  k.line = check.Mark().line + 1;
  auto metric = ParseMetricPath(check["metric"].as<std::string>(), mode, names);
  if (!metric.ok()) return ctx.Error(check["metric"], metric.status().message());
  k.metric = std::move(metric).value();
  if (check["open"]) {
    k.open = check["open"].IsScalar() ? check["open"].as<std::string>() : "";
    if (k.open.empty()) return ctx.Error(check["open"], "'open' needs the reason the target is not met yet");
  }
  if (check["equals"]) {
    if (!k.metric.is_string)
      return ctx.Error(check["equals"], "metric '" + k.metric.text + "' is a number: give a bound, not 'equals'");
    if (!check["equals"].IsScalar()) return ctx.Error(check["equals"], "'equals' takes one text");
    k.equals = check["equals"].as<std::string>();
    return k;
  }
  if (k.metric.is_string)
    return ctx.Error(check["bound"], "metric '" + k.metric.text + "' is a text: check it with 'equals: TEXT'");
  auto bound = ParseBound(check["bound"].as<std::string>());
  if (!bound.ok()) return ctx.Error(check["bound"], bound.status().message());
  k.bound = std::move(bound).value();
  if (!k.bound.reference.empty()) {
    auto reference = ParseMetricPath(k.bound.reference, mode, names);
    if (!reference.ok())
      return ctx.Error(check["bound"], "bound '" + k.bound.text + "': " + reference.status().message());
    if (reference.value().is_string)
      return ctx.Error(check["bound"], "bound '" + k.bound.text + "': '" + k.bound.reference + "' is a text");
    k.reference = std::move(reference).value();
  }
  return k;
}

// Loads and validates one case; `seen` holds the names of the cases before it.
Result<Case> LoadCase(const YAML::Node& node, const Context& suite, std::set<std::string>* seen, InputFiles* inputs) {
  Context ctx = suite;
  Case c;
  const Result<const ModeSpec*> mode = LoadNameAndMode(node, &ctx, seen, &c);
  if (!mode.ok()) return mode.status();
  Status st = CheckKeys(node, ctx, *mode.value());
  if (st.ok()) st = LoadValues(node, ctx, suite.file, &c);
  if (st.ok()) st = LoadEffects(node["effects"], ctx, &c);
  if (st.ok()) st = LoadFaults(node["faults"], ctx, inputs, &c);
  if (st.ok()) st = LoadOdometryModels(node["models"], ctx, &c);
  Names names;
  if (st.ok()) st = CheckInputs(node, ctx, c, inputs, &names);
  if (!st.ok()) return st;

  const YAML::Node checks = node["checks"];
  if (!checks || !checks.IsSequence() || checks.size() == 0)
    return ctx.Error(node, "no 'checks' (a list of {metric: PATH, bound: \"<= 0.5\"})");
  for (const YAML::Node& check : checks) {
    Result<Check> k = LoadCheck(check, ctx, *mode.value(), names);
    if (!k.ok()) return k.status();
    if (!c.command.empty() && k.value().metric.output == "summary")
      return ctx.Error(check, "metric '" + k.value().metric.text +
                                  "': an external command writes no summary.json (its case writes metrics)");
    c.checks.push_back(std::move(k).value());
  }
  return c;
}

}  // namespace

bool Bound::Holds(double value, double threshold) const {
  if (std::isnan(value) || std::isnan(threshold)) return false;
  switch (comparator) {
    case Comparator::kLess:
      return value < threshold;
    case Comparator::kLessEqual:
      return value <= threshold;
    case Comparator::kGreater:
      return value > threshold;
    case Comparator::kGreaterEqual:
      return value >= threshold;
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
  if (first && !InRange(*first)) return Status::Error(prefix + "a number beyond any metric (|value| <= 1e9)");
  if (first && !s.Accept("*")) {
    b.offset = *first;
    if (!s.AtEnd()) return Status::Error(prefix + "unexpected '" + s.Rest() + "' after the number");
    return b;
  }
  const std::string reference = s.Path();
  if (reference.empty() || (reference != "baseline" && reference.find('.') == std::string::npos))
    return Status::Error(prefix + (first ? "expected 'baseline' or a metric after '*'"
                                         : "expected a number, 'baseline', a metric or 'K * baseline' after the "
                                           "comparator"));
  if (reference == "baseline") {
    b.uses_baseline = true;
  } else {
    b.reference = reference;
  }
  b.scale = first.value_or(1.0);
  if (s.AtEnd()) return b;
  const bool plus = s.Accept("+");
  if (!plus && !s.Accept("-")) return Status::Error(prefix + "unexpected '" + s.Rest() + "' after '" + reference + "'");
  const std::optional<double> d = s.Number();
  if (!d) return Status::Error(prefix + "expected a number after '" + (plus ? "+" : "-") + "'");
  if (!InRange(*d)) return Status::Error(prefix + "a number beyond any metric (|value| <= 1e9)");
  b.offset = plus ? *d : -*d;
  if (!s.AtEnd()) return Status::Error(prefix + "unexpected '" + s.Rest() + "' at the end");
  return b;
}

namespace {

// Whether `row` matches every FIELD=VALUE of the selector (a null field matches "null").
bool Matches(const json& row, const Selector& selector) {
  for (const auto& [field, value] : selector) {
    if (!row.is_object() || !row.contains(field)) return false;
    const json& x = row[field];
    if (!(x.is_string() && x.get<std::string>() == value) && !(x.is_null() && value == "null")) return false;
  }
  return true;
}

// Where a metric path leads in an output: the node, or for the last key of an array of objects that column.
struct Walked {
  const json* node = nullptr;
  std::vector<double> column;
  bool is_column = false;
  bool relative = false;  // the derived relative_error of the parameter row `node`
  std::string where;
};

Result<Walked> Walk(const json& output, const MetricPath& path) {
  Walked w;
  w.node = &output;
  w.where = path.output;
  for (std::size_t i = 0; i < path.keys.size(); ++i) {
    const std::string& key = path.keys[i];
    const json* node = w.node;
    if (node->is_array() && i + 1 == path.keys.size() && !path.select.count(i)) {
      // The last key of an array of objects: that column, reduced below.
      for (const json& row : *node) {
        if (!row.is_object() || !row.contains(key) || !row[key].is_number())
          return Status::Error(w.where + "[]." + key + ": missing or not a number in a row");
        w.column.push_back(row[key].get<double>());
      }
      if (w.column.empty()) return Status::Error(w.where + " is empty");
      w.is_column = true;
      w.where += "[]." + key;
      return w;
    }
    if (key == "relative_error" && i + 1 == path.keys.size() && node->is_object() && !node->contains(key)) {
      w.relative = true;
      return w;
    }
    if (!node->is_object() || !node->contains(key)) return Status::Error(w.where + " has no key '" + key + "'");
    w.node = &(*node)[key];
    w.where += "." + key;
    const auto select = path.select.find(i);
    if (select == path.select.end()) continue;
    if (!w.node->is_array()) return Status::Error(w.where + " is not an array (no row to select)");
    std::string selector;
    for (const auto& [field, value] : select->second) selector += (selector.empty() ? "" : ",") + field + "=" + value;
    const json* row = nullptr;
    int matches = 0;
    for (const json& r : *w.node)
      if (Matches(r, select->second)) {
        row = &r;
        ++matches;
      }
    if (matches != 1)
      return Status::Error(w.where + ": " + std::to_string(matches) + " rows match [" + selector + "] (one needed)");
    w.node = row;
    w.where += "[" + selector + "]";
  }
  return w;
}

}  // namespace

Result<double> ResolveMetric(const json& output, const MetricPath& path) {
  Result<Walked> walked = Walk(output, path);
  if (!walked.ok()) return walked.status();
  Walked& w = walked.value();
  if (w.relative) return RelativeError(*w.node, w.where);
  if (path.reduction.empty()) {
    if (w.is_column) return Status::Error(w.where + " is a column: it needs a reduction");
    if (w.node->is_null()) return Status::Error(w.where + " is null (not a number)");
    if (!w.node->is_number()) return Status::Error(w.where + " is not a number");
    return w.node->get<double>();
  }
  if (!w.is_column) {
    auto v = Numbers(*w.node, w.where);
    if (!v.ok()) return v.status();
    w.column = std::move(v).value();
  }
  if (IsIndex(path.reduction)) {
    const std::size_t index = std::stoul(path.reduction);
    if (index >= w.column.size())
      return Status::Error(w.where + " has " + std::to_string(w.column.size()) + " elements, no index " +
                           path.reduction);
    return w.column[index];
  }
  return Reduce(w.column, path.reduction);
}

Result<std::string> ResolveText(const json& output, const MetricPath& path) {
  const Result<Walked> w = Walk(output, path);
  if (!w.ok()) return w.status();
  if (w.value().is_column || !w.value().node->is_string()) return Status::Error(w.value().where + " is not a text");
  return w.value().node->get<std::string>();
}

namespace {

Result<Suite> ReadSuite(const std::string& path) {
  Suite suite;
  suite.file = path;
  if (!fs::is_regular_file(path)) return Status::Error(path + ": cannot open the suite file");
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    return Status::Error(path + ":" + std::to_string(e.mark.line + 1) + ": not valid YAML: " + e.msg);
  }
  if (const std::string problem = DuplicateKeyProblem(root); !problem.empty())
    return Status::Error(path + ":" + problem);
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
  if (!cases || !cases.IsSequence() || cases.size() == 0) return Status::Error(path + ": no 'cases' (a list of cases)");
  std::set<std::string> seen;
  InputFiles inputs;
  for (const YAML::Node& node : cases) {
    try {
      auto c = LoadCase(node, ctx, &seen, &inputs);
      if (!c.ok()) return c.status();
      suite.cases.push_back(std::move(c).value());
    } catch (const YAML::Exception& e) {
      return Status::Error(path + ":" + std::to_string(e.mark.line + 1) + ": malformed case: " + e.msg);
    }
  }
  return suite;
}

}  // namespace

// Every field is read with its kind checked; a node of another kind that reaches yaml-cpp's conversion anyway (a key
// that is a map or a list, say) is one line naming the file and the line, not an exception.
Result<Suite> LoadSuite(const std::string& path) {
  try {
    return ReadSuite(path);
  } catch (const YAML::Exception& e) {
    const std::string line = e.mark.line >= 0 ? std::to_string(e.mark.line + 1) + ":" : "";
    return Status::Error(path + ":" + line + " a key or value of the wrong kind (" + e.msg + ")");
  }
}

}  // namespace roamlab::regress
