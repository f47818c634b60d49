#include "estimator/config.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "common/yaml_keys.h"
#include "estimator/model_registry.h"

namespace roamlab::estimator {
namespace {

// Errors carry "file:line: message".
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Every number of the configuration is at most this in magnitude; standard deviations lie in [kMinSigma, kMaxSigma].
constexpr double kMaxMagnitude = 1e9;
constexpr double kMinSigma = 1e-9;
constexpr double kMaxSigma = 1e6;

class Parser {
 public:
  explicit Parser(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void Fail(const YAML::Node& node, const std::string& message) const {
    std::ostringstream s;
    s << file_;
    if (node.Mark().line >= 0) s << ":" << node.Mark().line + 1;
    s << ": " << message;
    throw ConfigError(s.str());
  }

  void CheckKeys(const YAML::Node& map, const std::set<std::string>& allowed, const std::string& where) const {
    if (!map.IsMap()) Fail(map, where + " must be a mapping");
    for (const auto& kv : map) {
      const std::string key = kv.first.as<std::string>();
      if (allowed.count(key) == 0) Fail(kv.first, "unknown key '" + key + "' in " + where);
    }
  }

  // A finite number of magnitude at most kMaxMagnitude; with `allow_inf`, +Inf too (prior_sigma's "no prior").
  double Number(const YAML::Node& node, const std::string& what, bool allow_inf = false) const {
    double value = 0.0;
    try {
      value = node.as<double>();
    } catch (const YAML::Exception&) {
      Fail(node, what + " must be a number");
    }
    if (allow_inf && value == std::numeric_limits<double>::infinity()) return value;
    if (!std::isfinite(value)) Fail(node, what + " must be a finite number, not '" + node.Scalar() + "'");
    if (std::abs(value) > kMaxMagnitude)
      Fail(node, what + ": " + node.Scalar() + " is beyond the physical range (|value| <= 1e9)");
    return value;
  }

  std::string String(const YAML::Node& node, const std::string& what) const {
    if (!node.IsScalar()) Fail(node, what + " must be a string");
    return node.as<std::string>();
  }

  // The value of `node` among `choices` (name, value); anything else fails naming them.
  template <typename T>
  T Choice(const YAML::Node& node, const std::string& what,
           const std::vector<std::pair<std::string, T>>& choices) const {
    const std::string given = String(node, what);
    std::string names;
    for (std::size_t i = 0; i < choices.size(); ++i) {
      if (choices[i].first == given) return choices[i].second;
      names += (i == 0 ? "" : i + 1 == choices.size() ? " or " : ", ") + choices[i].first;
    }
    Fail(node, what + " must be " + names + ", not '" + given + "'");
  }

  std::vector<double> Numbers(const YAML::Node& node, const std::string& what, bool allow_inf = false) const {
    std::vector<double> out;
    if (node.IsScalar()) return {Number(node, what, allow_inf)};
    if (!node.IsSequence()) Fail(node, what + " must be a number or a list of numbers");
    for (const auto& item : node) out.push_back(Number(item, what, allow_inf));
    return out;
  }

  // A standard deviation in [kMinSigma, kMaxSigma] (its square, the variance, stays a normal double).
  double Sigma(const YAML::Node& node, const std::string& what) const {
    const double sigma = Number(node, what);
    if (!(sigma >= kMinSigma && sigma <= kMaxSigma))
      Fail(node, what + ": " + node.Scalar() + " is outside the accepted range [1e-9, 1e6] of a standard deviation");
    return sigma;
  }

  // A process setting of a 3-vector parameter: one number for every component, or a list of three.
  Eigen::Vector3d PerComponent(const YAML::Node& node, const std::string& what) const {
    const std::vector<double> v = Numbers(node, what);
    if (v.size() == 1) return Eigen::Vector3d::Constant(v[0]);
    if (v.size() != 3) Fail(node, what + " must be a number or a list of 3 numbers (one per component)");
    return Eigen::Vector3d(v[0], v[1], v[2]);
  }

  bool Bool(const YAML::Node& node, const std::string& what) const {
    try {
      return node.as<bool>();
    } catch (const YAML::Exception&) {
      Fail(node, what + " must be true or false");
    }
  }

  void ParseSolver(const YAML::Node& n, SolverOptions* s) const {
    CheckKeys(n,
              {"method", "max_iterations", "function_tolerance", "step_tolerance", "time_budget_s", "initial_lambda",
               "damping"},
              "solver");
    using Method = SolverOptions::Method;
    if (n["method"])
      s->method = Choice<Method>(n["method"], "solver.method",
                                 {{"gauss_newton", Method::kGaussNewton},
                                  {"levenberg_marquardt", Method::kLevenbergMarquardt}});
    if (n["max_iterations"]) s->max_iterations = static_cast<int>(Number(n["max_iterations"], "max_iterations"));
    if (n["function_tolerance"]) s->function_tolerance = Number(n["function_tolerance"], "function_tolerance");
    if (n["step_tolerance"]) s->step_tolerance = Number(n["step_tolerance"], "step_tolerance");
    if (n["time_budget_s"]) s->time_budget_s = Number(n["time_budget_s"], "time_budget_s");
    if (n["initial_lambda"]) s->initial_lambda = Number(n["initial_lambda"], "initial_lambda");
    using Damping = SolverOptions::Damping;
    if (n["damping"])
      s->damping = Choice<Damping>(n["damping"], "solver.damping",
                                   {{"all", Damping::kAll}, {"parameters", Damping::kParameters}});
    const std::string problem = s->Validate();
    if (!problem.empty()) Fail(n, "solver: " + problem);
  }

  void ParseTracking(const YAML::Node& n, TrackingConfig* t) const {
    CheckKeys(n,
              {"window", "max_iterations", "improvement_threshold", "time_budget_s", "initialization_s",
               "calibration_prior", "calibrate", "relinearize_threshold"},
              "tracking");
    if (n["calibration_prior"]) t->calibration_prior = Bool(n["calibration_prior"], "tracking.calibration_prior");
    if (n["calibrate"]) {
      const std::string path = String(n["calibrate"], "tracking.calibrate");
      if (path.empty()) Fail(n["calibrate"], "tracking.calibrate must name a configuration file");
      t->calibrate = (std::filesystem::path(file_).parent_path() / path).lexically_normal().string();
    }
    if (n["window"]) t->window = static_cast<int>(Number(n["window"], "tracking.window"));
    if (n["max_iterations"]) t->max_iterations = static_cast<int>(Number(n["max_iterations"], "max_iterations"));
    if (n["improvement_threshold"])
      t->improvement_threshold = Number(n["improvement_threshold"], "improvement_threshold");
    if (n["time_budget_s"]) t->time_budget_s = Number(n["time_budget_s"], "time_budget_s");
    if (n["initialization_s"]) t->initialization_s = Number(n["initialization_s"], "initialization_s");
    if (n["relinearize_threshold"])
      t->relinearize_threshold = Number(n["relinearize_threshold"], "tracking.relinearize_threshold");
    if (t->window < 3) Fail(n, "tracking.window must be at least 3 poses");
    if (t->max_iterations < 1) Fail(n, "tracking.max_iterations must be at least 1");
    if (!(t->time_budget_s > 0.0)) Fail(n, "tracking.time_budget_s must be positive");
    if (!(t->initialization_s >= 0.0)) Fail(n, "tracking.initialization_s must be >= 0");
    if (!(t->relinearize_threshold >= 0.0)) Fail(n, "tracking.relinearize_threshold must be >= 0");
  }

  // `roamlab design`'s target for every tangent component of a free parameter: a standard deviation.
  double TargetStd(const std::string& name, const YAML::Node& node, bool free) const {
    if (!free) Fail(node, "parameter '" + name + "': target_std is for a free parameter (free: true)");
    if (!node.IsScalar()) Fail(node, "parameters." + name + ".target_std must be one number (every component's std)");
    const double target = Number(node, "parameters." + name + ".target_std");
    if (!(target >= kMinSigma && target <= kMaxSigma))
      Fail(node, "parameters." + name + ".target_std: " + node.Scalar() +
                     " is outside the accepted range [1e-9, 1e6] of a standard deviation");
    return target;
  }

  ParameterConfig ParseParameter(const std::string& name, const YAML::Node& n) const {
    CheckKeys(n, {"value", "free", "process", "prior_sigma", "target_std"}, "parameter '" + name + "'");
    ParameterConfig p;
    if (n["value"]) {
      const std::vector<double> v = Numbers(n["value"], "parameters." + name + ".value");
      p.value = Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<int>(v.size()));
    }
    if (n["free"]) p.free = Bool(n["free"], "parameters." + name + ".free");
    if (n["prior_sigma"]) {
      const std::vector<double> v = Numbers(n["prior_sigma"], "parameters." + name + ".prior_sigma", true);
      for (double sigma : v)
        if (!(sigma >= kMinSigma))
          Fail(n["prior_sigma"], "parameter '" + name + "': prior_sigma must be at least 1e-9 (or .inf)");
      p.prior_sigma = Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<int>(v.size()));
    }
    if (n["target_std"]) p.target_std = TargetStd(name, n["target_std"], p.free);
    if (n["process"]) {
      const YAML::Node& pr = n["process"];
      CheckKeys(pr, {"type", "sigma", "tau_s", "interval_s"}, "parameter '" + name + "' process");
      const std::string type = pr["type"] ? String(pr["type"], "process.type") : "";
      if (type == "random_walk") {
        p.process.type = ProcessConfig::Type::kRandomWalk;
      } else if (type == "gauss_markov") {
        p.process.type = ProcessConfig::Type::kGaussMarkov;
        if (!pr["tau_s"]) Fail(pr, "parameter '" + name + "': gauss_markov needs tau_s");
        p.process.tau_s = PerComponent(pr["tau_s"], "parameters." + name + ".process.tau_s");
        if (!(p.process.tau_s.array() > 0).all()) Fail(pr, "parameter '" + name + "': tau_s must be positive");
      } else if (type != "constant") {
        Fail(pr, "parameter '" + name + "': process.type must be constant, random_walk or gauss_markov, not '" + type +
                     "'");
      }
      if (p.process.type != ProcessConfig::Type::kConstant) {
        if (!pr["sigma"]) Fail(pr, "parameter '" + name + "': process needs sigma");
        p.process.sigma = PerComponent(pr["sigma"], "parameters." + name + ".process.sigma");
        if (!(p.process.sigma.array() >= kMinSigma).all() || !(p.process.sigma.array() <= kMaxSigma).all())
          Fail(pr, "parameter '" + name + "': process sigma must be in [1e-9, 1e6]");
      }
      if (pr["interval_s"]) {
        if (p.process.type == ProcessConfig::Type::kConstant)
          Fail(pr["interval_s"], "parameter '" + name +
                                     "': process.interval_s needs a random_walk or gauss_markov "
                                     "process");
        p.process.interval_s = Number(pr["interval_s"], "parameters." + name + ".process.interval_s");
        if (!(p.process.interval_s > 0.0) || !std::isfinite(p.process.interval_s))
          Fail(pr["interval_s"], "parameter '" + name + "': process.interval_s must be a positive number of seconds");
      }
    }
    return p;
  }

