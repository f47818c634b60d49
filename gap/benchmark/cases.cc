#include "gap/benchmark/cases.h"

#include "common/atomic_file.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <sstream>

#include <Eigen/Core>

#include "common/atomic_file.h"
#include "gap/learn_baseline.h"
#include "gap/nominal_config.h"
#include "gap/report.h"
#include "gap/resimulate.h"
#include "recording/recording.h"
#include "recording/truth.h"
#include "sim/simulator.h"

namespace roamlab::gap::benchmark {
namespace {

// The stream whose held-out RMS an effect moves (the stream diagnose scales the candidate's statistic by).
std::string AffectedStream(const std::string& effect) {
  if (effect == "gps_latency") return "gps";
  if (effect == "imu_time_offset" || effect == "gyro_scale_error" || effect == "gyro_bias_drift") return "gyroscope";
  if (effect == "magnetometer_motor_interference") return "magnetometer";
  return "odometer";
}

// The recording's stream in which the effect shows when the scenario is simulated again (gap/resimulate.h): sensor
// effects in their sensor; physical ones (the drive is open-loop: the same commands) where the changed motion shows:
// the ATV's path and the mecanum robot's (track_width_error, drawn on it only) in their GPS fixes, the differential
// drive's turn rate in its gyroscope (it has no GPS). Not the mecanum robot's IMU: its rollers shake the body, and
// any change of the physics draws another shaking, which stays several times the noise with the effect fitted. A
// replay drives by the steering and rear-wheel readings and reproduces them whatever the patch (sim/replay.h takes
// the patch's effects on them back to the drive): the effects on those readings show in the path, in the GPS fixes.
std::string SimulatedStream(const std::string& effect, bool replayed) {
  if (effect == "gps_latency" || effect == "lateral_slip" || effect == "axle_misalignment" ||
      effect == "track_width_error")
    return "gps";
  if (effect == "magnetometer_motor_interference") return "magnetometer";
  const bool drive_reading = effect == "steering_offset" || effect == "longitudinal_slip" || effect == "slope_slip";
  if (drive_reading && replayed) return "gps";
  if (effect == "steering_offset") return "steering";
  if (drive_reading) return "rear_wheel";
  return "gyroscope";
}

// The random numbers of one draw: uniform on [0, 1) and a random sign.
struct Dice {
  std::mt19937_64& rng;
  std::uniform_real_distribution<double> u{0.0, 1.0};
  double U() { return u(rng); }
  double Sign() { return U() < 0.5 ? -1.0 : 1.0; }
  std::string Axis() { return std::string(1, "xyz"[static_cast<int>(3.0 * U()) % 3]); }
};

double RoundTo(double x, double step) { return std::round(x / step) * step; }

// A constant gyroscope bias on one axis (a MEMS turn-on bias), on any platform.
sim::EffectOptions GyroBias(Dice& dice, const std::string& axis) {
  return {"gyro_bias_drift", {{"initial_" + axis, dice.Sign() * (0.002 + 0.048 * dice.U())}}};
}

// Decoys, on the ATV only: effects no candidate models, each leaving structure in a stream the nominal model reads
// (sim/scenario.h).
void DrawDecoy(Dice& dice, double pick, Draw* d) {
  d->kind = "decoy";
  d->platform = 0;
  if (pick < 0.5) {
    // An accelerometer gain error on one axis: the accelerometer's components follow gravity and the motion.
    const std::string axis = dice.Axis();
    d->effect = {"accelerometer_scale_error", {{"scale_" + axis, 1.0 + dice.Sign() * (0.02 + 0.03 * dice.U())}}};
  } else {
    // GPS multipath: a correlated error of the fixes, which follows no motion condition.
    d->effect = {"gps_multipath", {{"sigma_m", 0.5 + 1.5 * dice.U()}, {"correlation_s", 2.0 + 8.0 * dice.U()}}};
  }
  d->parameter = d->effect.name == "gps_multipath" ? "sigma_m" : d->effect.parameters.begin()->first;
}

// The mecanum robot's effects: its position fixes tell its track, so the track is drawn, and a yaw gyro bias.
void DrawMecanumEffect(Dice& dice, double pick, Draw* d) {
  if (pick < 0.5) {
    d->effect = {"track_width_error", {{"track_error_m", dice.Sign() * (0.008 + 0.042 * dice.U())}}};
  } else {
    d->effect = GyroBias(dice, "z");
  }
  d->parameter = d->effect.parameters.begin()->first;
}

// The differential drive's effects: the ones its sensors can identify. track_width_error is not drawn, because with
// the wheel radius free and no speed reference only r / B is observable (the gyroscope sees the turn rate
// r (omega_R - omega_L) / B), so a track error is a radius error.
void DrawDiffDriveEffect(Dice& dice, double pick, Draw* d) {
  switch (static_cast<int>(3.0 * pick)) {
    case 0:
      d->effect = {"wheel_radius_asymmetry", {{"ratio_right_left", 1.0 + dice.Sign() * (0.004 + 0.046 * dice.U())}}};
      break;
    case 1:
      d->effect = {"wheel_deformation",
                   {{"wheel", dice.U() < 0.5 ? 0.0 : 1.0}, {"ovality_m", 0.001 + 0.003 * dice.U()}}};
      break;
    default:
      d->effect = GyroBias(dice, "z");
  }
  d->parameter = d->effect.name == "wheel_deformation" ? "ovality_m" : d->effect.parameters.begin()->first;
}

// A magnetometer bias following the drive torque, in a random direction with |k| from about 3x its std to large;
// scored on its largest axis.
void DrawMotorInterference(Dice& dice, Draw* d) {
  Eigen::Vector3d k(dice.U() - 0.5, dice.U() - 0.5, dice.U() - 0.5);
  k = k.normalized() * (5e-4 + 2.5e-3 * dice.U());
  Eigen::Index axis = 0;
  k.cwiseAbs().maxCoeff(&axis);
  d->effect = {"magnetometer_motor_interference",
               {{"b_per_nm_x", k.x()}, {"b_per_nm_y", k.y()}, {"b_per_nm_z", k.z()}}};
  d->parameter = std::string("b_per_nm_") + "xyz"[axis];
}

// The ATV's effects: one of nine kinds.
void DrawAtvEffect(Dice& dice, double pick, Draw* d) {
  switch (static_cast<int>(9.0 * pick)) {
    case 0:
      // To 0.5 s, diagnose's time-shift range (max_shift_s): a longer latency moves fixes past the poses' span that
      // the held-out part is cut to, and the held-out comparison loses them.
      d->effect = {"gps_latency", {{"latency_s", RoundTo(0.2 + 0.3 * dice.U(), 0.001)}}};
      break;
    case 1:
      d->effect = {"imu_time_offset", {{"offset_s", dice.Sign() * RoundTo(0.02 + 0.08 * dice.U(), 0.001)}}};
      break;
    case 2:
      d->effect = {"steering_offset", {{"offset_rad", dice.Sign() * (0.015 + 0.065 * dice.U())}}};
      break;
    case 3: {
      const std::string axis = dice.Axis();
      d->effect = {"gyro_scale_error", {{"scale_" + axis, 1.0 + dice.Sign() * (0.03 + 0.07 * dice.U())}}};
      break;
    }
    case 4:
      DrawMotorInterference(dice, d);
      return;
    case 5:
      // The rear tires' slip per m/s^2 of traction, from about the smallest the diagnosis names to large.
      d->effect = {"longitudinal_slip", {{"slip_per_mps2", 0.007 + 0.043 * dice.U()}}};
      break;
    case 6:
      // The slip per m/s^2 of slope, from about the smallest the diagnosis names to large.
      d->effect = {"slope_slip", {{"slip_per_mps2", 0.005 + 0.045 * dice.U()}}};
      break;
    case 7:
      // Softer tires: the contact time constant times 3-4 (smaller ones are not named reliably). Scored on the
      // compliance measured on the truth (RearCorneringCompliance), the candidate's cornering_rear_s.
      d->effect = {"lateral_slip", {{"contact_time_scale", 3.0 + dice.U()}}};
      d->parameter = "cornering_rear_s";
      return;
    default:
      d->effect = GyroBias(dice, dice.Axis());
  }
  d->parameter = d->effect.parameters.begin()->first;
}

// Simulates the case's "real" recording and writes it with its truth to `rec_dir`.
Result<sim::Simulation> SimulateCase(const Platform& platform, const Draw& draw, std::uint64_t noise_seed,
                                     const std::string& rec_dir) {
  sim::Scenario s = platform.scenario;
  if (draw.kind != "none") s.effects.push_back(draw.effect);
  if (draw.other_drive) s.driver = OtherDrive(s.driver, draw.drive_seed);
  sim::SimulateOptions options;
  options.seed = noise_seed;
  auto simulated = sim::Simulate(s, options);
  if (!simulated.ok()) return Status::Error("simulation: " + simulated.status().message());
  std::error_code ec;
  std::filesystem::create_directories(rec_dir, ec);
  if (ec) return Status::Error(rec_dir + ": cannot create the directory");
  if (Status st = recording::WriteRecording(simulated.value().recording, rec_dir); !st.ok()) return st;
  if (Status st = recording::WriteTruth(simulated.value().truth, rec_dir); !st.ok()) return st;
  return simulated;
}

// The blind diagnosis: the written recording's streams only, and the re-simulation against its held-out part.
struct BlindDiagnosis {
  recording::Recording recording;
  Diagnosis diagnosis;
  SimulationComparison simulation;
};

Result<BlindDiagnosis> DiagnoseBlind(const Platform& platform, const std::string& rec_dir, const CaseSetup& setup) {
  recording::ReadOptions read;
  read.load_ground_truth = false;
  auto rec = recording::ReadRecording(rec_dir, read);
  if (!rec.ok()) return rec.status();
  DiagnoseOptions options;
  options.baseline = &platform.baseline;
  options.alpha = setup.thresholds.alpha;
  options.max_delta_bic = setup.thresholds.max_delta_bic;
  options.min_heldout_improvement = setup.thresholds.min_heldout_improvement;
  options.min_explained_share = setup.thresholds.min_explained_share;
  options.heldout_all_candidates = setup.heldout_all;
  auto diagnosed = Diagnose(platform.config, rec.value(), options);
  if (!diagnosed.ok()) return Status::Error("diagnosis: " + diagnosed.status().message());
  const Diagnosis& d = diagnosed.value();
  auto twin = ChooseTwin(platform.scenario, rec.value(), TwinDrive::kDetect);
  if (!twin.ok()) return Status::Error("re-simulation: " + twin.status().message());
  auto simulation = CompareWithSimulation(platform.scenario, d.effects, rec.value(), d.train_end_s, twin.value());
  if (!simulation.ok()) return Status::Error("re-simulation: " + simulation.status().message());
  return BlindDiagnosis{std::move(rec).value(), std::move(diagnosed).value(), std::move(simulation).value()};
}

// What the diagnosis said: the verdict, the effects kept, the candidates in order.
void RecordDiagnosis(const Diagnosis& d, CaseResult* c) {
  c->verdict = d.verdict;
  for (const EffectEstimate& e : d.effects) c->named.push_back(e.name);
  c->ranked = c->named;
  for (const EffectEstimate& e : d.candidates) {  // in order of Delta BIC
    if (std::find(c->ranked.begin(), c->ranked.end(), e.name) == c->ranked.end()) c->ranked.push_back(e.name);
    CandidateStats stats{e.name, e.lr_pvalue,      e.delta_bic, e.evaluated_heldout, e.heldout_improvement,
                         e.std,  e.explained_share};
    c->candidates.push_back(stats);
  }
}

// An effect case's figures: the estimate of the hidden parameter when the truth was named, the affected stream's
// held-out RMS and the re-simulation's before and after.
void ScoreEffect(const BlindDiagnosis& blind, CaseResult* c) {
  const Diagnosis& d = blind.diagnosis;
  for (const EffectEstimate& e : d.effects) {
    if (e.name != c->truth_name || !e.parameters.count(c->truth_parameter)) continue;
    c->estimate = e.parameters.at(c->truth_parameter);
    c->has_estimate = true;
    break;
  }
  const std::string stream = AffectedStream(c->truth_name);
  if (d.before.count(stream) && d.after.count(stream)) {
    c->rms_before = d.before.at(stream).rms;
    c->rms_after = d.after.at(stream).rms;
    c->rms_1s_before = d.before.at(stream).rms_1s;
    c->rms_1s_after = d.after.at(stream).rms_1s;
    c->has_rms = true;
  }
  c->sim_stream = SimulatedStream(c->truth_name, blind.simulation.twin.replayed);
  const auto before = blind.simulation.before.find(c->sim_stream);
  const auto after = blind.simulation.after.find(c->sim_stream);
  if (before != blind.simulation.before.end() && after != blind.simulation.after.end()) {
    c->sim_rms_before = before->second.rms;
    c->sim_rms_after = after->second.rms;
    c->sim_rms_1s_before = before->second.rms_1s;
    c->sim_rms_1s_after = after->second.rms_1s;
    c->has_sim_rms = true;
  }
}

// Scoring: now, and only now, the truth.
Status ScoreFromTruth(const Platform& platform, const Draw& draw, const sim::Simulation& simulated,
                      const std::string& rec_dir, const BlindDiagnosis& blind, CaseResult* c) {
  auto truth = recording::ReadTruth(rec_dir);
  if (!truth.ok()) return truth.status();
  if (draw.kind != "none") {
    if (truth.value().effects.empty()) return Status::Error(rec_dir + "/truth.yaml: the hidden effect is missing");
    const auto& effect = truth.value().effects.front();
    c->truth_name = effect.name;
    c->truth_parameter = draw.parameter;
    const auto value = effect.parameters.find(draw.parameter);
    c->truth_value = value != effect.parameters.end() ? value->second : 0.0;
    // Softer tires: their size in the candidate's units, the compliance on this drive's truth minus the nominal's
    // (the physics does not depend on the noise seed).
    if (effect.name == "lateral_slip" && simulated.recording.ground_truth)
      c->truth_value = RearCorneringCompliance(*simulated.recording.ground_truth) - platform.rear_compliance_s;
  }
  if (draw.kind == "effect") ScoreEffect(blind, c);
  return Status::Ok();
}

}  // namespace

Result<Platform> LoadPlatform(const std::string& name, const std::string& path, const std::string& kind,
                              double duration_s) {
  auto scenario = sim::LoadScenario(path);
  if (!scenario.ok()) return scenario.status();
  if (scenario.value().robot.kind != kind)
    return Status::Error(path + ": the " + name + " scenario must describe a robot of kind '" + kind + "', not '" +
                         scenario.value().robot.kind + "'");
  auto config = NominalConfig(scenario.value());
  if (!config.ok()) return Status::Error(path + ": " + config.status().message());
  Platform p;
  p.name = name;
  p.scenario = scenario.value();
  p.scenario.effects.clear();
  if (duration_s > 0.0) p.scenario.duration_s = duration_s;
  p.config = config.value();
  return p;
}

// Magnitudes from about the smallest the diagnosis resolves (its std on the training part) to large: the worst a
// badly set-up robot of the kind plausibly has (a consumer MEMS gyroscope's few deg/s turn-on bias, a 100 ms clock
// offset, a 10 % gyroscope gain error, a 5 % wheel radius difference), where the effect's trace in its stream reaches
// or passes the stream's sample noise. Decoys are drawn on the ATV only: an accelerometer gain error or GPS multipath
// shows in the accelerometer's or the GPS's residuals and no candidate models it (tire_growth is not drawn: it leaves
// the speed and GPS residuals within their band); the differential drive's nominal model reads only the encoders and
// the gyroscope, and the out-of-library effects the simulator has for it either do not show there or look like a
// library effect (a yawed axle reads as a smaller wheel).
Draw DrawCase(std::mt19937_64& rng, const std::string& stratum) {
  Dice dice{rng};
  Draw d;
  const double platform = dice.U();
  d.platform = platform < 0.5 ? 0 : platform < 0.75 ? 1 : 2;
  const double u_kind = dice.U();
  const double pick = dice.U();
  const std::string kind = !stratum.empty() ? stratum : u_kind < 0.2 ? "none" : u_kind < 0.35 ? "decoy" : "effect";
  if (kind == "none") {
    d.kind = "none";
    return d;
  }
  if (kind == "decoy") {
    DrawDecoy(dice, pick, &d);
    return d;
  }
  d.kind = "effect";
  if (d.platform == 2) {
    DrawMecanumEffect(dice, pick, &d);
  } else if (d.platform == 1) {
    DrawDiffDriveEffect(dice, pick, &d);
  } else {
    DrawAtvEffect(dice, pick, &d);
  }
  return d;
}

sim::DriverOptions OtherDrive(const sim::DriverOptions& nominal, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> phase(0.0, 2.0 * M_PI);
  sim::DriverOptions out = nominal;
  for (sim::Profile* p : {&out.speed_mps, &out.handlebar_rad, &out.linear_mps, &out.angular_radps, &out.lateral_mps})
    for (sim::ProfileTerm& term : p->terms)
      if (term.type == sim::ProfileTerm::Type::kSine || term.type == sim::ProfileTerm::Type::kSquare)
        term.phase_rad += phase(rng);
  return out;
}

void DrawDrives(std::mt19937_64& rng, double fraction, std::vector<Draw>* draws) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (Draw& d : *draws) {
    d.other_drive = u(rng) < fraction;
    d.drive_seed = rng();
  }
}

