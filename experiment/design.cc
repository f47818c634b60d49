#include "experiment/design.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <limits>
#include <sstream>
#include <utility>

#include <yaml-cpp/yaml.h>

#include "common/atomic_file.h"
#include "common/json.h"
#include "estimator/config.h"
#include "estimator/information.h"
#include "sim/drive_envelope.h"
#include "sim/simulator.h"

namespace roamlab::experiment {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = 3.14159265358979323846;
constexpr double kDegPerRad = 180.0 / kPi;
constexpr double kInfinity = std::numeric_limits<double>::infinity();
// Lateral acceleration samples: speed x yaw rate of O between true poses this far apart [s].
constexpr double kLateralStepS = 0.1;
// The longest designed drive [s].
constexpr double kMaxDurationS = 3600.0;
// The pattern search's first and last step in the normalized coordinates.
constexpr double kFirstStep = 0.2;
constexpr double kLastStep = 0.02;

// A number as the designed scenario writes it: the rounded value's shortest form (yaml-cpp would write 17 digits).
std::string Text(double value) {
  std::ostringstream out;
  out << std::setprecision(10) << value;
  return out.str();
}

// Largest speed x |yaw rate| of O between true poses kLateralStepS apart [m/s^2].
double MaxLateralAcceleration(const Trajectory& truth) {
  double out = 0.0;
  std::size_t a = 0;
  for (std::size_t b = 1; b < truth.size(); ++b) {
    const double dt = SecondsBetween(truth[a].t, truth[b].t);
    if (dt < kLateralStepS - 1e-9) continue;
    const Eigen::AngleAxisd turn(truth[a].q_world_body.conjugate() * truth[b].q_world_body);
    const double yaw_rate = std::abs((turn.angle() * turn.axis()).z()) / dt;
    const double speed = (truth[b].p_world_body - truth[a].p_world_body).norm() / dt;
    out = std::max(out, speed * yaw_rate);
    a = b;
  }
  return out;
}

// The body_velocity drivers' horizontal set-point of O at time t [s] (driver.linear_mps, driver.lateral_mps among the
// drive's profiles); false for a drive without them (ackermann).
bool SetPoint(const std::vector<std::pair<std::string, sim::Profile>>& profiles, double t_s, Eigen::Vector2d* v_mps) {
  bool found = false;
  *v_mps = Eigen::Vector2d::Zero();
  for (const auto& [key, profile] : profiles) {
    if (key == "linear_mps") {
      (*v_mps)[0] = profile.Evaluate(t_s);
      found = true;
    }
    if (key == "lateral_mps") (*v_mps)[1] = profile.Evaluate(t_s);
  }
  return found;
}

// Largest |horizontal velocity of O in its frame - its set-point| between true poses kLateralStepS apart, stamped at
// the middle (seconds since the first pose, the recording's t = 0) [m/s]; 0 for a drive without body-velocity
// set-points.
double MaxVelocityError(const Trajectory& truth, const std::vector<std::pair<std::string, sim::Profile>>& profiles) {
  double out = 0.0;
  Eigen::Vector2d set_point;
  if (truth.empty() || !SetPoint(profiles, 0.0, &set_point)) return 0.0;
  std::size_t a = 0;
  for (std::size_t b = 1; b < truth.size(); ++b) {
    const double dt = SecondsBetween(truth[a].t, truth[b].t);
    if (dt < kLateralStepS - 1e-9) continue;
    const Eigen::Quaterniond middle = truth[a].q_world_body.slerp(0.5, truth[b].q_world_body);
    const Eigen::Vector3d v_body = middle.conjugate() * (truth[b].p_world_body - truth[a].p_world_body) / dt;
    SetPoint(profiles, SecondsBetween(truth.front().t, truth[a].t) + 0.5 * dt, &set_point);
    out = std::max(out, (v_body.head<2>() - set_point).norm());
    a = b;
  }
  return out;
}

// The first limit the simulated drive exceeds, or empty.
std::string LimitExceeded(const DesignCandidate& c, const DesignLimits& l) {
  std::ostringstream why;
  if (c.max_roll_deg > l.max_roll_deg)
    why << "roll " << c.max_roll_deg << " deg > " << l.max_roll_deg;
  else if (c.max_pitch_deg > l.max_pitch_deg)
    why << "pitch " << c.max_pitch_deg << " deg > " << l.max_pitch_deg;
  else if (c.max_side_slip_mps > l.max_side_slip_mps)
    why << "side slip " << c.max_side_slip_mps << " m/s > " << l.max_side_slip_mps;
  else if (c.max_lateral_accel_mps2 > l.max_lateral_accel_mps2)
    why << "lateral acceleration " << c.max_lateral_accel_mps2 << " m/s^2 > " << l.max_lateral_accel_mps2;
  else if (c.max_velocity_error_mps > l.max_velocity_error_mps)
    why << "velocity error " << c.max_velocity_error_mps << " m/s > " << l.max_velocity_error_mps
        << " (a wall, an obstacle or slip)";
  return why.str();
}

// What every evaluation shares.
struct Problem {
  const DesignRequest& request;
  sim::Scenario scenario;  // with the designed duration
  estimator::EstimatorConfig config;
  std::map<std::string, double> targets;  // the request's, the configuration's target_std where not given
  DesignLimits limits;                    // the request's, the robot's where NaN
  std::unique_ptr<DriveFamily> family;    // the scenario's driver's
};

// Objective and per-component CRB std of one analysed drive.
void Score(const estimator::InformationResult& r, const std::map<std::string, double>& targets, DesignCandidate* c) {
  c->objective = 0.0;
  for (const estimator::InformationComponent& comp : r.components) {
    c->crb_std.emplace_back(comp.label, comp.crb_std);
    const auto target = targets.find(comp.parameter);
    if (target == targets.end()) continue;
    const double ratio = std::isfinite(comp.crb_std) ? comp.crb_std / target->second : kInfinity;
    if (ratio > c->objective || c->worst.empty()) {
      c->objective = ratio;
      c->worst = comp.label;
    }
  }
}

// Simulates and analyses one drive. Errors: an analysis that fails (the configuration does not fit the recording).
// An infeasible drive is a candidate with `infeasible` set.
Result<DesignCandidate> Evaluate(const Problem& p, const DriveDesign& drive, const std::string& stage) {
  const auto begin = std::chrono::steady_clock::now();
  DesignCandidate c;
  c.drive = drive;
  c.stage = stage;
  c.objective = kInfinity;
  sim::SimulateOptions options;
  options.noise = false;
  sim::Scenario simulated = WithDrive(*p.family, p.scenario, drive);
  simulated.DropUnreadCostlySensors(estimator::StreamsRead(p.config));
  auto simulation = sim::Simulate(simulated, options);
  auto seconds = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count(); };
  if (!simulation.ok()) {
    c.infeasible = simulation.status().message();
    c.seconds = seconds();
    return c;
  }
  const sim::Simulation& s = simulation.value();
  c.max_roll_deg = s.stats.max_abs_roll_rad * kDegPerRad;
  c.max_pitch_deg = s.stats.max_abs_pitch_rad * kDegPerRad;
  c.max_side_slip_mps = s.stats.max_lateral_speed_mps;
  c.distance_m = s.stats.distance_m;
  if (!s.recording.ground_truth || s.recording.ground_truth->empty())
    return Status::Error(p.request.scenario + ": the simulation wrote no ground truth");
  c.max_lateral_accel_mps2 = MaxLateralAcceleration(*s.recording.ground_truth);
  c.max_velocity_error_mps = MaxVelocityError(*s.recording.ground_truth, p.family->Profiles(drive));
  c.infeasible = LimitExceeded(c, p.limits);
  if (c.infeasible.empty()) {
    auto analysed =
        estimator::AnalyzeInformation(p.config, s.recording, s.truth.calibration, *s.recording.ground_truth);
    if (!analysed.ok()) return Status::Error(p.request.config + ": " + analysed.status().message());
    Score(analysed.value(), p.targets, &c);
  }
  c.seconds = seconds();
  return c;
}