  StreamConfig ParseStream(const std::string& name, const YAML::Node& n) const {
    const std::string where = "stream '" + name + "'";
    CheckKeys(n, {"model", "source", "noise", "parameters", "options", "inputs", "loss", "gate"}, where);
    StreamConfig s;
    if (!n["model"]) Fail(n, where + ": missing key 'model'");
    s.model = String(n["model"], where + ".model");
    const ModelSpec* spec = FindModelSpec(s.model);
    if (spec == nullptr) {
      std::string known;
      for (const std::string& model : ErrorModelNames()) known += (known.empty() ? "" : ", ") + model;
      Fail(n["model"], where + ": unknown model '" + s.model + "' (registered: " + known + ")");
    }

    // Sources: a stream name, or a role -> stream mapping.
    if (!n["source"]) Fail(n, where + ": missing key 'source'");
    if (spec->source_roles.size() == 1 && spec->source_roles[0].empty()) {
      s.sources[""] = String(n["source"], where + ".source");
    } else {
      std::set<std::string> roles(spec->source_roles.begin(), spec->source_roles.end());
      CheckKeys(n["source"], roles, where + " source");
      for (const std::string& role : spec->source_roles) {
        if (!n["source"][role]) Fail(n["source"], where + ": source needs '" + role + "'");
        s.sources[role] = String(n["source"][role], where + ".source." + role);
      }
    }

    // Noise: every key of the model, positive.
    if (!n["noise"]) Fail(n, where + ": missing key 'noise'");
    CheckKeys(n["noise"], {spec->noise_keys.begin(), spec->noise_keys.end()}, where + " noise");
    for (const std::string& key : spec->noise_keys) {
      if (!n["noise"][key]) Fail(n["noise"], where + ": noise needs '" + key + "'");
      s.noise[key] = Sigma(n["noise"][key], where + ".noise." + key);
    }

    if (n["parameters"]) {
      std::set<std::string> slots;
      for (const SlotSpec& slot : spec->slots) slots.insert(slot.name);
      CheckKeys(n["parameters"], slots, where + " parameters");
      for (const auto& kv : n["parameters"])
        s.parameters[kv.first.as<std::string>()] = String(kv.second, where + " parameter name");
    }
    if (n["options"]) {
      CheckKeys(n["options"], {spec->option_keys.begin(), spec->option_keys.end()}, where + " options");
      for (const auto& kv : n["options"]) s.options[kv.first.as<std::string>()] = Numbers(kv.second, where + " option");
    }
    if (n["inputs"]) {
      CheckKeys(n["inputs"], {spec->input_roles.begin(), spec->input_roles.end()}, where + " inputs");
      for (const auto& kv : n["inputs"])
        s.inputs[kv.first.as<std::string>()] = String(kv.second, where + ".inputs." + kv.first.as<std::string>());
    }
    if (n["loss"]) {
      const YAML::Node& l = n["loss"];
      CheckKeys(l, {"type", "scale"}, where + " loss");
      const std::string type = l["type"] ? String(l["type"], "loss.type") : "none";
      const double scale = l["scale"] ? Number(l["scale"], "loss.scale") : 1.0;
      if (!(scale > 0.0)) Fail(l, where + ": loss scale must be positive");
      if (type == "huber") {
        s.loss = Loss::Huber(scale);
      } else if (type == "cauchy") {
        s.loss = Loss::Cauchy(scale);
      } else if (type != "none") {
        Fail(l, where + ": loss type must be none, huber or cauchy, not '" + type + "'");
      }
    }
    if (n["gate"]) s.gated = Bool(n["gate"], where + ".gate");
    return s;
  }

