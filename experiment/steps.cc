#include "experiment/steps.h"

#include <algorithm>
#include <filesystem>
#include <initializer_list>
#include <iomanip>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "common/atomic_file.h"
#include "common/interrupt.h"
#include "estimator/calibration_io.h"
#include "estimator/config.h"
#include "estimator/problem.h"
#include "estimator/tracking_io.h"
#include "importers/optiodom.h"
#include "recording/recording.h"
#include "recording/stream_health.h"
#include "recording/trajectory.h"
#include "recording/truth.h"
#include "sim/replay.h"
#include "sim/scenario.h"

namespace roamlab::experiment {
namespace {

// The configuration and the recording streams it reads (without the ground truth).
struct Inputs {
  estimator::EstimatorConfig config;
  recording::Recording recording;
};

// "[a, b] s" of a stream's first and last stamps.
std::string Span(const recording::Stream& stream) {
  return "[" + FormatSeconds(stream.t.front()) + ", " + FormatSeconds(stream.t.back()) + "] s";
}

std::string Seconds(double s) {
  std::ostringstream out;
  out << std::setprecision(4) << s;
  return out.str();
}

// What recording/stream_health.h finds in a source stream, one warning each: duplicated rows dropped by the reader,
// gaps (with, when the stream also runs past the master's end, the forward clock jump they suggest) and frozen runs.
void HealthWarnings(const recording::Stream& stream, const std::string& path, Time master_end,
                    std::vector<std::string>* warnings) {
  const std::string name = "stream '" + stream.info.name + "'";
  if (stream.duplicate_rows_dropped > 0) {
    warnings->push_back(path + ": " + std::to_string(stream.duplicate_rows_dropped) +
                        " rows repeat the row before them (duplicated messages); dropped");
  }
  const recording::StreamHealth health = recording::CheckStreamHealth(stream);
  const double past_end_s = std::max(0.0, SecondsBetween(master_end, stream.t.back()));
  for (const recording::StreamGap& gap : health.gaps) {
    std::string line = path + ": " + name + " has a gap of " + Seconds(gap.length_s) + " s after " +
                       FormatSeconds(gap.after) + " s (an outage, or its clock jumped)";
    if (past_end_s > 0.0)
      line += "; it also runs " + Seconds(past_end_s) +
              " s past the master's end: its clock looks to have jumped "
              "forward by about that much, so its later samples are stamped late";
    warnings->push_back(line);
  }
  for (const recording::FrozenRun& run : health.frozen) {
    warnings->push_back(path + ": " + name + " repeats one reading on " + std::to_string(run.rows) + " rows over [" +
                        FormatSeconds(run.first) + ", " + FormatSeconds(run.last) +
                        "] s: the sensor looks frozen; the rows after the first are not used");
  }
}

// Each configured source stream against the master's time span: an empty stream and one with samples outside the span
// are warnings naming it (with the count), a stream with no sample inside the span is an error (it would leave its
// parameters to the priors alone while the run claims to have used it).
Status CheckCoverage(const estimator::EstimatorConfig& config, const recording::Recording& rec,
                     const std::string& recording_dir, std::vector<std::string>* warnings) {
  const std::string& master_source = config.streams.at(config.master).sources.begin()->second;
  const recording::Stream* master = rec.Find(master_source);
  const std::string csv = recording_dir + "/" + master_source + ".csv";
  if (master == nullptr || master->t.size() < 2)
    return Status::Error(csv + ": the master stream '" + master_source + "' has fewer than two samples");
  std::set<std::string> sources;
  for (const auto& [name, stream] : config.streams)
    for (const auto& [role, source] : stream.sources) sources.insert(source);
  for (const std::string& source : sources) {
    const recording::Stream& stream = *rec.Find(source);
    const std::string path = recording_dir + "/" + source + ".csv";
    if (stream.t.empty()) {
      warnings->push_back(path + ": stream '" + source + "' is empty; it contributes nothing");
      continue;
    }
    const auto inside = std::count_if(stream.t.begin(), stream.t.end(),
                                      [&](Time t) { return t >= master->t.front() && t <= master->t.back(); });
    const std::string which =
        "of stream '" + source + "' " + Span(stream) + " within the master '" + master_source + "' " + Span(*master);
    if (inside == 0) return Status::Error(path + ": no sample " + which + ": the streams do not overlap in time");
    const std::size_t outside = stream.t.size() - static_cast<std::size_t>(inside);
    if (outside > 0) {
      warnings->push_back(path + ": " + std::to_string(outside) + " of " + std::to_string(stream.t.size()) +
                          " samples lie outside the master's span (" + which + "); they are not used");
    }
    HealthWarnings(stream, path, master->t.back(), warnings);
  }
  return Status::Ok();
}

Result<Inputs> LoadInputs(const std::string& config_path, const std::string& recording_dir,
                          std::vector<std::string>* warnings) {
  auto config = estimator::LoadEstimatorConfig(config_path);
  if (!config.ok()) return config.status();
  recording::ReadOptions read;
  read.load_ground_truth = false;
  for (const auto& [name, stream] : config.value().streams)
    for (const auto& [role, source] : stream.sources) read.required_streams.push_back(source);
  auto rec = recording::ReadRecording(recording_dir, read);
  if (!rec.ok()) return rec.status();
  // The configuration against the recording (stream types, parameter sizes and names, stages): bad input, found
  // before any work.
  auto builder = estimator::ProblemBuilder::Create(config.value(), rec.value());
  if (!builder.ok()) return builder.status();
  if (Status s = CheckCoverage(config.value(), rec.value(), recording_dir, warnings); !s.ok()) return s;
  return Inputs{std::move(config).value(), std::move(rec).value()};
}

// The files an earlier run of the same command left in `dir`, removed before this one starts: an interrupted run then
// leaves the marker and no result of another run beside it.
Status RemoveEarlierOutputs(const std::string& dir, std::initializer_list<const char*> files) {
  for (const char* file : files)
    if (Status s = RemoveStaleFile(dir + "/" + file); !s.ok()) return s;
  return Status::Ok();
}

// A failure after the marker was written: its message goes into the marker.
Outcome Failed(const Status& status, IncompleteMarker* marker) {
  marker->SetMessage(status.message());
  return Outcome::Failed(status);
}

}  // namespace

Status MakeOutputDirectory(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return Status::Error(dir + ": cannot create the output directory: " + ec.message());
  return Status::Ok();
}

Outcome SimulateToDirectory(const SimulateRequest& request, sim::Simulation* simulation) {
  auto scenario = sim::LoadScenario(request.scenario);
  if (!scenario.ok()) return Outcome::BadInput(scenario.status());
  std::vector<sim::FaultOptions>& faults = scenario.value().faults;
  faults.insert(faults.end(), request.faults.begin(), request.faults.end());
  if (Status dir = MakeOutputDirectory(request.out); !dir.ok()) return Outcome::BadInput(dir);
  sim::SimulateOptions options;
  options.seed = request.seed;
  options.image_directory = request.out;
  options.progress = request.progress;
  auto simulator = sim::Simulator::Create(scenario.value(), options);
  if (!simulator.ok()) return Outcome::BadInput(simulator.status());
  auto run = simulator.value()->Run();
  if (!run.ok()) return Outcome::Failed(run.status());

  // The recording and its truth.
  Status status = recording::WriteRecording(run.value().recording, request.out);
  if (status.ok()) status = recording::WriteTruth(run.value().truth, request.out);
  if (!status.ok()) return Outcome::Failed(status);
  if (simulation) *simulation = std::move(run).value();
  return Outcome::Ok();
}

Outcome ReplayToDirectory(const ReplayRequest& request, sim::Simulation* simulation) {
  auto scenario = sim::LoadScenario(request.scenario);
  if (!scenario.ok()) return Outcome::BadInput(scenario.status());
  if (auto nominal = sim::NominalPlatformGeometry(scenario.value()); !nominal.ok())
    return Outcome::BadInput(nominal.status());
  auto real = recording::ReadRecording(request.recording);
  if (!real.ok()) return Outcome::BadInput(real.status());
  auto inputs = sim::DriveInputsFrom(real.value(), scenario.value());
  if (!inputs.ok()) return Outcome::BadInput(Status::Error(request.recording + ": " + inputs.status().message()));
  const double first_s = inputs.value().t.front().seconds(), last_s = inputs.value().t.back().seconds();
  const double from_s = request.from_s.value_or(first_s), to_s = request.to_s.value_or(last_s);
  if (!(from_s < to_s) || from_s >= last_s || to_s <= first_s) {
    std::ostringstream message;
    message << request.recording << ": the window [" << from_s << ", " << to_s
            << "] s is empty or outside the drive inputs' span [" << first_s << ", " << last_s << "] s";
    return Outcome::BadInput(Status::Error(message.str()));
  }
  if (Status dir = MakeOutputDirectory(request.out); !dir.ok()) return Outcome::BadInput(dir);

  sim::ReplayOptions options;
  options.from_s = request.from_s;
  options.to_s = request.to_s;
  options.progress = request.progress;
  auto run = sim::Replay(scenario.value(), real.value(), options);
  if (!run.ok()) return Outcome::Failed(Status::Error(request.recording + ": " + run.status().message()));
  Status status = recording::WriteRecording(run.value().recording, request.out);
  if (status.ok()) status = recording::WriteTruth(run.value().truth, request.out);
  if (!status.ok()) return Outcome::Failed(status);
  if (simulation) *simulation = std::move(run).value();
  return Outcome::Ok();
}

Outcome CalibrateToDirectory(const CalibrateRequest& request, estimator::CalibrationResult* result) {
  std::vector<std::string> warnings;
  auto inputs = LoadInputs(request.config, request.recording, &warnings);
  if (!inputs.ok()) return Outcome::BadInput(inputs.status());
  const Status dir = MakeOutputDirectory(request.out);
  if (!dir.ok()) return Outcome::BadInput(dir);
  if (request.warning)
    for (const std::string& w : warnings) request.warning(w);
  if (Status s = RemoveEarlierOutputs(request.out, {"calibration.json", "trajectory.tum"}); !s.ok())
    return Outcome::Failed(s);
  IncompleteMarker marker(request.out);
  if (Status s = marker.Start(); !s.ok()) return Outcome::Failed(s);

  estimator::CalibrationOptions options;
  // Each line of progress (stages solved, measurements gated) is what was done when the run stops early.
  options.progress = [&](const std::string& line) {
    (void)marker.AddDone(line);
    if (request.progress) request.progress(line);
  };
  using Method = estimator::CalibrationOptions::StdMethod;
  if (request.std_method == "white") options.std_method = Method::kWhite;
  if (request.std_method == "hac") options.std_method = Method::kHac;
  auto calibrated = estimator::Calibrate(inputs.value().config, inputs.value().recording, options);
  if (!calibrated.ok()) return Failed(calibrated.status(), &marker);
  const estimator::CalibrationResult& r = calibrated.value();
  if (request.warning)
    for (const std::string& line : estimator::HeavilyGatedStreams(r)) request.warning(request.recording + ": " + line);
  Status st = estimator::WriteCalibrationFile(r, request.recording, request.config, request.out + "/calibration.json");
  if (st.ok()) st = WriteTum(r.trajectory, request.out + "/trajectory.tum");
  if (st.ok()) st = marker.Complete();
  if (!st.ok()) return Failed(st, &marker);
  if (result) *result = std::move(calibrated).value();
  return Outcome::Ok();
}

Outcome TrackToDirectory(const TrackRequest& request, estimator::TrackingResult* result) {
  std::vector<std::string> warnings;
  auto inputs = LoadInputs(request.config, request.recording, &warnings);
  if (!inputs.ok()) return Outcome::BadInput(inputs.status());
  if (request.warning)
    for (const std::string& w : warnings) request.warning(w);
  estimator::EstimatorConfig& config = inputs.value().config;
  if (request.no_time_budget) config.tracking.time_budget_s = std::numeric_limits<double>::infinity();
  std::map<std::string, Eigen::VectorXd> calibration;
  if (!request.calibration.empty()) {
    auto values = estimator::ReadCalibrationValues(request.calibration);
    if (!values.ok()) return Outcome::BadInput(values.status());
    calibration = std::move(values).value();
  }
  auto options = estimator::TrackingOptionsFor(config, request.calibration);
  if (!options.ok()) return Outcome::BadInput(options.status());
  const Status dir = MakeOutputDirectory(request.out);
  if (!dir.ok()) return Outcome::BadInput(dir);
  if (Status s = RemoveEarlierOutputs(request.out, {"trajectory.tum", "covariance.csv", "summary.json"}); !s.ok())
    return Outcome::Failed(s);
  IncompleteMarker marker(request.out);
  if (Status s = marker.Start(); !s.ok()) return Outcome::Failed(s);

  options.value().progress = request.progress;
  auto tracked = estimator::Track(config, inputs.value().recording, calibration, options.value());
  if (!tracked.ok()) return Failed(tracked.status(), &marker);
  Status st = estimator::WriteTrackingFiles(tracked.value(), config.tracking.window, request.out);
  if (st.ok()) st = marker.Complete();
  if (!st.ok()) return Failed(st, &marker);
  if (result) *result = std::move(tracked).value();
  return Outcome::Ok();
}

Outcome ImportOptiOdomToDirectory(const std::string& run_csv, const std::string& metadata, const std::string& out,
                                  recording::Recording* imported) {
  const std::string metadata_path = metadata.empty() ? importers::OptiOdomMetadataPath(run_csv) : metadata;
  if (metadata_path.empty())
    return Outcome::BadInput(
        Status::Error(run_csv + ": cannot find the metadata file (expected <set>_run-NN.csv; use --metadata)"));
  Result<recording::Recording> rec = importers::ImportOptiOdom(run_csv, metadata_path);
  if (!rec.ok()) return Outcome::BadInput(rec.status());
  if (Status dir = MakeOutputDirectory(out); !dir.ok()) return Outcome::BadInput(dir);
  if (Status s = recording::WriteRecording(rec.value(), out); !s.ok()) return Outcome::Failed(s);
  if (imported) *imported = std::move(rec).value();
  return Outcome::Ok();
}

}  // namespace roamlab::experiment