// The search of the header comment; fills `result` (candidates in order, the best). Errors as Evaluate's.
Status Search(const Problem& p, DesignResult* result) {
  const DriveFamily& family = *p.family;
  const int budget = p.request.budget;
  auto better = [&](int i, int j) {
    return j < 0 || result->candidates[i].objective < result->candidates[j].objective;
  };
  auto try_drive = [&](const DriveDesign& drive, const std::string& stage) -> Result<bool> {
    for (const DesignCandidate& seen : result->candidates) {  // a rounded drive already tried costs nothing
      if (family.ToCoordinates(seen.drive) == family.ToCoordinates(drive)) return false;
    }
    auto c = Evaluate(p, drive, stage);
    if (!c.ok()) return c.status();
    result->candidates.push_back(std::move(c).value());
    const int index = static_cast<int>(result->candidates.size()) - 1;
    const bool improved = std::isfinite(result->candidates[index].objective) && better(index, result->best);
    if (improved) result->best = index;
    if (p.request.progress) p.request.progress(static_cast<double>(result->candidates.size()) / budget);
    return improved;
  };
  auto spent = [&] { return static_cast<int>(result->candidates.size()) >= budget; };

  const DriveDesign start = family.StartDrive(p.scenario);
  if (auto r = try_drive(start, "start"); !r.ok()) return r.status();
  for (const std::vector<double>& u : family.Grid(family.ToCoordinates(start))) {
    if (spent()) break;
    if (auto r = try_drive(family.FromCoordinates(u), "grid"); !r.ok()) return r.status();
  }
  // Pattern search: from the best, each coordinate up and down by the step; the first improvement is taken; a sweep
  // without one halves the step. The family's wrapping coordinate (the heading) wraps around.
  for (double step = kFirstStep; step >= kLastStep && !spent() && result->best >= 0; step /= 2.0) {
    bool improved = true;
    while (improved && !spent()) {
      improved = false;
      for (int k : family.SearchOrder()) {
        if (improved || spent()) break;
        for (double sign : {1.0, -1.0}) {
          if (spent()) break;
          std::vector<double> u = family.ToCoordinates(result->candidates[result->best].drive);
          const double moved = u[k] + sign * step;
          u[k] = k == family.Wrapping() ? std::fmod(moved + 1.0, 1.0) : std::clamp(moved, 0.0, 1.0);
          auto r = try_drive(family.FromCoordinates(u), "pattern");
          if (!r.ok()) return r.status();
          if (r.value()) {
            improved = true;
            break;
          }
        }
      }
    }
  }
  return Status::Ok();
}

