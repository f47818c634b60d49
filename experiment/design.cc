#include "experiment/design.h"

#include <algorithm>
#include <array>
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
// The normalized coordinates of the family (Coordinates below) and the pattern search's first and last step in them.
constexpr int kCoordinates = 6;
constexpr double kFirstStep = 0.2;
constexpr double kLastStep = 0.02;
// The speed term's phase: a quarter turn (slowest where the handlebar is turned most), as written (10 digits).
constexpr double kSpeedPhaseRad = 1.570796327;
// The pattern search's order of the coordinates: the handlebar's amplitude and period first (the steering range
// excites most parameters), the heading last.
constexpr std::array<int, kCoordinates> kSearchOrder = {2, 3, 0, 1, 4, 5};
// The coarse grid: start headings (added to the scenario's) and handlebar offsets (fractions of the room left by the
// amplitude; 0.5 is none).
constexpr std::array<double, 4> kGridHeadingsDeg = {0.0, 90.0, 180.0, 270.0};
constexpr std::array<double, 3> kGridOffsets = {0.5, 0.25, 0.75};

// A number as the designed scenario writes it: the rounded value's shortest form (yaml-cpp would write 17 digits).
std::string Text(double value) {
  std::ostringstream out;
  out << std::setprecision(10) << value;
  return out.str();
}

// `value` to a multiple of `step`, as its text reads back, so that the drive analysed is the one written.
double Round(double value, double step) { return std::stod(Text(std::round(value / step) * step)); }

// The drive as written: values rounded so that the scenario written is the one analysed.
DriveDesign Rounded(const DriveDesign& d) {
  DriveDesign r;
  r.speed_mean_mps = Round(d.speed_mean_mps, 0.01);
  r.speed_swing_mps = Round(d.speed_swing_mps, 0.01);
  r.handlebar_amplitude_rad = Round(d.handlebar_amplitude_rad, 0.001);
  r.handlebar_period_s = Round(d.handlebar_period_s, 0.01);
  r.handlebar_offset_rad = Round(d.handlebar_offset_rad, 0.001);
  r.heading_deg = Round(std::fmod(std::fmod(d.heading_deg, 360.0) + 360.0, 360.0), 0.1);
  return r;
}

// Normalized coordinates u in [0, 1]^6: mean speed; swing as a fraction of the room the mean leaves; handlebar
// amplitude; period; offset as a fraction of the room the amplitude leaves (0.5: none); heading over a turn.
DriveDesign FromCoordinates(const std::array<double, kCoordinates>& u, const DesignLimits& l) {
  DriveDesign d;
  d.speed_mean_mps = l.min_speed_mps + u[0] * (l.max_speed_mps - l.min_speed_mps);
  d.speed_swing_mps = u[1] * std::min(d.speed_mean_mps - l.min_speed_mps, l.max_speed_mps - d.speed_mean_mps);
  d.handlebar_amplitude_rad = u[2] * l.max_handlebar_rad;
  d.handlebar_period_s = l.min_period_s + u[3] * (l.max_period_s - l.min_period_s);
  d.handlebar_offset_rad = (2.0 * u[4] - 1.0) * (l.max_handlebar_rad - d.handlebar_amplitude_rad);
  d.heading_deg = 360.0 * u[5];
  return Rounded(d);
}

double Fraction(double value, double low, double high) {
  return high > low ? std::clamp((value - low) / (high - low), 0.0, 1.0) : 0.0;
}

std::array<double, kCoordinates> ToCoordinates(const DriveDesign& d, const DesignLimits& l) {
  std::array<double, kCoordinates> u{};
  u[0] = Fraction(d.speed_mean_mps, l.min_speed_mps, l.max_speed_mps);
  const double mean = l.min_speed_mps + u[0] * (l.max_speed_mps - l.min_speed_mps);
  u[1] = Fraction(d.speed_swing_mps, 0.0, std::min(mean - l.min_speed_mps, l.max_speed_mps - mean));
  u[2] = Fraction(d.handlebar_amplitude_rad, 0.0, l.max_handlebar_rad);
  u[3] = Fraction(d.handlebar_period_s, l.min_period_s, l.max_period_s);
  const double room = l.max_handlebar_rad - u[2] * l.max_handlebar_rad;
  u[4] = room > 0.0 ? std::clamp(0.5 + 0.5 * d.handlebar_offset_rad / room, 0.0, 1.0) : 0.5;
  u[5] = std::fmod(std::fmod(d.heading_deg, 360.0) + 360.0, 360.0) / 360.0;
  return u;
}

