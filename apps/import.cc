#include "apps/import.h"

#include <cmath>
#include <cstdlib>
#include <iostream>

#include "apps/cli.h"
#include "common/progress.h"
#include "experiment/steps.h"
#include "importers/csv.h"
#include "importers/rosbag.h"
#include "recording/recording.h"

namespace roamlab::apps {
namespace {

constexpr const char* kCommand = "import";

// Writes an imported recording to `out`: 0, or the exit code after one line on stderr (2: the input was bad,
// 1: the recording could not be written).
int Written(const Result<recording::Recording>& rec, const std::string& out) {
  if (!rec.ok()) return BadInput(nullptr, kCommand, rec.status().message());
  if (Status s = experiment::MakeOutputDirectory(out); !s.ok()) return BadInput(nullptr, kCommand, s.message());
  if (Status s = recording::WriteRecording(rec.value(), out); !s.ok()) return Failure(nullptr, kCommand, s.message());
  return 0;
}

}  // namespace

int RunImportOptiOdom(const ImportOptiOdomArgs& args) {
  recording::Recording rec;
  const experiment::Outcome outcome =
      experiment::ImportOptiOdomToDirectory(args.run_csv, args.metadata, args.out, &rec);
  if (!outcome.ok()) return Exit(nullptr, kCommand, outcome);
  if (!args.quiet) {
    const recording::Stream& enc = rec.streams.front();
    std::cout << "imported " << enc.t.size() << " samples (" << rec.platform.kind << ", "
              << SecondsBetween(enc.t.front(), enc.t.back()) << " s) into " << args.out << "\n";
  }
  return 0;
}

namespace {

// The importer's options from the arguments: 0, or the exit code after one line on stderr.
int RosbagOptions(const ImportRosbagArgs& args, importers::RosbagImportOptions* options) {
  options->platform.kind = args.platform_kind;
  options->wheels_from_odometry = args.wheels_from_odometry;
  options->odometry_topic = args.odometry_topic;
  options->odometry_wheel_separation_m = args.odometry_wheel_separation_m;
  options->joints = args.joints;
  options->joint_velocities = args.joint_velocities;
  for (const std::string& kv : args.geometry) {
    const std::size_t eq = kv.find('=');
    char* end = nullptr;
    const double value = eq == std::string::npos ? NAN : std::strtod(kv.c_str() + eq + 1, &end);
    if (eq == std::string::npos || eq == 0 || !end || *end != '\0' || !std::isfinite(value)) {
      return BadInput(nullptr, kCommand, "--geometry '" + kv + "': expected KEY=NUMBER");
    }
    options->platform.geometry[kv.substr(0, eq)] = value;
  }
  for (const std::string& ts : args.topics) {
    const std::size_t eq = ts.rfind('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == ts.size())
      return BadInput(nullptr, kCommand, "--topic '" + ts + "': expected TOPIC=STREAM");
    options->topics.emplace_back(ts.substr(0, eq), ts.substr(eq + 1));
  }
  if (!args.imu_mounting_wxyz.empty()) {
    const std::vector<double>& q = args.imu_mounting_wxyz;
    const double norm = q.size() == 4 ? std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]) : 0.0;
    if (std::abs(norm - 1.0) > 1e-3) {
      return BadInput(nullptr, kCommand, "--imu-mounting: expected a unit quaternion W X Y Z");
    }
    options->q_body_imu = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized();
  }
  return 0;
}

// `--list`: one row per topic.
int ListRosbagTopics(const std::string& bag) {
  const Result<std::vector<importers::RosbagTopicListing>> rows = importers::ListRosbag(bag);
  if (!rows.ok()) return BadInput(nullptr, kCommand, rows.status().message());
  std::cout << "topic\ttype\tmessages\trate_hz\tfirst_s\tlast_s\tspan_s\timported\n";
  for (const importers::RosbagTopicListing& r : rows.value()) {
    std::cout << r.topic << "\t" << r.type << "\t" << r.messages << "\t" << r.rate_hz << "\t" << FormatSeconds(r.first)
              << "\t" << FormatSeconds(r.last) << "\t" << SecondsBetween(r.first, r.last) << "\t"
              << (r.supported ? "yes" : "no") << "\n";
  }
  return 0;
}

void PrintRosbagSummary(const recording::Recording& rec, const importers::RosbagImportReport& report,
                        const std::string& out) {
  for (const importers::RosbagTopicReport& t : report.topics) {
    if (!t.decoded) {
      std::cout << "ignored " << t.messages << " messages on " << t.topic << " (" << t.type << ")\n";
      continue;
    }
    if (t.streams.empty()) std::cout << t.topic << " (" << t.type << "): not imported\n";
    for (const std::string& name : t.streams) {
      const recording::Stream& s = *rec.Find(name);
      std::cout << t.topic << " (" << t.type << ") -> " << name << ": " << s.t.size() << " samples, "
                << SecondsBetween(s.t.front(), s.t.back()) << " s, " << s.info.rate_hz << " Hz; "
                << importers::DescribeClockOffset(t.clock_offset_s) << "\n";
    }
    for (const auto& [what, n] : t.skipped)
      std::cout << "skipped " << n << " messages of " << t.topic << " (" << what << ")\n";
  }
  if (const recording::Stream* wheels = rec.Find("wheels");
      wheels && wheels->info.attributes.count("derived_from_odometry"))
    std::cout << "wheels: " << wheels->t.size() << " samples re-expressed from the odometry\n";
  std::cout << "imported " << report.format << " (" << report.chunks << " chunks) into " << out << "\n";
}

}  // namespace

