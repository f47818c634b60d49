#include "apps/gap_benchmark.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <mutex>
#include <random>
#include <sstream>
#include <thread>
#include <tuple>

#include <nlohmann/json.hpp>

#include "apps/diagnose.h"
#include "apps/gap_benchmark_score.h"
#include "gap/diagnose.h"
#include "gap/resimulate.h"
#include "recording/recording.h"
#include "recording/truth.h"
#include "sim/scenario.h"
#include "sim/simulator.h"

namespace roamlab::apps {
namespace {

using nlohmann::json;
using gapbench::CaseResult;
using gapbench::Thresholds;

constexpr std::uint64_t kBaselineSeed = 900001;
constexpr int kMaxCases = 500;                 // per phase: the calibration seeds start 500 after the scored ones

struct Platform {
  std::string name;                            // atv | diffdrive | mecanum
  sim::Scenario scenario;
  estimator::EstimatorConfig config;
  gap::Baseline baseline;
  double rear_compliance_s = 0.0;              // ATV: the nominal drive's cornering compliance, on its truth
};

// One drawn case: the platform, the kind and the effect hidden in its scenario (empty name: none).
struct Draw {
  int platform = 0;                            // index into the platforms
  std::string kind;                            // none | effect | decoy
  sim::EffectOptions effect;
  std::string parameter;                       // the parameter drawn away from neutral
};

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
// any change of the physics draws another shaking (the first run with the gyroscope for the track: accelerometer 15-20
// and gyroscope 2-2.9 times the noise as believed, still 13-20 and 1.6-2.5 with the track fitted within 3-13 %,
// while the GPS fell from 4.4-8.2 to 1.03-1.14).
std::string SimulatedStream(const std::string& effect) {
  if (effect == "gps_latency" || effect == "lateral_slip" || effect == "axle_misalignment" ||
      effect == "track_width_error")
    return "gps";
  if (effect == "magnetometer_motor_interference") return "magnetometer";
  if (effect == "steering_offset") return "steering";
  if (effect == "longitudinal_slip" || effect == "slope_slip") return "rear_wheel";
  return "gyroscope";
}

// Platform 0 is the ATV (half of the cases: its library is the largest), 1 the differential drive and 2 the mecanum
// robot (a quarter each). Kinds: none 20 %, decoy 15 %, effect 65 %; or `stratum` (none, decoy or effect) when given
// (the calibration's stratified draws: the same random numbers are drawn, the kind's is overruled).
// Magnitudes from about the smallest the diagnosis resolves (its std on a 20 s training part, README) to large: the
// worst a badly set-up robot of the kind plausibly has (a consumer MEMS gyroscope's few deg/s turn-on bias, a 100 ms
// clock offset, a 10 % gyroscope gain error, a 5 % wheel radius difference), where the effect's trace in its stream
// reaches or passes the stream's sample noise. Below the noise an effect found and fitted moves each whitened sample
// by a fraction of its noise (README, gap-benchmark).
// Decoys are drawn on the ATV only: an accelerometer gain error or GPS multipath shows in the accelerometer's or the
// GPS's residuals and no candidate models it (tire_growth is not drawn: at 0.003 s^2/m^2, already 2-7 % at the drive's
// speeds, it left the speed and GPS residuals within their band); the differential drive's nominal model reads only
// the encoders and the gyroscope, and the out-of-library effects the simulator has for it either do not show there or
// look like a library effect (a yawed axle reads as a smaller wheel). Its effects are the ones its sensors can identify:
// track_width_error is not drawn, because with the wheel radius free and no speed reference only r / B is observable
// (the gyroscope sees the turn rate r (omega_R - omega_L) / B), so a track error is a radius error. The mecanum robot's
// position fixes tell its track (README: 0.04 m -> 0.0411 +- 0.0026), so it is drawn there, with a yaw gyro bias.
Draw DrawCase(std::mt19937_64& rng, const std::string& stratum) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto sign = [&] { return u(rng) < 0.5 ? -1.0 : 1.0; };
  const auto round_to = [](double x, double step) { return std::round(x / step) * step; };
  Draw d;
  const double platform = u(rng);
  d.platform = platform < 0.5 ? 0 : platform < 0.75 ? 1 : 2;
  const double u_kind = u(rng);
  const double pick = u(rng);
  const std::string kind = !stratum.empty() ? stratum : u_kind < 0.2 ? "none" : u_kind < 0.35 ? "decoy" : "effect";
  if (kind == "none") {
    d.kind = "none";
    return d;
  }
  if (kind == "decoy") {
    d.kind = "decoy";
    d.platform = 0;
    // Effects no candidate models, each leaving structure in a stream the nominal model reads (sim/scenario.h).
    if (pick < 0.5) {
      // An accelerometer gain error on one axis: the accelerometer's components follow gravity and the motion.
      const std::string axis(1, "xyz"[static_cast<int>(3.0 * u(rng)) % 3]);
      d.effect = {"accelerometer_scale_error", {{"scale_" + axis, 1.0 + sign() * (0.02 + 0.03 * u(rng))}}};
    } else {
      // GPS multipath: a correlated error of the fixes, which follows no motion condition.
      d.effect = {"gps_multipath", {{"sigma_m", 0.5 + 1.5 * u(rng)}, {"correlation_s", 2.0 + 8.0 * u(rng)}}};
    }
    d.parameter = d.effect.name == "gps_multipath" ? "sigma_m" : d.effect.parameters.begin()->first;
    return d;
  }
  d.kind = "effect";
  // A constant gyroscope bias on one axis (a MEMS turn-on bias), on either platform.
  const auto gyro_bias = [&](const std::string& axis) {
    d.effect = {"gyro_bias_drift", {{"initial_" + axis, sign() * (0.002 + 0.048 * u(rng))}}};
  };
  if (d.platform == 2) {
    if (pick < 0.5) {
      d.effect = {"track_width_error", {{"track_error_m", sign() * (0.008 + 0.042 * u(rng))}}};
    } else {
      gyro_bias("z");
    }
    d.parameter = d.effect.parameters.begin()->first;
    return d;
  }
  if (d.platform == 1) {
    switch (static_cast<int>(3.0 * pick)) {
      case 0:
        d.effect = {"wheel_radius_asymmetry", {{"ratio_right_left", 1.0 + sign() * (0.004 + 0.046 * u(rng))}}};
        break;
      case 1:
        d.effect = {"wheel_deformation", {{"wheel", u(rng) < 0.5 ? 0.0 : 1.0}, {"ovality_m", 0.001 + 0.003 * u(rng)}}};
        break;
      default:
        gyro_bias("z");
    }
    d.parameter = d.effect.name == "wheel_deformation" ? "ovality_m" : d.effect.parameters.begin()->first;
    return d;
  }
  switch (static_cast<int>(9.0 * pick)) {
    case 0:
      // To 0.5 s, diagnose's time-shift range (max_shift_s): a longer latency moves fixes past the poses' span that
      // the held-out part is cut to (drawn to 1 s, a 0.572 s latency was fitted at 0.563 s on the training part and
      // then lost fixes on the held-out part, so nothing was kept).
      d.effect = {"gps_latency", {{"latency_s", round_to(0.2 + 0.3 * u(rng), 0.001)}}};
      break;
    case 1:
      d.effect = {"imu_time_offset", {{"offset_s", sign() * round_to(0.02 + 0.08 * u(rng), 0.001)}}};
      break;
    case 2:
      d.effect = {"steering_offset", {{"offset_rad", sign() * (0.015 + 0.065 * u(rng))}}};
      break;
    case 3: {
      const std::string axis(1, "xyz"[static_cast<int>(3.0 * u(rng)) % 3]);
      d.effect = {"gyro_scale_error", {{"scale_" + axis, 1.0 + sign() * (0.03 + 0.07 * u(rng))}}};
      break;
    }
    case 4: {
      // A magnetometer bias following the drive torque, in a random direction with |k| from about 3x its std
      // (about 1.5e-4 per axis) to large; scored on its largest axis.
      Eigen::Vector3d k(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5);
      k = k.normalized() * (5e-4 + 2.5e-3 * u(rng));
      Eigen::Index axis = 0;
      k.cwiseAbs().maxCoeff(&axis);
      d.effect = {"magnetometer_motor_interference", {{"b_per_nm_x", k.x()}, {"b_per_nm_y", k.y()}, {"b_per_nm_z", k.z()}}};
      d.parameter = std::string("b_per_nm_") + "xyz"[axis];
      return d;
    }
    case 5:
      // The rear tires' slip per m/s^2 of traction (std about 0.001 s^2/m on the 30 s drive: 0.007 named, 0.005 not,
      // README), to large.
      d.effect = {"longitudinal_slip", {{"slip_per_mps2", 0.007 + 0.043 * u(rng)}}};
      break;
    case 6:
      // The slip per m/s^2 of slope (std about 0.0014 s^2/m: 0.005 named, 0.003 not, README), to large.
      d.effect = {"slope_slip", {{"slip_per_mps2", 0.005 + 0.045 * u(rng)}}};
      break;
    case 7:
      // Softer tires: the contact time constant times 3-4, the rear cornering compliance +0.041-0.061 s (std about
      // 0.0036 s; at x2 the diagnosis named gyro_scale_error first, at x1.5 nothing: README). Scored on the
      // compliance measured on the truth (gapbench::RearCorneringCompliance), the candidate's cornering_rear_s.
      d.effect = {"lateral_slip", {{"contact_time_scale", 3.0 + u(rng)}}};
      d.parameter = "cornering_rear_s";
      return d;
    default:
      gyro_bias(std::string(1, "xyz"[static_cast<int>(3.0 * u(rng)) % 3]));
  }
  d.parameter = d.effect.parameters.begin()->first;
  return d;
}

// Runs fn(0..n-1) on `jobs` threads with a progress bar; the first error stops the rest.
Status RunParallel(int n, int jobs, const std::string& label, bool quiet,
                   const std::function<Result<std::string>(int)>& fn) {
  std::atomic<int> next{0};
  std::mutex mutex;
  int done = 0;
  Status first_error = Status::Ok();
  const auto start = std::chrono::steady_clock::now();
  const auto bar = [&] {
    constexpr int kWidth = 30;
    const int filled = n > 0 ? kWidth * done / n : kWidth;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::ostringstream s;
    s << "\r" << label << " [" << std::string(filled, '#') << std::string(kWidth - filled, '.') << "] " << done
      << "/" << n << "  " << std::fixed << std::setprecision(0) << elapsed << " s";
    if (done > 0 && done < n) s << ", about " << elapsed / done * (n - done) << " s left";
    std::cout << s.str() << std::flush;
  };
  if (!quiet) bar();
  const auto worker = [&] {
    for (int i = next++; i < n; i = next++) {
      {
        std::lock_guard<std::mutex> lock(mutex);
        if (!first_error.ok()) return;
      }
      Result<std::string> line = fn(i);
      std::lock_guard<std::mutex> lock(mutex);
      ++done;
      if (!line.ok() && first_error.ok()) first_error = line.status();
      if (!quiet) {
        std::cout << "\r" << std::string(100, ' ') << "\r" << (line.ok() ? line.value() : line.status().message())
                  << "\n";
        bar();
      }
    }
  };
  std::vector<std::thread> threads;
  for (int k = 0; k < std::max(1, std::min(jobs, n)); ++k) threads.emplace_back(worker);
  for (std::thread& t : threads) t.join();
  if (!quiet) std::cout << "\n";
  return first_error;
}

Result<Platform> LoadPlatform(const std::string& name, const std::string& path, const std::string& kind,
                              double duration_s) {
  auto scenario = sim::LoadScenario(path);
  if (!scenario.ok()) return scenario.status();
  if (scenario.value().robot.kind != kind)
    return Status::Error(path + ": the " + name + " scenario must describe a robot of kind '" + kind + "', not '" +
                         scenario.value().robot.kind + "'");
  auto config = gap::NominalConfig(scenario.value());
  if (!config.ok()) return Status::Error(path + ": " + config.status().message());
  Platform p;
  p.name = name;
  p.scenario = scenario.value();
  p.scenario.effects.clear();
  if (duration_s > 0.0) p.scenario.duration_s = duration_s;
  p.config = config.value();
  return p;
}

// The thresholds the diagnosis is run with, and whether it evaluates every passing candidate on the held-out part.
struct CaseSetup {
  Thresholds thresholds;
  bool heldout_all = false;
};

// Simulates, writes, diagnoses blind, then reads truth.yaml and fills the case.
Result<CaseResult> RunCase(const Platform& platform, const Draw& draw, std::uint64_t noise_seed,
                           const std::string& id, const std::string& dir, const CaseSetup& setup) {
  const auto start = std::chrono::steady_clock::now();
  sim::Scenario s = platform.scenario;
  if (draw.kind != "none") s.effects.push_back(draw.effect);
  sim::SimulateOptions options;
  options.seed = noise_seed;
  auto simulated = sim::Simulate(s, options);
  if (!simulated.ok()) return Status::Error("simulation: " + simulated.status().message());
  const std::string rec_dir = dir + "/rec";
  std::error_code ec;
  std::filesystem::create_directories(rec_dir, ec);
  if (ec) return Status::Error(rec_dir + ": cannot create the directory");
  if (Status st = recording::WriteRecording(simulated.value().recording, rec_dir); !st.ok()) return st;
  if (Status st = recording::WriteTruth(simulated.value().truth, rec_dir); !st.ok()) return st;

  // Blind: the diagnosis reads the written recording's streams only.
  recording::ReadOptions read;
  read.load_ground_truth = false;
  auto rec = recording::ReadRecording(rec_dir, read);
  if (!rec.ok()) return rec.status();
  gap::DiagnoseOptions d_options;
  d_options.baseline = &platform.baseline;
  d_options.alpha = setup.thresholds.alpha;
  d_options.max_delta_bic = setup.thresholds.max_delta_bic;
  d_options.min_heldout_improvement = setup.thresholds.min_heldout_improvement;
  d_options.min_explained_share = setup.thresholds.min_explained_share;
  d_options.heldout_all_candidates = setup.heldout_all;
  auto diagnosed = gap::Diagnose(platform.config, rec.value(), d_options);
  if (!diagnosed.ok()) return Status::Error("diagnosis: " + diagnosed.status().message());
  const gap::Diagnosis& d = diagnosed.value();
  // The diagnosis as `roamlab diagnose` writes it (located components, candidates, held-out fit before and after),
  // for the study of a case.
  // The nominal scenario simulated again, as believed and with the accepted effects, against the held-out part.
  auto simulation = gap::CompareWithSimulation(platform.scenario, d.effects, rec.value(), d.train_end_s);
  if (!simulation.ok()) return Status::Error("re-simulation: " + simulation.status().message());
  std::ofstream(dir + "/gap.json") << DiagnosisJson(d, &platform.baseline, kBaselineSeed, &simulation.value()).dump(2)
                                   << "\n";

  CaseResult c;
  c.id = id;
  c.platform = platform.name;
  c.kind = draw.kind;
  c.verdict = d.verdict;
  for (const gap::EffectEstimate& e : d.effects) c.named.push_back(e.name);
  c.ranked = c.named;
  for (const gap::EffectEstimate& e : d.candidates) {   // in order of Delta BIC
    if (std::find(c.ranked.begin(), c.ranked.end(), e.name) == c.ranked.end()) c.ranked.push_back(e.name);
    gapbench::CandidateStats stats{e.name, e.lr_pvalue, e.delta_bic, e.evaluated_heldout, e.heldout_improvement,
                                   e.std, e.explained_share};
    c.candidates.push_back(stats);
  }

  // Scoring: now, and only now, the truth.
  auto truth = recording::ReadTruth(rec_dir);
  if (!truth.ok()) return truth.status();
  if (draw.kind != "none") {
    if (truth.value().effects.empty()) return Status::Error(rec_dir + "/truth.yaml: the hidden effect is missing");
    const auto& effect = truth.value().effects.front();
    c.truth_name = effect.name;
    c.truth_parameter = draw.parameter;
    const auto value = effect.parameters.find(draw.parameter);
    c.truth_value = value != effect.parameters.end() ? value->second : 0.0;
    // Softer tires: their size in the candidate's units, the compliance on this drive's truth minus the nominal's
    // (the physics does not depend on the noise seed).
    if (effect.name == "lateral_slip" && simulated.value().recording.ground_truth)
      c.truth_value =
          gapbench::RearCorneringCompliance(*simulated.value().recording.ground_truth) - platform.rear_compliance_s;
  }
  if (draw.kind == "effect") {
    for (const gap::EffectEstimate& e : d.effects) {
      if (e.name != c.truth_name || !e.parameters.count(c.truth_parameter)) continue;
      c.estimate = e.parameters.at(c.truth_parameter);
      c.has_estimate = true;
      break;
    }
    const std::string stream = AffectedStream(c.truth_name);
    if (d.before.count(stream) && d.after.count(stream)) {
      c.rms_before = d.before.at(stream).rms;
      c.rms_after = d.after.at(stream).rms;
      c.rms_1s_before = d.before.at(stream).rms_1s;
      c.rms_1s_after = d.after.at(stream).rms_1s;
      c.has_rms = true;
    }
    c.sim_stream = SimulatedStream(c.truth_name);
    const auto before = simulation.value().before.find(c.sim_stream);
    const auto after = simulation.value().after.find(c.sim_stream);
    if (before != simulation.value().before.end() && after != simulation.value().after.end()) {
      c.sim_rms_before = before->second.rms;
      c.sim_rms_after = after->second.rms;
      c.sim_rms_1s_before = before->second.rms_1s;
      c.sim_rms_1s_after = after->second.rms_1s;
      c.has_sim_rms = true;
    }
  }
  c.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::ofstream(dir + "/case.json") << gapbench::CaseRow(c).dump(2) << "\n";
  return c;
}

std::string CaseLine(const CaseResult& c) {
  std::ostringstream s;
  s << c.id << " " << c.platform << " " << c.kind;
  if (!c.truth_name.empty()) s << " " << c.truth_name << " " << c.truth_parameter << "=" << c.truth_value;
  if (c.noise_ratio >= 0.0) s << std::setprecision(3) << " (" << c.noise_ratio << "x noise)";
  s << " -> " << c.verdict;
  if (!c.named.empty()) s << " " << c.named.front();
  if (c.has_estimate) s << " " << c.estimate;
  s << std::fixed << std::setprecision(0) << " [" << c.seconds << " s]";
  return s.str();
}

// Draws and runs one phase's cases (stratified: kinds by gapbench::CalibrationKind; else blind); results in draw
// order.
Result<std::vector<CaseResult>> RunPhase(const std::vector<Platform>& platforms, int n, std::uint64_t draw_seed,
                                         std::uint64_t noise_seed0, bool stratified, const std::string& dir,
                                         const CaseSetup& setup, const std::string& label,
                                         const GapBenchmarkArgs& args) {
  std::mt19937_64 rng(draw_seed);
  std::vector<Draw> draws;
  for (int i = 0; i < n; ++i)   // all drawn first: independent of scheduling
    draws.push_back(DrawCase(rng, stratified ? gapbench::CalibrationKind(i) : std::string()));
  std::vector<CaseResult> results(static_cast<std::size_t>(n));
  const Status st = RunParallel(n, args.jobs, label, args.quiet, [&](int i) -> Result<std::string> {
    std::ostringstream id;
    id << std::setw(3) << std::setfill('0') << i;
    const Draw& draw = draws[static_cast<std::size_t>(i)];
    auto c = RunCase(platforms[static_cast<std::size_t>(draw.platform)], draw,
                     noise_seed0 + static_cast<std::uint64_t>(i), id.str(), dir + "/" + id.str(), setup);
    if (!c.ok()) return Status::Error(label + " case " + id.str() + ": " + c.status().message());
    results[static_cast<std::size_t>(i)] = c.value();
    return CaseLine(c.value());
  });
  if (!st.ok()) return st;
  return results;
}

double SecondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

int RunGapBenchmark(const GapBenchmarkArgs& args) {
  std::ostream& err = args.err ? *args.err : std::cerr;
  if (args.cases < 1 || args.cases > kMaxCases || args.calibration_cases < 1 || args.calibration_cases > kMaxCases) {
    err << "roamlab gap-benchmark: --cases and --calibration-cases must be in [1, " << kMaxCases << "]\n";
    return 2;
  }
  if (args.jobs < 1) {
    err << "roamlab gap-benchmark: --jobs must be >= 1\n";
    return 2;
  }
  if (args.duration_s < 0.0) {
    err << "roamlab gap-benchmark: --duration must be positive\n";
    return 2;
  }
  std::vector<Platform> platforms;
  for (const auto& [name, path, kind] : {std::make_tuple("atv", args.atv_scenario, "ackermann"),
                                         std::make_tuple("diffdrive", args.diffdrive_scenario, "differential_drive"),
                                         std::make_tuple("mecanum", args.mecanum_scenario, "mecanum")}) {
    auto p = LoadPlatform(name, path, kind, args.duration_s);
    if (!p.ok()) {
      err << "roamlab gap-benchmark: " << p.status().message() << "\n";
      return 2;
    }
    platforms.push_back(std::move(p).value());
  }
  std::error_code ec;
  std::filesystem::create_directories(args.out, ec);
  if (ec) {
    err << "roamlab gap-benchmark: " << args.out << ": cannot create the output directory\n";
    return 2;
  }
  const auto start = std::chrono::steady_clock::now();

  // The baselines, once per platform (in parallel).
  const Status base = RunParallel(static_cast<int>(platforms.size()), args.jobs, "baselines", args.quiet,
                                  [&](int i) -> Result<std::string> {
    Platform& p = platforms[static_cast<std::size_t>(i)];
    sim::SimulateOptions options;
    options.seed = kBaselineSeed;
    auto simulated = sim::Simulate(p.scenario, options);
    if (!simulated.ok()) return Status::Error(p.name + " nominal simulation: " + simulated.status().message());
    gap::DiagnoseOptions learn;
    learn.max_effects = 0;
    auto learned = gap::Diagnose(p.config, simulated.value().recording, learn);
    if (!learned.ok()) return Status::Error(p.name + " baseline: " + learned.status().message());
    p.baseline = gap::BaselineFrom(learned.value());
    if (p.name == "atv" && simulated.value().recording.ground_truth)
      p.rear_compliance_s = gapbench::RearCorneringCompliance(*simulated.value().recording.ground_truth);
    return p.name + " baseline learned (noise seed " + std::to_string(kBaselineSeed) + ")";
  });
  if (!base.ok()) {
    err << "roamlab gap-benchmark: " << base.message() << "\n";
    return 1;
  }
  const double baseline_s = SecondsSince(start);

  // 1. Calibration: the loosest thresholds, every passing candidate evaluated on the held-out part.
  const auto calibration_start = std::chrono::steady_clock::now();
  CaseSetup loose{gapbench::Loosest(), true};
  const std::uint64_t calibration_seed = args.seed * 1000 + kMaxCases;
  auto calibration = RunPhase(platforms, args.calibration_cases, calibration_seed, calibration_seed, true,
                              args.out + "/calibration", loose, "calibration", args);
  if (!calibration.ok()) {
    err << "roamlab gap-benchmark: " << calibration.status().message() << "\n";
    return 1;
  }
  json grid;
  // The targets on the effect-free cases, imposed on the calibration with the score's rule.
  const double max_decoy_false_rate = 1.0 - gapbench::kMinDecoysUnknown;
  const Thresholds chosen =
      gapbench::ChooseThresholds(calibration.value(), gapbench::kMaxNoneFalseRate, max_decoy_false_rate, &grid);
  const auto sigmas = gapbench::CalibrationSigmas(calibration.value());
  json calibration_rows = json::array();
  for (CaseResult& c : calibration.value()) {
    if (c.kind == "effect")
      c.noise_ratio = gapbench::NoiseRatio(sigmas, c.platform, c.truth_name, c.truth_parameter, c.truth_value);
    json row = gapbench::CaseRow(c);
    row["replayed_first_round"] = gapbench::ReplayFirstRound(c.candidates, chosen);
    calibration_rows.push_back(row);
  }
  const double calibration_s = SecondsSince(calibration_start);
  const json thresholds = {{"alpha", chosen.alpha},
                           {"max_delta_bic", chosen.max_delta_bic},
                           {"min_heldout_improvement", chosen.min_heldout_improvement},
                           {"min_explained_share", chosen.min_explained_share}};
  if (!args.quiet) std::cout << "thresholds from the calibration cases: " << thresholds.dump() << "\n";

  // 2. The scored cases, diagnosed with the chosen thresholds.
  const auto scored_start = std::chrono::steady_clock::now();
  auto scored = RunPhase(platforms, args.cases, args.seed, args.seed * 1000, false, args.out + "/cases",
                         {chosen, false}, "scored", args);
  if (!scored.ok()) {
    err << "roamlab gap-benchmark: " << scored.status().message() << "\n";
    return 1;
  }
  json rows = json::array();
  for (CaseResult& c : scored.value()) {
    if (c.kind == "effect")
      c.noise_ratio = gapbench::NoiseRatio(sigmas, c.platform, c.truth_name, c.truth_parameter, c.truth_value);
    rows.push_back(gapbench::CaseRow(c));
  }
  const double scored_s = SecondsSince(scored_start);
  const double total_s = SecondsSince(start);
  json sigma_json = json::object();
  for (const auto& [platform, by_parameter] : sigmas)
    for (const auto& [key, sigma] : by_parameter) sigma_json[platform][key] = sigma;
  const json figures = gapbench::Summarize(scored.value());
  const json score = {
      {"seed", args.seed},
      {"jobs", args.jobs},
      {"duration_s",
       {{"atv", platforms[0].scenario.duration_s},
        {"diffdrive", platforms[1].scenario.duration_s},
        {"mecanum", platforms[2].scenario.duration_s}}},
      {"figures", figures},
      {"thresholds", thresholds},
      {"calibration",
       {{"cases", calibration_rows},
        {"draw_and_noise_seed_base", calibration_seed},
        {"max_none_false_rate", gapbench::kMaxNoneFalseRate},
        {"max_decoy_false_rate", max_decoy_false_rate},
        {"grid", grid},
        {"noise_sigmas", sigma_json}}},
      {"cases", rows},
      {"seconds",
       {{"total", total_s},
        {"baselines", baseline_s},
        {"calibration", calibration_s},
        {"scored", scored_s},
        {"extrapolated_total_for_60_scored_cases", baseline_s + calibration_s + scored_s / args.cases * 60.0}}}};
  std::ofstream out(args.out + "/score.json");
  out << score.dump(2) << "\n";
  if (!out) {
    err << "roamlab gap-benchmark: " << args.out << "/score.json: cannot write\n";
    return 1;
  }
  if (!args.quiet) {
    std::cout << "figures: " << figures.dump() << "\n"
              << "total " << std::fixed << std::setprecision(0) << total_s << " s (" << args.out << "/score.json)\n";
  }
  return 0;
}

}  // namespace roamlab::apps