// robot.model (and world.model) as a path from the directory of `out`.
std::string PathFrom(const std::string& file, const std::string& out) {
  const fs::path dir = fs::absolute(fs::path(out)).parent_path();
  return fs::absolute(file).lexically_normal().lexically_relative(dir).string();
}

// A profile's constant and sine terms (the ones a drive family makes) as the scenario writes them.
YAML::Node ProfileNode(const sim::Profile& profile) {
  YAML::Node terms(YAML::NodeType::Sequence);
  for (const sim::ProfileTerm& t : profile.terms) {
    YAML::Node term;
    if (t.type == sim::ProfileTerm::Type::kConstant) term["constant"] = Text(t.value);
    if (t.type == sim::ProfileTerm::Type::kSine) {
      term["sine"]["amplitude"] = Text(t.amplitude);
      term["sine"]["period_s"] = Text(t.period_s);
      term["sine"]["phase_rad"] = Text(t.phase_rad);
    }
    terms.push_back(term);
  }
  return terms;
}

// The scenario file with the designed drive, duration and start heading, and its paths made relative to `out`.
std::string DesignedYaml(const Problem& p, const DesignCandidate& best) {
  const DesignRequest& request = p.request;
  const sim::Scenario& scenario = p.scenario;
  YAML::Node root = YAML::LoadFile(request.scenario);
  root["duration_s"] = Text(scenario.duration_s);
  root["robot"]["model"] = PathFrom(scenario.robot.model_file, request.out);
  if (!scenario.world_model_file.empty()) root["world"]["model"] = PathFrom(scenario.world_model_file, request.out);
  root["robot"]["start"]["heading_deg"] = Text(p.family->HeadingDeg(scenario, best.drive));
  for (const auto& [key, profile] : p.family->Profiles(best.drive)) root["driver"][key] = ProfileNode(profile);

  std::ostringstream text;
  text << "# Designed by\n#   roamlab design " << request.scenario << " --config " << request.config << " --duration "
       << scenario.duration_s << " --budget " << request.budget;
  for (const auto& [name, target] : p.targets) text << " --target " << name << "=" << target;
  text << std::setprecision(3) << "\n"
       << "# (limits in design.json): of the drives " << p.family->Formula() << "\n"
       << "# (driver, robot.start), the feasible one with the least max CRB std / target:\n# " << best.objective
       << ", set by " << best.worst << "; " << best.distance_m << " m; largest roll " << best.max_roll_deg
       << " deg, pitch " << best.max_pitch_deg << " deg, side slip " << best.max_side_slip_mps
       << " m/s, lateral acceleration " << best.max_lateral_accel_mps2 << " m/s^2.\n"
       << "# Predicted std (Cramer-Rao bound of the noise-free drive at its truth) and target:\n";
  for (const auto& [label, std] : best.crb_std) {
    const auto target = p.targets.find(label.substr(0, label.find('[')));
    text << "#   " << label << ": " << std;
    if (target != p.targets.end()) text << " (target " << target->second << ")";
    text << "\n";
  }
  YAML::Emitter emitter;
  emitter << root;
  text << emitter.c_str() << "\n";
  return text.str();
}

