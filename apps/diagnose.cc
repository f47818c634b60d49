#include "apps/diagnose.h"

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "estimator/config.h"
#include "gap/diagnose.h"
#include "gap/nominal_config.h"
#include "gap/report.h"
#include "gap/resimulate.h"
#include "recording/recording.h"
#include "sim/scenario.h"

namespace roamlab::apps {
namespace {

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
  double span_s = 0.0;   // the recording's last stamp
};

// The inputs, checked against each other; errors are bad input (exit 2).
Result<Inputs> LoadInputs(const DiagnoseArgs& args) {
  if (args.scenario.empty() && (args.config.empty() || !args.no_baseline))
    return Status::Error("without --scenario, give the nominal model as --config EST.yaml and --no-baseline");
  Inputs in;
  if (!args.scenario.empty()) {
    auto loaded = sim::LoadScenario(args.scenario);
    if (!loaded.ok()) return loaded.status();
    in.scenario = std::move(loaded).value();
  }
  recording::ReadOptions read;
  read.load_ground_truth = false;
  auto rec = recording::ReadRecording(args.recording, read);
  if (!rec.ok()) return rec.status();
  in.recording = std::move(rec).value();
  if (in.scenario && in.recording.platform.kind != in.scenario->robot.kind)
    return Status::Error(args.recording + ": platform kind '" + in.recording.platform.kind +
                         "' does not match the robot kind '" + in.scenario->robot.kind + "' of " + args.scenario);
  auto config = args.config.empty() ? gap::NominalConfig(*in.scenario) : estimator::LoadEstimatorConfig(args.config);
  if (!config.ok())
    return Status::Error((args.config.empty() ? args.scenario + ": " : std::string()) + config.status().message());
  in.config = std::move(config).value();
  for (const auto& [name, stream] : in.config.streams)
    for (const auto& [role, source] : stream.sources)
      if (!in.recording.Find(source))
        return Status::Error(args.recording + ": no stream '" + source + "' (the nominal model's stream '" + name +
                             "' reads it)");
  std::error_code ec;
  std::filesystem::create_directories(args.out, ec);
  if (ec) return Status::Error(args.out + ": cannot create the output directory: " + ec.message());
  for (const recording::Stream& s : in.recording.streams)
    if (!s.t.empty()) in.span_s = std::max(in.span_s, s.t.back().seconds());
  // The held-out third loses twice the range of its position fixes at each end (the diagnosis's slices).
  if (args.max_shift_s && (!(*args.max_shift_s > 0.0) || !(*args.max_shift_s < in.span_s / 12.0)))
    return Status::Error("--max-shift " + Fixed(*args.max_shift_s, 3) + " s: must be above 0 and below " +
                         Fixed(in.span_s / 12.0, 3) + " s, 1/12 of " + args.recording + "'s span");
  return in;
}

}  // namespace

int RunDiagnose(const DiagnoseArgs& args) {
  std::ostream& err = args.err ? *args.err : std::cerr;
  const auto say = [&](const std::string& line) {
    if (!args.quiet) std::cout << line << std::endl;
  };
  auto inputs = LoadInputs(args);
  if (!inputs.ok()) {
    err << "roamlab diagnose: " << inputs.status().message() << "\n";
    return 2;
  }
  const Inputs& in = inputs.value();
  const auto fail = [&](const std::string& message) {
    err << "roamlab diagnose: " << message << "\n";
    return 1;
  };
  gap::DiagnoseOptions options;
  options.progress = [&](const std::string& line) { say("  " + line); };
  if (args.max_shift_s) options.max_shift_s = *args.max_shift_s;

  // The baseline: the nominal scenario simulated over the recording's span and diagnosed without effects.
  gap::Baseline baseline;
  if (!args.no_baseline) {
    sim::Scenario nominal = *in.scenario;
    nominal.duration_s = std::min(nominal.duration_s, std::max(in.span_s, 1.0));
    gap::LearnBaselineOptions learn;
    learn.seed = args.baseline_seed;
    learn.diagnose = options;
    learn.progress = say;
    auto learned = gap::LearnBaseline(nominal, in.config, learn);
    if (!learned.ok()) return fail(learned.status().message());
    baseline = std::move(learned).value().baseline;
    options.baseline = &baseline;
  }

  say("diagnosing " + args.recording);
  auto diagnosis = gap::Diagnose(in.config, in.recording, options);
  if (!diagnosis.ok()) return fail(diagnosis.status().message());
  const gap::Diagnosis& d = diagnosis.value();

  // The simulation again, as believed and with the accepted effects, against the recording's held-out part.
  std::optional<gap::SimulationComparison> simulation;
  if (in.scenario) {
    say("re-simulating the nominal scenario without noise, as believed and with the accepted effects");
    auto compared = gap::CompareWithSimulation(*in.scenario, d.effects, in.recording, d.train_end_s);
    if (!compared.ok()) return fail("re-simulation: " + compared.status().message());
    simulation = std::move(compared).value();
  }

  gap::ReportInputs report;
  report.recording = args.recording;
  report.model = args.scenario.empty() ? args.config : args.scenario;
  report.baseline = args.no_baseline ? nullptr : &baseline;
  report.baseline_seed = args.baseline_seed;
  report.simulation = simulation ? &*simulation : nullptr;
  report.plots = !args.no_plots;
  report.progress = say;
  if (Status s = gap::WriteReport(d, report, args.out); !s.ok()) return fail(s.message());
  std::string summary = "verdict: " + d.verdict;
  for (const gap::EffectEstimate& e : d.effects) {
    summary += "; " + e.name;
    for (const auto& [k, v] : e.parameters) summary += " " + k + " = " + Fixed(v, 4);
  }
  say(summary + " (" + args.out + "/report.md)");
  return 0;
}

}  // namespace roamlab::apps