int RunImportRosbag(const ImportRosbagArgs& args) {
  if (args.list) return ListRosbagTopics(args.bag);
  if (args.out.empty()) return BadInput(nullptr, kCommand, "--out is required (or --list)");
  importers::RosbagImportOptions options;
  if (const int code = RosbagOptions(args, &options); code != 0) return code;
  importers::RosbagImportReport report;
  ProgressMeter meter("import", &std::cerr);
  if (!args.quiet) options.progress = [&meter](double fraction) { meter.Update(fraction); };
  const Result<recording::Recording> rec = importers::ImportRosbag(args.bag, options, &report);
  meter.Finish();
  if (const int code = Written(rec, args.out); code != 0) return code;
  if (Status s = importers::WriteCameraFrames(report.frames, args.out); !s.ok())
    return Failure(nullptr, kCommand, s.message());
  for (const std::string& w : report.warnings) std::cerr << "roamlab import: warning: " << w << "\n";
  if (!args.quiet) PrintRosbagSummary(rec.value(), report, args.out);
  return 0;
}

int RunImportCsv(const ImportCsvArgs& args) {
  importers::CsvImportReport report;
  const Result<recording::Recording> rec = importers::ImportCsv(args.files, args.map, &report);
  if (const int code = Written(rec, args.out); code != 0) return code;
  if (args.quiet) return 0;
  for (const importers::CsvFileReport& f : report.files) {
    std::cout << f.path << ": " << f.rows << " rows read, " << f.ignored_lines << " blank/comment/skip_rows lines, "
              << f.skipped_non_numeric << " rows skipped (non-numeric), " << f.skipped_duplicate_time
              << " rows skipped (duplicate time)\n";
  }
  for (std::size_t i = 0; i < report.streams.size(); ++i) {
    const importers::CsvStreamReport& r = report.streams[i];
    const recording::Stream& s = rec.value().streams[i];
    std::cout << r.name << ": " << r.samples << " samples, " << SecondsBetween(s.t.front(), s.t.back()) << " s, "
              << s.info.rate_hz << " Hz; " << r.empty_cells << " rows with empty cells, " << r.collapsed
              << " rows collapsed\n";
  }
  std::cout << "imported into " << args.out << "\n";
  return 0;
}

}  // namespace roamlab::apps