// Inputs: the scenario (a driver with a family), the configuration, the targets, the limits, the duration and budget.
Result<Problem> LoadProblem(const DesignRequest& request) {
  auto scenario = sim::LoadScenario(request.scenario);
  if (!scenario.ok()) return scenario.status();
  auto limits = WithRobotDefaults(request.limits, scenario.value());
  if (!limits.ok()) return Status::Error(request.scenario + ": " + limits.status().message());
  if (const std::string problem = limits.value().Validate(scenario.value().driver.type); !problem.empty())
    return Status::Error(problem);
  auto family = MakeDriveFamily(scenario.value(), limits.value());
  if (!family.ok()) return Status::Error(request.scenario + ": " + family.status().message());
  auto config = estimator::LoadEstimatorConfig(request.config);
  if (!config.ok()) return config.status();
  for (const auto& [name, target] : request.targets) {
    const auto it = config.value().parameters.find(name);
    if (it == config.value().parameters.end() || !it->second.free)
      return Status::Error("--target " + name + ": not a free parameter of " + request.config);
    if (!(target > 0.0) || !std::isfinite(target)) return Status::Error("--target " + name + ": must be > 0");
  }
  std::map<std::string, double> targets = request.targets;
  for (const auto& [name, parameter] : config.value().parameters)
    if (parameter.target_std) targets.emplace(name, *parameter.target_std);  // a given --target stays
  if (targets.empty())
    return Status::Error("--target: no target given, and no parameter of " + request.config + " has a target_std");
  if (!(request.duration_s >= 0.0) || request.duration_s > kMaxDurationS)
    return Status::Error("--duration: must be in (0, 3600]");
  if (request.budget < 1) return Status::Error("--budget: must be >= 1");
  Problem p{request,        std::move(scenario).value(), std::move(config).value(), std::move(targets),
            limits.value(), std::move(family).value()};
  if (request.duration_s > 0.0) p.scenario.duration_s = request.duration_s;
  return p;
}

}  // namespace