  // A name a stream's `parameters:` maps a slot to must be declared under `parameters:`, be shared by several slots,
  // or be a default name "<stream>.<slot>" of a configured stream: a name used once and declared nowhere is a typo
  // that would silently give the slot a parameter of its own at the model default.
  void CheckParameterNames(const YAML::Node& root, const EstimatorConfig& c) const {
    std::map<std::string, int> uses;
    std::set<std::string> defaults;
    for (const auto& [stream, sc] : c.streams) {
      for (const auto& [slot, pname] : sc.parameters) ++uses[pname];
      for (const SlotSpec& slot : FindModelSpec(sc.model)->slots) defaults.insert(stream + "." + slot.name);
    }
    for (const auto& [stream, sc] : c.streams)
      for (const auto& [slot, pname] : sc.parameters) {
        if (c.parameters.count(pname) > 0 || uses[pname] > 1 || defaults.count(pname) > 0) continue;
        Fail(root["streams"][stream]["parameters"][slot],
             "stream '" + stream + "': slot '" + slot + "' names parameter '" + pname +
                 "', which no parameters: entry declares and no other slot shares (a typo?)");
      }
  }

  // The IMU master's checks and its poses key (PosesConfig).
  void ParseImuMaster(const YAML::Node& root, EstimatorConfig* c) const {
    const bool imu_master = c->streams.at(c->master).model == "gyroscope";
    if (!imu_master) {
      if (root["poses"]) Fail(root["poses"], "poses is for an IMU master (a gyroscope stream as master) only");
      return;
    }
    bool accelerometer = false;
    for (const auto& [name, sc] : c->streams) accelerometer = accelerometer || sc.model == "accelerometer";
    if (!accelerometer)
      Fail(root["master"], "master stream '" + c->master +
                               "' is a gyroscope (IMU master), which needs an accelerometer stream to place the poses");
    if (!root["poses"]) return;
    const YAML::Node& n = root["poses"];
    CheckKeys(n, {"rate_hz", "position_sigma_m"}, "poses");
    if (n["rate_hz"]) {
      c->poses.rate_hz = Number(n["rate_hz"], "poses.rate_hz");
      if (!(c->poses.rate_hz > 0.0) || !std::isfinite(c->poses.rate_hz))
        Fail(n["rate_hz"], "poses.rate_hz must be a positive number of poses per second");
    }
    if (n["position_sigma_m"]) {
      c->poses.position_sigma_m = Number(n["position_sigma_m"], "poses.position_sigma_m");
      if (!(c->poses.position_sigma_m >= kMinSigma && c->poses.position_sigma_m <= kMaxSigma))
        Fail(n["position_sigma_m"], "poses.position_sigma_m must be a number of metres in [1e-9, 1e6]");
    }
  }