Result<CaseResult> RunCase(const Platform& platform, const Draw& draw, std::uint64_t noise_seed, const std::string& id,
                           const std::string& dir, const CaseSetup& setup) {
  const auto start = std::chrono::steady_clock::now();
  const std::string rec_dir = dir + "/rec";
  auto simulated = SimulateCase(platform, draw, noise_seed, rec_dir);
  if (!simulated.ok()) return simulated.status();
  // Blind: the diagnosis reads the written recording's streams only; written as `roamlab diagnose` writes it
  // (located components, candidates, held-out fit before and after), for the study of a case.
  auto blind = DiagnoseBlind(platform, rec_dir, setup);
  if (!blind.ok()) return blind.status();
  const BlindDiagnosis& b = blind.value();
  const nlohmann::json gap =
      DiagnosisJson(b.diagnosis, &platform.baseline, kDefaultBaselineSeed, &b.simulation, &b.recording);
  if (Status s = WriteFileAtomic(dir + "/gap.json", gap.dump(2) + "\n"); !s.ok()) return s;
  CaseResult c;
  c.id = id;
  c.platform = platform.name;
  c.kind = draw.kind;
  c.other_drive = draw.other_drive;
  c.replayed = b.simulation.twin.replayed;
  RecordDiagnosis(b.diagnosis, &c);
  if (Status s = ScoreFromTruth(platform, draw, simulated.value(), rec_dir, b, &c); !s.ok()) return s;
  c.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // Written last, under a temporary name then renamed: a case.json marks a finished case (BenchmarkOptions::resume).
  if (Status written = WriteFileAtomic(dir + "/case.json", CaseRow(c).dump(2) + "\n"); !written.ok()) return written;
  return c;
}

std::string CaseLine(const CaseResult& c) {
  std::ostringstream s;
  s << c.id << " " << c.platform << " " << c.kind;
  if (c.other_drive) s << " (other drive" << (c.replayed ? ", replayed" : ", not replayed") << ")";
  if (!c.truth_name.empty()) s << " " << c.truth_name << " " << c.truth_parameter << "=" << c.truth_value;
  if (c.noise_ratio >= 0.0) s << std::setprecision(3) << " (" << c.noise_ratio << "x noise)";
  s << " -> " << c.verdict;
  if (!c.named.empty()) s << " " << c.named.front();
  if (c.has_estimate) s << " " << c.estimate;
  s << std::fixed << std::setprecision(0) << " [" << c.seconds << " s]";
  return s.str();
}

}  // namespace roamlab::gap::benchmark