std::string DesignLimits::Validate(const std::string& driver_type) const {
  if (!(max_speed_mps > min_speed_mps)) return "--speed-range: need min < max";
  if (driver_type == "ackermann" && !(min_speed_mps > 0.0)) return "--speed-range: an ackermann drive needs 0 < min";
  if (driver_type == "ackermann" && (!(max_handlebar_rad > 0.0) || max_handlebar_rad > 1.0))
    return "--max-handlebar: must be in (0, 1] rad";
  if (driver_type != "ackermann" && (!(max_yaw_rate_radps > 0.0) || !std::isfinite(max_yaw_rate_radps)))
    return "--max-yaw-rate: must be > 0";
  if (driver_type != "ackermann" && (!(max_lateral_mps >= 0.0) || !std::isfinite(max_lateral_mps)))
    return "--max-lateral-speed: must be >= 0";
  if (!(min_period_s > 0.0) || !(max_period_s >= min_period_s)) return "--period-range: need 0 < min <= max";
  if (!(max_roll_deg > 0.0) || !(max_pitch_deg > 0.0)) return "--max-roll/--max-pitch: must be > 0";
  if (!(max_side_slip_mps > 0.0)) return "--max-side-slip: must be > 0";
  if (!(max_lateral_accel_mps2 > 0.0)) return "--max-lateral-accel: must be > 0";
  if (!(max_velocity_error_mps > 0.0)) return "--max-velocity-error: must be > 0";
  return "";
}

Result<DesignLimits> WithRobotDefaults(const DesignLimits& given, const sim::Scenario& scenario) {
  auto envelope = sim::DesignEnvelope(scenario.robot.kind);
  if (!envelope.ok()) return envelope.status();
  const sim::DriveEnvelope& e = envelope.value();
  if (e.max_lateral_mps == 0.0 && given.max_lateral_mps > 0.0)
    return Status::Error("--max-lateral-speed: a robot of kind " + scenario.robot.kind + " has no sideways set-point");
  DesignLimits l = given;
  auto fill = [](double* value, double robot) {
    if (std::isnan(*value)) *value = robot;
  };
  const bool ackermann = scenario.driver.type == "ackermann";
  fill(&l.min_speed_mps, e.min_speed_mps);
  fill(&l.max_speed_mps, e.max_speed_mps);
  // The turn limit of the other driver type stays NaN (unused).
  if (ackermann) fill(&l.max_handlebar_rad, e.max_turn);
  if (!ackermann) fill(&l.max_yaw_rate_radps, e.max_turn);
  fill(&l.max_lateral_mps, e.max_lateral_mps);
  fill(&l.min_period_s, e.min_period_s);
  fill(&l.max_period_s, e.max_period_s);
  fill(&l.max_roll_deg, e.max_roll_deg);
  fill(&l.max_pitch_deg, e.max_pitch_deg);
  fill(&l.max_side_slip_mps, e.max_side_slip_mps);
  fill(&l.max_lateral_accel_mps2, e.max_lateral_accel_mps2);
  fill(&l.max_velocity_error_mps, e.max_velocity_error_mps);
  return l;
}

Result<DriveDesign> StartDrive(const sim::Scenario& scenario, const DesignLimits& limits) {
  auto complete = WithRobotDefaults(limits, scenario);
  if (!complete.ok()) return complete.status();
  auto family = MakeDriveFamily(scenario, complete.value());
  if (!family.ok()) return family.status();
  return family.value()->StartDrive(scenario);
}

