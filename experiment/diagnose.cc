#include "experiment/diagnose.h"

#include <algorithm>
#include <filesystem>
#include <optional>
#include <sstream>

#include "common/atomic_file.h"
#include "common/interrupt.h"
#include "estimator/calibration.h"
#include "estimator/config.h"
#include "experiment/init.h"
#include "gap/nominal_config.h"
#include "gap/report.h"
#include "gap/resimulate.h"
#include "gap/twin.h"
#include "recording/recording.h"
#include "sim/scenario.h"

namespace roamlab::experiment {
namespace {

using StdMethod = estimator::CalibrationOptions::StdMethod;

// --std: auto | white | hac.
StdMethod ParseStdMethod(const std::string& method) {
  return method == "white" ? StdMethod::kWhite : method == "hac" ? StdMethod::kHac : StdMethod::kAuto;
}

std::string Fixed(double x, int digits) {
  std::ostringstream s;
  s.precision(digits);
  s << x;
  return s.str();
}

// What the diagnosis reads: the nominal scenario (none for a robot without a MuJoCo twin), the recording's streams
// (never its truth.yaml), the nominal configuration.
struct Inputs {
  std::optional<sim::Scenario> scenario;
  recording::Recording recording;
  estimator::EstimatorConfig config;
  double span_s = 0.0;  // from the recording's first stamp to its last (stamps may be absolute, e.g. Unix time)
};

// The nominal model: the configuration given, or the one built from the scenario; every stream it reads present.
Status LoadNominalModel(const DiagnoseRequest& request, Inputs* in) {
  auto config =
      request.config.empty() ? gap::NominalConfig(*in->scenario) : estimator::LoadEstimatorConfig(request.config);
  if (!config.ok())
    return Status::Error((request.config.empty() ? request.scenario + ": " : std::string()) +
                         config.status().message());
  in->config = std::move(config).value();
  for (const auto& [name, stream] : in->config.streams)
    for (const auto& [role, source] : stream.sources)
      if (!in->recording.Find(source))
        return Status::Error(request.recording + ": no stream '" + source + "' (the nominal model's stream '" + name +
                             "' reads it)");
  return Status::Ok();
}

// The inputs, checked against each other; errors are bad input.
Result<Inputs> LoadInputs(const DiagnoseRequest& request) {
  if (request.scenario.empty() && (request.config.empty() || !request.no_baseline))
    return Status::Error(
        "without --scenario, a --config EST.yaml needs --no-baseline (with neither, roamlab init's configuration is "
        "used)");
  Inputs in;
  if (!request.scenario.empty()) {
    auto loaded = sim::LoadScenario(request.scenario);
    if (!loaded.ok()) return loaded.status();
    in.scenario = std::move(loaded).value();
    // The diagnosis names what the nominal model leaves out; a scenario with effects (one patched with a diagnosis's
    // scenario_patch.yaml, say) is not the nominal one, and its effects would not be in the model compared with.
    if (!in.scenario->effects.empty()) {
      std::string names;
      for (const sim::EffectOptions& e : in.scenario->effects) names += (names.empty() ? "" : ", ") + e.name;
      return Status::Error(request.scenario + ": has effects (" + names +
                           "); diagnose compares the recording with the nominal model: give the scenario without them");
    }
  }
  recording::ReadOptions read;
  read.load_ground_truth = false;
  auto rec = recording::ReadRecording(request.recording, read);
  if (!rec.ok()) return rec.status();
  in.recording = std::move(rec).value();
  if (in.scenario && in.recording.platform.kind != in.scenario->robot.kind)
    return Status::Error(request.recording + ": platform kind '" + in.recording.platform.kind +
                         "' does not match the robot kind '" + in.scenario->robot.kind + "' of " + request.scenario);
  if (Status s = LoadNominalModel(request, &in); !s.ok()) return s;
  if (Status s = MakeOutputDirectory(request.out); !s.ok()) return s;
  std::optional<Time> first, last;
  for (const recording::Stream& s : in.recording.streams) {
    if (s.t.empty()) continue;
    if (!first || s.t.front() < *first) first = s.t.front();
    if (!last || *last < s.t.back()) last = s.t.back();
  }
  if (first) in.span_s = SecondsBetween(*first, *last);
  // The held-out third loses twice the range of its position fixes at each end (the diagnosis's slices).
  if (request.max_shift_s && (!(*request.max_shift_s > 0.0) || !(*request.max_shift_s < in.span_s / 12.0)))
    return Status::Error("--max-shift " + Fixed(*request.max_shift_s, 3) + " s: must be above 0 and below " +
                         Fixed(in.span_s / 12.0, 3) + " s, 1/12 of " + request.recording + "'s span");
  return in;
}

// The baseline: the nominal scenario simulated over the recording's span and diagnosed without effects.
Result<gap::Baseline> NominalBaseline(const DiagnoseRequest& request, const Inputs& in,
                                      const gap::DiagnoseOptions& options) {
  sim::Scenario nominal = *in.scenario;
  nominal.duration_s = std::min(nominal.duration_s, std::max(in.span_s, 1.0));
  gap::LearnBaselineOptions learn;
  learn.seed = request.baseline_seed;
  learn.diagnose = options;
  learn.progress = request.progress;
  auto learned = gap::LearnBaseline(nominal, in.config, learn);
  if (!learned.ok()) return learned.status();
  return std::move(learned).value().baseline;
}

// The scenario's twin of `rec` (read from `path`), as `request.drive` says, and its runner; errors are bad input.
Result<gap::TwinChoice> ChooseTwin(const sim::Scenario& scenario, const recording::Recording& rec,
                                   const std::string& path, gap::TwinDrive drive,
                                   const std::function<void(const std::string&)>& say) {
  auto choice = gap::ChooseTwin(scenario, rec, drive);
  if (!choice.ok()) return Status::Error(path + ": " + choice.status().message());
  const gap::TwinChoice& c = choice.value();
  std::string line = path + ": " + c.reason;
  if (c.mismatch) line += " (" + c.stream + " differs from the scenario's own drive by " + Fixed(*c.mismatch, 3) + ")";
  say(line + (c.replayed ? ": the twin replays the recorded drive" : ": the twin is the scenario's own drive"));
  return choice;
}

gap::TwinRunner Runner(const gap::TwinChoice& choice, const recording::Recording& rec) {
  return choice.replayed ? gap::ReplayRunner(rec) : gap::PlainSimulationRunner();
}

// A held-out or training recording with its twin's runner; errors are bad input.
struct HeldOut {
  std::string path;
  recording::Recording recording;
  gap::TwinRunner runner;
  bool replayed = false;
};
Result<std::vector<HeldOut>> LoadOtherRuns(const DiagnoseRequest& request, const std::vector<std::string>& paths,
                                           const sim::Scenario& scenario,
                                           const std::function<void(const std::string&)>& say) {
  std::vector<HeldOut> out;
  for (const std::string& path : paths) {
    recording::ReadOptions read;
    read.load_ground_truth = false;
    auto rec = recording::ReadRecording(path, read);
    if (!rec.ok()) return rec.status();
    if (rec.value().platform.kind != scenario.robot.kind)
      return Status::Error(path + ": platform kind '" + rec.value().platform.kind +
                           "' does not match the robot kind '" + scenario.robot.kind + "' of " + request.scenario);
    HeldOut h{path, std::move(rec).value(), {}, false};
    auto choice = ChooseTwin(scenario, h.recording, path, request.drive, say);
    if (!choice.ok()) return choice.status();
    h.runner = Runner(choice.value(), h.recording);
    h.replayed = choice.value().replayed;
    out.push_back(std::move(h));
  }
  return out;
}

// Each of `names` a twin candidate `scenario` supports.
Status CheckTwinCandidates(const std::vector<std::string>& names, const sim::Scenario& scenario) {
  const std::vector<std::string> known = gap::TwinCandidateNames(scenario);
  for (const std::string& name : names)
    if (std::find(known.begin(), known.end(), name) == known.end()) {
      std::string list;
      for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
      return Status::Error("--twin-candidates: '" + name + "' is not a twin candidate of the scenario (" + list + ")");
    }
  return Status::Ok();
}

// A drive's clock (drive_time_offset) shifts a replay's recorded inputs: named as a candidate, every training run must
// be replayed. The first run twinned by the plain simulation of its own drive, or "".
std::string NotReplayedForTheDriveClock(const DiagnoseRequest& request, const gap::TwinChoice& twin,
                                        const std::vector<HeldOut>& training) {
  const auto& names = request.twin_candidates;
  if (std::find(names.begin(), names.end(), "drive_time_offset") == names.end()) return "";
  if (!twin.replayed) return request.recording;
  for (const HeldOut& t : training)
    if (!t.replayed) return t.path;
  return "";
}

std::string Millimetres(double m) { return Fixed(1e3 * m, 3) + " mm"; }

// The diagnosis against the scenario's twin (runner: ChooseTwin's), fitted on the recording and the training runs,
// its patch shown on the held-out recordings, into out/twin.json; `out` receives it.
Outcome DiagnoseTwinToFile(const DiagnoseRequest& request, const Inputs& in, const gap::TwinRunner& runner,
                           bool replayed, const std::vector<HeldOut>& training, const std::vector<HeldOut>& held_out,
                           gap::TwinDiagnosis* out, const std::function<void(const std::string&)>& say) {
  say("diagnosing " + request.recording + " against the scenario's twin" + (replayed ? " (replayed)" : "") +
      (training.empty() ? "" : ", fitted with " + std::to_string(training.size()) + " further training runs"));
  gap::TwinDiagnoseOptions options;
  options.replayed = replayed;
  options.std_method = ParseStdMethod(request.std_method);
  options.progress = [&](const std::string& line) { say("  " + line); };
  if (request.max_shift_s) options.max_shift_s = *request.max_shift_s;
  if (request.max_effects) options.max_effects = *request.max_effects;
  if (request.train_weight == "runs") options.train_weight = gap::TwinDiagnoseOptions::TrainWeight::kRuns;
  options.candidates = request.twin_candidates;
  std::vector<gap::TwinTrainingRun> runs = {{request.recording, &in.recording, runner, replayed}};
  for (const HeldOut& t : training) runs.push_back({t.path, &t.recording, t.runner, t.replayed});
  auto diagnosed = gap::DiagnoseTwin(*in.scenario, runs, options);
  if (!diagnosed.ok()) return Outcome::Failed(Status::Error("twin: " + diagnosed.status().message()));
  gap::TwinDiagnosis& d = diagnosed.value();
  for (const HeldOut& h : held_out) {
    const gap::TwinResidualOptions residuals =
        h.replayed ? gap::ReplayedResidualOptions(*in.scenario, h.recording, options.increment_window_s)
                   : gap::TwinResidualOptions{};
    auto shown =
        gap::ShowOnHeldOut(*in.scenario, d.patch, h.recording, h.runner, options.drift, options.threads, residuals);
    if (!shown.ok())
      return Outcome::Failed(Status::Error("twin, held out " + h.path + ": " + shown.status().message()));
    shown.value().recording = h.path;
    shown.value().replayed = h.replayed;
    for (const auto& [stream, before] : shown.value().before.drift)
      if (const auto after = shown.value().after.drift.find(stream); after != shown.value().after.drift.end())
        say("twin, held out " + h.path + ": " + stream + " " + Fixed(before.window_s, 3) + " s drift " +
            Millimetres(before.mean_position_m) + " -> " + Millimetres(after->second.mean_position_m));
    d.heldout_runs.push_back(std::move(shown).value());
  }
  const std::string path = (std::filesystem::path(request.out) / "twin.json").string();
  if (Status s = WriteFileAtomic(path, gap::TwinDiagnosisJson(d).dump(2) + "\n"); !s.ok()) return Outcome::Failed(s);
  say("twin: " + d.verdict + ", std " + d.std_method + " (" + path + ")");
  *out = std::move(d);
  return Outcome::Ok();
}

// The outputs of an earlier diagnosis in OUT, removed before this one starts so that an interrupted run leaves no mix
// of two runs: the report files, twin.json, the figures, and roamlab init's nominal configuration unless this run
// writes it (no scenario, no configuration) or reads it (it is the --config given).
Status RemoveEarlierOutputs(const DiagnoseRequest& given, const std::string& out) {
  std::vector<std::string> earlier = {"gap.json",  "scenario_patch.yaml", "estimator_patch.yaml",
                                      "report.md", "report.html",         "twin.json"};
  for (const char* stem : {"residual_vs_condition", "heldout_fit", "twin_top_view", "twin_residual_vs_condition"})
    for (const char* extension : {".dat", ".gp", ".png", ".log"}) earlier.push_back(std::string(stem) + extension);
  const std::filesystem::path init_config = std::filesystem::path(out) / kInitConfigFile;
  std::error_code ec;
  const bool given_config = !given.config.empty() && std::filesystem::equivalent(given.config, init_config, ec);
  if ((!given.scenario.empty() || !given.config.empty()) && !given_config) earlier.push_back(kInitConfigFile);
  for (const std::string& file : earlier)
    if (Status s = RemoveStaleFile((std::filesystem::path(out) / file).string()); !s.ok()) return s;
  return Status::Ok();
}

}  // namespace

Outcome DiagnoseToDirectory(const DiagnoseRequest& given, gap::Diagnosis* diagnosis, gap::TwinDiagnosis* twin_out) {
  const auto say = [&](const std::string& line) {
    if (given.progress) given.progress(line);
  };
  DiagnoseRequest request = given;
  if (request.scenario.empty() && request.config.empty()) {
    // No nominal model given: `roamlab init`'s, written beside the outputs; no MuJoCo twin, so no baseline.
    InitRequest init{request.recording, (std::filesystem::path(request.out) / kInitConfigFile).string(), ""};
    if (Outcome made = InitToFile(init); !made.ok()) return made;
    request.config = init.out;
    request.no_baseline = true;
    say("no --scenario and no --config: the nominal model is roamlab init's configuration of " + request.recording +
        " (" + init.out + "), without a baseline");
  }
  auto inputs = LoadInputs(request);
  if (!inputs.ok()) return Outcome::BadInput(inputs.status());
  const Inputs& in = inputs.value();
  std::optional<gap::TwinChoice> twin;
  std::vector<HeldOut> held_out, training;
  if (!request.held_out.empty() && !request.twin)
    return Outcome::BadInput(Status::Error("--held-out needs --twin (or --replay)"));
  if (!request.train_with.empty() && !request.twin)
    return Outcome::BadInput(Status::Error("--train-with needs --twin (or --replay)"));
  if (request.train_weight != "windows" && request.train_weight != "runs")
    return Outcome::BadInput(Status::Error("--train-weight " + request.train_weight + ": must be windows or runs"));
  if (request.max_effects && !(*request.max_effects >= 1))
    return Outcome::BadInput(
        Status::Error("--max-effects " + std::to_string(*request.max_effects) + ": must be 1 or more"));
  if ((request.twin || request.drive != gap::TwinDrive::kDetect) && !in.scenario)
    return Outcome::BadInput(Status::Error("--twin, --replay and --no-replay need --scenario"));
  if (!request.twin_candidates.empty()) {
    if (!request.twin) return Outcome::BadInput(Status::Error("--twin-candidates needs --twin (or --replay)"));
    if (Status s = CheckTwinCandidates(request.twin_candidates, *in.scenario); !s.ok()) return Outcome::BadInput(s);
  }
  if (in.scenario) {
    auto choice = ChooseTwin(*in.scenario, in.recording, request.recording, request.drive, say);
    if (!choice.ok()) return Outcome::BadInput(choice.status());
    twin = std::move(choice).value();
    auto loaded = LoadOtherRuns(request, request.held_out, *in.scenario, say);
    if (!loaded.ok()) return Outcome::BadInput(loaded.status());
    held_out = std::move(loaded).value();
    auto trained = LoadOtherRuns(request, request.train_with, *in.scenario, say);
    if (!trained.ok()) return Outcome::BadInput(trained.status());
    training = std::move(trained).value();
    if (const std::string run = NotReplayedForTheDriveClock(request, *twin, training); !run.empty())
      return Outcome::BadInput(
          Status::Error("--twin-candidates: 'drive_time_offset' shifts a replay's recorded drive inputs, and " + run +
                        " is twinned by the plain simulation of its own drive (--replay replays it)"));
  }
  if (Status s = RemoveEarlierOutputs(given, request.out); !s.ok()) return Outcome::Failed(s);
  IncompleteMarker marker(request.out);
  if (Status s = marker.Start(); !s.ok()) return Outcome::Failed(s);
  const auto failed = [&marker](const Status& status) {
    marker.SetMessage(status.message());
    return Outcome::Failed(status);
  };
  gap::DiagnoseOptions options;
  options.progress = [&](const std::string& line) { say("  " + line); };
  if (request.max_shift_s) options.max_shift_s = *request.max_shift_s;
  options.std_method = ParseStdMethod(request.std_method);

  gap::Baseline baseline;
  if (!request.no_baseline) {
    auto learned = NominalBaseline(request, in, options);
    if (!learned.ok()) return failed(learned.status());
    baseline = std::move(learned).value();
    options.baseline = &baseline;
    (void)marker.AddDone("the nominal baseline learned");
  }

  say("diagnosing " + request.recording);
  auto diagnosed = gap::Diagnose(in.config, in.recording, options);
  if (!diagnosed.ok()) return failed(diagnosed.status());
  const gap::Diagnosis& d = diagnosed.value();
  (void)marker.AddDone("the diagnosis");

  std::optional<gap::TwinDiagnosis> twin_diagnosis;
  if (request.twin) {
    twin_diagnosis.emplace();
    if (Outcome fitted = DiagnoseTwinToFile(request, in, Runner(*twin, in.recording), twin->replayed, training,
                                            held_out, &*twin_diagnosis, say);
        !fitted.ok())
      return failed(fitted.status);
  }

  // The twin again, as believed and with the accepted effects (the twin's patch when it was fitted), against the
  // recording's held-out part.
  std::optional<gap::SimulationComparison> simulation;
  if (in.scenario) {
    say(std::string("running the scenario's twin without noise (") + (twin->replayed ? "replayed" : "its own drive") +
        "), as believed and with the accepted effects");
    auto compared = gap::CompareWithSimulation(
        *in.scenario, d.effects, in.recording, d.train_end_s, *twin,
        twin_diagnosis ? std::optional<std::vector<sim::EffectOptions>>(twin_diagnosis->patch) : std::nullopt);
    if (!compared.ok()) return failed(Status::Error("re-simulation: " + compared.status().message()));
    simulation = std::move(compared).value();
    (void)marker.AddDone("the re-simulation");
  }

  gap::ReportInputs report;
  report.recording = request.recording;
  report.model = request.scenario.empty() ? request.config : request.scenario;
  report.baseline = request.no_baseline ? nullptr : &baseline;
  report.baseline_seed = request.baseline_seed;
  report.simulation = simulation ? &*simulation : nullptr;
  report.plots = !request.no_plots;
  report.real = &in.recording;
  report.twin = twin_diagnosis ? &*twin_diagnosis : nullptr;
  report.progress = say;
  if (Status s = gap::WriteReport(d, report, request.out); !s.ok()) return failed(s);
  (void)marker.AddDone("gap.json, the patches and the report");
  if (Status s = marker.Complete(); !s.ok()) return Outcome::Failed(s);
  if (diagnosis) *diagnosis = std::move(diagnosed).value();
  if (twin_out && twin_diagnosis) *twin_out = std::move(*twin_diagnosis);
  return Outcome::Ok();
}

}  // namespace roamlab::experiment
