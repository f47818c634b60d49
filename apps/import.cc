#include "apps/import.h"

#include <cmath>
#include <cstdlib>
#include <iostream>

#include "recording/import_optiodom.h"
#include "recording/import_rosbag.h"
#include "recording/recording.h"

namespace roamlab::apps {
namespace {

// Writes an imported recording to `out`: 0, or the exit code after one line on stderr (2: the input was bad,
// 1: the recording could not be written).
int Written(const Result<recording::Recording>& rec, const std::string& out) {
  if (!rec.ok()) {
    std::cerr << "roamlab import: " << rec.status().message() << "\n";
    return 2;
  }
  if (Status s = recording::WriteRecording(rec.value(), out); !s.ok()) {
    std::cerr << "roamlab import: " << s.message() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace

int RunImportOptiOdom(const ImportOptiOdomArgs& args) {
  std::string metadata = args.metadata;
  if (metadata.empty()) metadata = recording::OptiOdomMetadataPath(args.run_csv);
  if (metadata.empty()) {
    std::cerr << "roamlab import: " << args.run_csv
              << ": cannot find the metadata file (expected <set>_run-NN.csv; use --metadata)\n";
    return 2;
  }
  const Result<recording::Recording> rec = recording::ImportOptiOdom(args.run_csv, metadata);
  if (const int code = Written(rec, args.out); code != 0) return code;
  if (!args.quiet) {
    const recording::Stream& enc = rec.value().streams.front();
    std::cout << "imported " << enc.t.size() << " samples (" << rec.value().platform.kind << ", "
              << SecondsBetween(enc.t.front(), enc.t.back()) << " s) into " << args.out << "\n";
  }
  return 0;
}

int RunImportRosbag(const ImportRosbagArgs& args) {
  recording::RosbagImportOptions options;
  options.platform.kind = args.platform_kind;
  options.wheels_from_odometry = args.wheels_from_odometry;
  for (const std::string& kv : args.geometry) {
    const std::size_t eq = kv.find('=');
    char* end = nullptr;
    const double value = eq == std::string::npos ? NAN : std::strtod(kv.c_str() + eq + 1, &end);
    if (eq == std::string::npos || eq == 0 || !end || *end != '\0' || !std::isfinite(value)) {
      std::cerr << "roamlab import: --geometry '" << kv << "': expected KEY=NUMBER\n";
      return 2;
    }
    options.platform.geometry[kv.substr(0, eq)] = value;
  }
  if (!args.imu_mounting_wxyz.empty()) {
    const std::vector<double>& q = args.imu_mounting_wxyz;
    const double norm = q.size() == 4 ? std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]) : 0.0;
    if (std::abs(norm - 1.0) > 1e-3) {
      std::cerr << "roamlab import: --imu-mounting: expected a unit quaternion W X Y Z\n";
      return 2;
    }
    options.q_body_imu = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized();
  }
  recording::RosbagImportReport report;
  const Result<recording::Recording> rec = recording::ImportRosbag(args.bag, options, &report);
  if (const int code = Written(rec, args.out); code != 0) return code;
  if (!args.quiet) {
    for (const recording::Stream& s : rec.value().streams) {
      std::cout << s.info.name << ": " << s.t.size() << " samples, " << SecondsBetween(s.t.front(), s.t.back())
                << " s, " << s.info.rate_hz << " Hz\n";
    }
    for (const auto& [topic, type] : report.types) {
      if (type != "sensor_msgs/Imu" && type != "nav_msgs/Odometry" && type != "sensor_msgs/NavSatFix")
        std::cout << "ignored " << report.messages.at(topic) << " messages on " << topic << " (" << type << ")\n";
    }
    for (const auto& [what, n] : report.skipped) std::cout << "skipped " << n << " samples (" << what << ")\n";
    std::cout << "imported " << report.chunks << " chunks into " << args.out << "\n";
  }
  return 0;
}

}  // namespace roamlab::apps