Outcome DesignToFile(const DesignRequest& request, DesignResult* result_out) {
  auto problem = LoadProblem(request);
  if (!problem.ok()) return Outcome::BadInput(problem.status());
  const Problem& p = problem.value();
  std::error_code error;
  const fs::path dir = fs::absolute(fs::path(request.out)).parent_path();
  if (!fs::is_directory(dir, error)) return Outcome::BadInput(Status::Error("--out: no directory " + dir.string()));

  DesignResult result;
  result.duration_s = p.scenario.duration_s;
  result.limits = p.limits;
  result.targets = p.targets;
  result.formula = p.family->Formula();
  if (Status s = Search(p, &result); !s.ok()) {
    // The first drive's analysis failing is the configuration not fitting the recording: bad input.
    return result.candidates.empty() ? Outcome::BadInput(s) : Outcome::Failed(s);
  }
  if (result.best < 0) {
    const DesignCandidate& first = result.candidates.front();
    const std::string why =
        first.infeasible.empty() ? first.worst + " is unobservable on it (its std is not finite)" : first.infeasible;
    const Outcome failed =
        Outcome::Failed(Status::Error("no feasible drive with a finite objective among " +
                                      std::to_string(result.candidates.size()) + " (the first: " + why + ")"));
    if (result_out) *result_out = std::move(result);
    return failed;
  }
  const DesignCandidate& best = result.candidates[static_cast<std::size_t>(result.best)];
  result.designed_yaml = DesignedYaml(p, best);
  result.best_drive = p.family->Describe(best.drive);
  if (Status s = WriteFileAtomic(request.out, result.designed_yaml); !s.ok()) return Outcome::Failed(s);
  if (Status s = WriteFileAtomic((dir / "design.json").string(), DesignJson(request, result).dump(2) + "\n"); !s.ok())
    return Outcome::Failed(s);
  if (result_out) *result_out = std::move(result);
  return Outcome::Ok();
}

nlohmann::json DesignJson(const DesignRequest& request, const DesignResult& result) {
  using nlohmann::json;
  auto drive_json = [](const DriveDesign& d) { return json(d.values); };
  json candidates = json::array();
  for (const DesignCandidate& c : result.candidates) {
    json crb = json::object();
    for (const auto& [label, std] : c.crb_std) crb[label] = Number(std);
    candidates.push_back({{"stage", c.stage},
                          {"drive", drive_json(c.drive)},
                          {"feasible", c.infeasible.empty()},
                          {"infeasible", c.infeasible},
                          {"objective", Number(c.objective)},
                          {"worst", c.worst},
                          {"crb_std", crb},
                          {"max_roll_deg", c.max_roll_deg},
                          {"max_pitch_deg", c.max_pitch_deg},
                          {"max_side_slip_mps", c.max_side_slip_mps},
                          {"max_lateral_accel_mps2", c.max_lateral_accel_mps2},
                          {"max_velocity_error_mps", c.max_velocity_error_mps},
                          {"distance_m", c.distance_m},
                          {"seconds", c.seconds}});
  }
  json targets = json::object();
  for (const auto& [name, std] : result.targets) targets[name] = std;
  const DesignLimits& l = result.limits;
  return {{"scenario", request.scenario},
          {"config", request.config},
          {"out", request.out},
          {"duration_s", result.duration_s},
          {"targets", targets},
          {"limits",
           {{"speed_range_mps", {l.min_speed_mps, l.max_speed_mps}},
            {"max_handlebar_rad", Number(l.max_handlebar_rad)},
            {"max_yaw_rate_radps", Number(l.max_yaw_rate_radps)},
            {"max_lateral_mps", Number(l.max_lateral_mps)},
            {"period_range_s", {l.min_period_s, l.max_period_s}},
            {"max_roll_deg", l.max_roll_deg},
            {"max_pitch_deg", l.max_pitch_deg},
            {"max_side_slip_mps", Number(l.max_side_slip_mps)},
            {"max_lateral_accel_mps2", l.max_lateral_accel_mps2},
            {"max_velocity_error_mps", Number(l.max_velocity_error_mps)}}},
          {"family", result.formula},
          {"budget", request.budget},
          {"best", result.best},
          {"candidates", candidates}};
}

}  // namespace roamlab::experiment