  EstimatorConfig Parse(const YAML::Node& root) const {
    EstimatorConfig c;
    c.source_file = file_;
    CheckKeys(root, {"master", "poses", "solver", "gating", "tracking", "parameters", "streams", "stages"},
              "the configuration");
    if (!root["master"]) Fail(root, "missing key 'master'");
    if (!root["streams"]) Fail(root, "missing key 'streams'");
    c.master = String(root["master"], "master");
    if (root["solver"]) ParseSolver(root["solver"], &c.solver);
    if (root["tracking"]) ParseTracking(root["tracking"], &c.tracking);
    if (root["gating"]) {
      CheckKeys(root["gating"], {"probability", "robust_start"}, "gating");
      const double p = Number(root["gating"]["probability"], "gating.probability");
      if (!(p > 0.0 && p < 1.0)) Fail(root["gating"], "gating.probability must be in (0, 1)");
      c.gate_probability = p;
      if (root["gating"]["robust_start"])
        c.gate_robust_start = Bool(root["gating"]["robust_start"], "gating.robust_start");
    }
    if (!root["streams"].IsMap()) Fail(root["streams"], "streams must be a mapping");
    for (const auto& kv : root["streams"]) {
      const std::string name = kv.first.as<std::string>();
      c.streams[name] = ParseStream(name, kv.second);
    }
    if (c.streams.count(c.master) == 0) Fail(root["master"], "master stream '" + c.master + "' is not in streams");
    const std::string& master_model = c.streams[c.master].model;
    if (!FindModelSpec(master_model)->odometric && master_model != "gyroscope")
      Fail(root["master"], "master stream '" + c.master +
                               "' must use an odometric model (ackermann, ackermann_seed, differential_drive, "
                               "omni3_drive, mecanum_drive, omni4_drive, tricycle_drive or odometer) or the gyroscope "
                               "model (IMU master)");
    ParseImuMaster(root, &c);
    if (root["parameters"]) {
      if (!root["parameters"].IsMap()) Fail(root["parameters"], "parameters must be a mapping");
      for (const auto& kv : root["parameters"]) {
        const std::string name = kv.first.as<std::string>();
        c.parameters[name] = ParseParameter(name, kv.second);
      }
    }
    CheckParameterNames(root, c);
    if (root["stages"]) {
      for (const auto& stage : root["stages"]) {
        std::vector<std::string> names;
        for (const auto& item : stage) names.push_back(String(item, "stage entry"));
        c.stages.push_back(names);
      }
    }
    return c;
  }