sim::ProfileTerm Constant(double value) {
  sim::ProfileTerm t;
  t.type = sim::ProfileTerm::Type::kConstant;
  t.value = value;
  return t;
}

sim::ProfileTerm Sine(double amplitude, double period_s, double phase_rad) {
  sim::ProfileTerm t;
  t.type = sim::ProfileTerm::Type::kSine;
  t.amplitude = amplitude;
  t.period_s = period_s;
  t.phase_rad = phase_rad;
  return t;
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
  return why.str();
}

// What every evaluation shares.
struct Problem {
  const DesignRequest& request;
  sim::Scenario scenario;  // with the designed duration
  estimator::EstimatorConfig config;
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
  auto simulation = sim::Simulate(WithDrive(p.scenario, drive), options);
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
  c.infeasible = LimitExceeded(c, p.request.limits);
  if (c.infeasible.empty()) {
    auto analysed =
        estimator::AnalyzeInformation(p.config, s.recording, s.truth.calibration, *s.recording.ground_truth);
    if (!analysed.ok()) return Status::Error(p.request.config + ": " + analysed.status().message());
    Score(analysed.value(), p.request.targets, &c);
  }
  c.seconds = seconds();
  return c;
}

// The search of the header comment; fills `result` (candidates in order, the best). Errors as Evaluate's.
Status Search(const Problem& p, DesignResult* result) {
  const DesignLimits& limits = p.request.limits;
  const int budget = p.request.budget;
  auto better = [&](int i, int j) {
    return j < 0 || result->candidates[i].objective < result->candidates[j].objective;
  };
  auto try_drive = [&](const DriveDesign& drive, const std::string& stage) -> Result<bool> {
    for (const DesignCandidate& seen : result->candidates) {  // a rounded drive already tried costs nothing
      const std::array<double, kCoordinates> a = ToCoordinates(seen.drive, limits), b = ToCoordinates(drive, limits);
      if (a == b) return false;
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

  const DriveDesign start = StartDrive(p.scenario, limits);
  if (auto r = try_drive(start, "start"); !r.ok()) return r.status();
  for (double heading : kGridHeadingsDeg)
    for (double offset : kGridOffsets) {
      if (spent()) break;
      std::array<double, kCoordinates> u = ToCoordinates(start, limits);
      u[4] = offset;
      u[5] = std::fmod(u[5] + heading / 360.0, 1.0);
      if (auto r = try_drive(FromCoordinates(u, limits), "grid"); !r.ok()) return r.status();
    }
  // Pattern search: from the best, each coordinate up and down by the step; the first improvement is taken; a sweep
  // without one halves the step. The heading wraps around.
  for (double step = kFirstStep; step >= kLastStep && !spent() && result->best >= 0; step /= 2.0) {
    bool improved = true;
    while (improved && !spent()) {
      improved = false;
      for (int i = 0; i < kCoordinates && !improved && !spent(); ++i)
        for (double sign : {1.0, -1.0}) {
          const int k = kSearchOrder[static_cast<std::size_t>(i)];
          if (spent()) break;
          std::array<double, kCoordinates> u = ToCoordinates(result->candidates[result->best].drive, limits);
          u[k] = k == 5 ? std::fmod(u[k] + sign * step + 1.0, 1.0) : std::clamp(u[k] + sign * step, 0.0, 1.0);
          auto r = try_drive(FromCoordinates(u, limits), "pattern");
          if (!r.ok()) return r.status();
          if (r.value()) {
            improved = true;
            break;
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

YAML::Node TermNode(const char* type, const std::map<std::string, double>& fields) {
  YAML::Node inner;
  for (const auto& [key, value] : fields) inner[key] = Text(value);
  YAML::Node term;
  term[type] = inner;
  return term;
}

// The scenario file with the designed drive, duration and start heading, and its paths made relative to `out`.
std::string DesignedYaml(const DesignRequest& request, const sim::Scenario& scenario, const DesignCandidate& best) {
  YAML::Node root = YAML::LoadFile(request.scenario);
  const DriveDesign& d = best.drive;
  root["duration_s"] = Text(scenario.duration_s);
  root["robot"]["model"] = PathFrom(scenario.robot.model_file, request.out);
  if (!scenario.world_model_file.empty()) root["world"]["model"] = PathFrom(scenario.world_model_file, request.out);
  root["robot"]["start"]["heading_deg"] = Text(d.heading_deg);
  YAML::Node speed(YAML::NodeType::Sequence), handlebar(YAML::NodeType::Sequence);
  speed.push_back(YAML::Node());
  speed[0]["constant"] = Text(d.speed_mean_mps);
  speed.push_back(TermNode(
      "sine",
      {{"amplitude", d.speed_swing_mps}, {"period_s", 0.5 * d.handlebar_period_s}, {"phase_rad", kSpeedPhaseRad}}));
  handlebar.push_back(YAML::Node());
  handlebar[0]["constant"] = Text(d.handlebar_offset_rad);
  handlebar.push_back(TermNode(
      "sine", {{"amplitude", d.handlebar_amplitude_rad}, {"period_s", d.handlebar_period_s}, {"phase_rad", 0.0}}));
  root["driver"]["speed_mps"] = speed;
  root["driver"]["handlebar_rad"] = handlebar;

  std::ostringstream text;
  text << "# Designed by\n#   roamlab design " << request.scenario << " --config " << request.config << " --duration "
       << scenario.duration_s << " --budget " << request.budget;
  for (const auto& [name, target] : request.targets) text << " --target " << name << "=" << target;
  text << std::setprecision(3) << "\n"
       << "# (limits in design.json): of the drives speed = v0 + dv cos(4 pi t / P),\n"
       << "# handlebar = d0 + da sin(2 pi t / P), start heading h (driver, robot.start), the feasible one with the "
          "least max CRB std / target:\n# "
       << best.objective << ", set by " << best.worst << "; " << best.distance_m << " m; largest roll "
       << best.max_roll_deg << " deg, pitch " << best.max_pitch_deg << " deg, side slip " << best.max_side_slip_mps
       << " m/s, lateral acceleration " << best.max_lateral_accel_mps2 << " m/s^2.\n"
       << "# Predicted std (Cramer-Rao bound of the noise-free drive at its truth) and target:\n";
  for (const auto& [label, std] : best.crb_std) {
    const auto target = request.targets.find(label.substr(0, label.find('[')));
    text << "#   " << label << ": " << std;
    if (target != request.targets.end()) text << " (target " << target->second << ")";
    text << "\n";
  }
  YAML::Emitter emitter;
  emitter << root;
  text << emitter.c_str() << "\n";
  return text.str();
}

// Inputs: the scenario (ackermann driver), the configuration, the targets, the limits, the duration and budget.
Result<Problem> LoadProblem(const DesignRequest& request) {
  auto scenario = sim::LoadScenario(request.scenario);
  if (!scenario.ok()) return scenario.status();
  if (scenario.value().driver.type != "ackermann")
    return Status::Error(request.scenario + ": driver.type: design needs an ackermann driver, not " +
                         scenario.value().driver.type);
  auto config = estimator::LoadEstimatorConfig(request.config);
  if (!config.ok()) return config.status();
  if (request.targets.empty()) return Status::Error("--target: no target given");
  for (const auto& [name, target] : request.targets) {
    const auto it = config.value().parameters.find(name);
    if (it == config.value().parameters.end() || !it->second.free)
      return Status::Error("--target " + name + ": not a free parameter of " + request.config);
    if (!(target > 0.0) || !std::isfinite(target)) return Status::Error("--target " + name + ": must be > 0");
  }
  if (const std::string problem = request.limits.Validate(); !problem.empty()) return Status::Error(problem);
  if (!(request.duration_s >= 0.0) || request.duration_s > kMaxDurationS)
    return Status::Error("--duration: must be in (0, 3600]");
  if (request.budget < 1) return Status::Error("--budget: must be >= 1");
  Problem p{request, std::move(scenario).value(), std::move(config).value()};
  if (request.duration_s > 0.0) p.scenario.duration_s = request.duration_s;
  return p;
}

}  // namespace

std::string DesignLimits::Validate() const {
  if (!(min_speed_mps > 0.0) || !(max_speed_mps > min_speed_mps)) return "--speed-range: need 0 < min < max";
  if (!(max_handlebar_rad > 0.0) || max_handlebar_rad > 1.0) return "--max-handlebar: must be in (0, 1] rad";
  if (!(min_period_s > 0.0) || !(max_period_s >= min_period_s)) return "--period-range: need 0 < min <= max";
  if (!(max_roll_deg > 0.0) || !(max_pitch_deg > 0.0)) return "--max-roll/--max-pitch: must be > 0";
  if (!(max_side_slip_mps > 0.0)) return "--max-side-slip: must be > 0";
  if (!(max_lateral_accel_mps2 > 0.0)) return "--max-lateral-accel: must be > 0";
  return "";
}

sim::Scenario WithDrive(const sim::Scenario& scenario, const DriveDesign& drive) {
  sim::Scenario out = scenario;
  out.robot.start_heading_rad = drive.heading_deg / kDegPerRad;
  out.driver.speed_mps.terms = {Constant(drive.speed_mean_mps),
                                Sine(drive.speed_swing_mps, 0.5 * drive.handlebar_period_s, kSpeedPhaseRad)};
  out.driver.handlebar_rad.terms = {Constant(drive.handlebar_offset_rad),
                                    Sine(drive.handlebar_amplitude_rad, drive.handlebar_period_s, 0.0)};
  return out;
}

DriveDesign StartDrive(const sim::Scenario& scenario, const DesignLimits& limits) {
  DriveDesign d;
  d.speed_mean_mps = 0.0;
  bool speed_sine = false, handlebar_sine = false;
  for (const sim::ProfileTerm& t : scenario.driver.speed_mps.terms) {
    if (t.type == sim::ProfileTerm::Type::kConstant) d.speed_mean_mps += t.value;
    if (t.type == sim::ProfileTerm::Type::kSine && !speed_sine) d.speed_swing_mps = std::abs(t.amplitude);
    speed_sine = speed_sine || t.type == sim::ProfileTerm::Type::kSine;
  }
  for (const sim::ProfileTerm& t : scenario.driver.handlebar_rad.terms) {
    if (t.type == sim::ProfileTerm::Type::kConstant) d.handlebar_offset_rad += t.value;
    if (t.type == sim::ProfileTerm::Type::kSine && !handlebar_sine) {
      d.handlebar_amplitude_rad = std::abs(t.amplitude);
      d.handlebar_period_s = t.period_s;
    }
    handlebar_sine = handlebar_sine || t.type == sim::ProfileTerm::Type::kSine;
  }
  d.heading_deg = scenario.robot.start_heading_rad * kDegPerRad;
  return FromCoordinates(ToCoordinates(d, limits), limits);
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
  if (Status s = Search(p, &result); !s.ok()) {
    // The first drive's analysis failing is the configuration not fitting the recording: bad input.
    return result.candidates.empty() ? Outcome::BadInput(s) : Outcome::Failed(s);
  }
  if (result.best < 0) {
    const Outcome failed =
        Outcome::Failed(Status::Error("no feasible drive among " + std::to_string(result.candidates.size()) +
                                      " (the first: " + result.candidates.front().infeasible + ")"));
    if (result_out) *result_out = std::move(result);
    return failed;
  }
  result.designed_yaml = DesignedYaml(request, p.scenario, result.candidates[static_cast<std::size_t>(result.best)]);
  if (Status s = WriteFileAtomic(request.out, result.designed_yaml); !s.ok()) return Outcome::Failed(s);
  if (Status s = WriteFileAtomic((dir / "design.json").string(), DesignJson(request, result).dump(2) + "\n"); !s.ok())
    return Outcome::Failed(s);
  if (result_out) *result_out = std::move(result);
  return Outcome::Ok();
}

nlohmann::json DesignJson(const DesignRequest& request, const DesignResult& result) {
  using nlohmann::json;
  auto drive_json = [](const DriveDesign& d) {
    return json{{"speed_mean_mps", d.speed_mean_mps},
                {"speed_swing_mps", d.speed_swing_mps},
                {"handlebar_amplitude_rad", d.handlebar_amplitude_rad},
                {"handlebar_period_s", d.handlebar_period_s},
                {"handlebar_offset_rad", d.handlebar_offset_rad},
                {"heading_deg", d.heading_deg}};
  };
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
                          {"distance_m", c.distance_m},
                          {"seconds", c.seconds}});
  }
  json targets = json::object();
  for (const auto& [name, std] : request.targets) targets[name] = std;
  const DesignLimits& l = request.limits;
  return {{"scenario", request.scenario},
          {"config", request.config},
          {"out", request.out},
          {"duration_s", result.duration_s},
          {"targets", targets},
          {"limits",
           {{"speed_range_mps", {l.min_speed_mps, l.max_speed_mps}},
            {"max_handlebar_rad", l.max_handlebar_rad},
            {"period_range_s", {l.min_period_s, l.max_period_s}},
            {"max_roll_deg", l.max_roll_deg},
            {"max_pitch_deg", l.max_pitch_deg},
            {"max_side_slip_mps", l.max_side_slip_mps},
            {"max_lateral_accel_mps2", l.max_lateral_accel_mps2}}},
          {"budget", request.budget},
          {"best", result.best},
          {"candidates", candidates}};
}

}  // namespace roamlab::experiment