 private:
  std::string file_;
};

}  // namespace

Result<EstimatorConfig> ParseEstimatorConfig(const std::string& yaml_text, const std::string& source_name) {
  try {
    const YAML::Node root = YAML::Load(yaml_text);
    if (const std::string problem = DuplicateKeyProblem(root); !problem.empty())
      return Status::Error(source_name + ":" + problem);
    Parser parser(source_name);
    if (!root.IsMap()) return Status::Error(source_name + ": the configuration must be a YAML mapping");
    return parser.Parse(root);
  } catch (const ConfigError& e) {
    return Status::Error(e.what());
  } catch (const YAML::Exception& e) {
    return Status::Error(source_name + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
}

std::set<std::string> StreamsRead(const EstimatorConfig& config) {
  std::set<std::string> read;
  for (const auto& [name, stream] : config.streams) {
    for (const auto& [role, source] : stream.sources) read.insert(source);
    for (const auto& [role, source] : stream.inputs) read.insert(source);
  }
  return read;
}

Result<EstimatorConfig> LoadEstimatorConfig(const std::string& path) {
  std::ifstream in(path);
  if (!in) return Status::Error(path + ": cannot open the estimator configuration");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return ParseEstimatorConfig(buffer.str(), path);
}

}  // namespace roamlab::estimator
