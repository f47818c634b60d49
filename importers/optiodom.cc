#include "importers/optiodom.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <vector>

#include "recording/internal/text_io.h"

namespace roamlab::importers {

using recording::GeodeticOrigin;
using recording::Mounting;
using recording::Platform;
using recording::Recording;
using recording::Stream;
using recording::StreamType;

namespace {

constexpr double kPi = 3.14159265358979323846;

// The cells of one CSV line (comma-separated, blanks trimmed, a UTF-8 byte-order mark at the start removed).
std::vector<std::string> SplitCells(std::string_view line) {
  if (line.substr(0, 3) == "\xEF\xBB\xBF") line.remove_prefix(3);
  std::vector<std::string> cells;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    cells.emplace_back(
        recording::internal::Trim(line.substr(start, comma == std::string_view::npos ? line.npos : comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return cells;
}

// Lines of a text file, without line terminators; blank lines kept (as empty strings) so that numbers stay right.
std::vector<std::string> Lines(const std::string& content) {
  std::vector<std::string> lines;
  std::istringstream in(content);
  std::string line;
  while (std::getline(in, line)) lines.push_back(std::string(recording::internal::Trim(line)));
  return lines;
}

std::string At(const std::string& path, std::size_t line_index) {
  return path + ":" + std::to_string(line_index + 1) + ": ";
}

struct Metadata {
  std::string type;  // diff | omni3
  double gear_ratio = 0.0;
  double ticks_per_motor_rev = 0.0;
  double distance_m = 0.0;
  std::vector<double> diameters_m;
};

Result<Metadata> ReadMetadata(const std::string& path) {
  std::string content;
  if (Status s = recording::internal::ReadTextFile(path, &content); !s.ok()) return s;
  static const std::set<std::string> kIgnored = {"Thi", "N", "L", "imarkers", "gt_ti", "gt_tf", "odo_ti", "odo_tf"};
  std::map<std::string, std::vector<double>> numbers;
  Metadata meta;
  const std::vector<std::string> lines = Lines(content);
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (lines[i].empty()) continue;
    std::vector<std::string> cells = SplitCells(lines[i]);
    const std::string key = cells.front();
    while (!cells.empty() && cells.back().empty()) cells.pop_back();  // trailing empty cells
    if (key == "type") {
      meta.type = cells.size() > 1 ? cells[1] : "";
      continue;
    }
    if (kIgnored.count(key) > 0) continue;
    if (key != "ngear" && key != "encRes" && key != "Li" && key != "Di") {
      return Status::Error(At(path, i) + "unknown key '" + key + "'");
    }
    std::vector<double> values;
    for (std::size_t c = 1; c < cells.size(); ++c) {
      double value = 0.0;
      if (recording::internal::ParseNumber(cells[c], &value) != recording::internal::NumberParse::kOk ||
          !(value > 0.0)) {
        return Status::Error(At(path, i) + key + ": '" + cells[c] + "' is not a positive number");
      }
      values.push_back(value);
    }
    if (values.empty()) return Status::Error(At(path, i) + key + " has no value");
    numbers[key] = values;
  }
  // Required keys and their sizes.
  if (meta.type != "diff" && meta.type != "omni3") {
    return Status::Error(path + ": type '" + meta.type + "' is not supported (diff, omni3)");
  }
  for (const char* key : {"ngear", "encRes", "Li", "Di"}) {
    if (numbers.count(key) == 0) return Status::Error(path + ": missing key '" + key + "'");
  }
  meta.gear_ratio = numbers["ngear"][0];
  meta.ticks_per_motor_rev = numbers["encRes"][0];
  meta.distance_m = numbers["Li"][0];
  meta.diameters_m = numbers["Di"];
  const std::size_t wheels = meta.type == "diff" ? 2 : 3;
  if (meta.diameters_m.size() != wheels) {
    return Status::Error(path + ": Di has " + std::to_string(meta.diameters_m.size()) + " diameters, type " +
                         meta.type + " needs " + std::to_string(wheels));
  }
  return meta;
}

}  // namespace

std::string OptiOdomMetadataPath(const std::string& run_csv) {
  const std::filesystem::path path(run_csv);
  const std::string name = path.filename().string();
  const std::size_t run = name.rfind("_run-");
  if (run == std::string::npos) return "";
  return (path.parent_path() / (name.substr(0, run) + "_metadata.csv")).string();
}

Result<Recording> ImportOptiOdom(const std::string& run_csv, const std::string& metadata_csv) {
  Result<Metadata> meta_result = ReadMetadata(metadata_csv);
  if (!meta_result.ok()) return meta_result.status();
  const Metadata& meta = meta_result.value();
  const bool diff = meta.type == "diff";
  const std::vector<std::string> wheels =
      diff ? std::vector<std::string>{"right", "left"} : std::vector<std::string>{"w1", "w2", "w3"};
  const auto m = static_cast<Eigen::Index>(wheels.size());
  const std::size_t columns = 4 + wheels.size();

  // The run: time, pose, ticks per cycle.
  std::string content;
  if (Status s = recording::internal::ReadTextFile(run_csv, &content); !s.ok()) return s;
  std::vector<Time> t;
  std::vector<Eigen::Vector3d> pose;
  std::vector<Eigen::VectorXd> ticks;
  const std::vector<std::string> lines = Lines(content);
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (lines[i].empty()) continue;
    const std::vector<std::string> cells = SplitCells(lines[i]);
    if (cells.size() != columns) {
      return Status::Error(At(run_csv, i) + std::to_string(cells.size()) + " columns, expected " +
                           std::to_string(columns) + " (t, x, y, theta, ticks of " + std::to_string(m) + " wheels)");
    }
    Eigen::VectorXd row(static_cast<Eigen::Index>(columns));
    for (std::size_t c = 0; c < columns; ++c) {
      if (recording::internal::ParseNumber(cells[c], &row[static_cast<Eigen::Index>(c)]) !=
          recording::internal::NumberParse::kOk) {
        return Status::Error(At(run_csv, i) + "column " + std::to_string(c + 1) + ": '" + cells[c] +
                             "' is not a finite number");
      }
    }
    const Time time = Time::FromSeconds(row[0]);
    if (!t.empty() && time <= t.back()) {
      return Status::Error(At(run_csv, i) + recording::internal::TimeOrderProblem(t.back(), time));
    }
    t.push_back(time);
    pose.emplace_back(row[1], row[2], row[3]);
    ticks.push_back(row.tail(m));
  }
  if (t.size() < 2) return Status::Error(run_csv + ": fewer than two samples");

  Recording rec;
  // Platform.
  rec.platform.kind = diff ? "differential_drive" : "omni3";
  rec.platform.geometry["gear_ratio"] = meta.gear_ratio;
  rec.platform.geometry["encoder_ticks_per_motor_revolution"] = meta.ticks_per_motor_rev;
  rec.platform.geometry[diff ? "track_m" : "wheel_distance_m"] = meta.distance_m;
  const double omni_angles_rad[] = {-kPi / 3.0, kPi / 3.0, kPi};
  for (Eigen::Index w = 0; w < m; ++w) {
    rec.platform.geometry["wheel_radius_" + wheels[w] + "_m"] = 0.5 * meta.diameters_m[w];
    if (!diff) {
      rec.platform.geometry["wheel_angle_" + wheels[w] + "_rad"] = omni_angles_rad[w];
      rec.platform.geometry["wheel_direction_" + wheels[w]] = -1.0;
    }
  }
  rec.provenance.source = "imported";
  rec.provenance.description = "OptiOdom run " + std::filesystem::path(run_csv).filename().string() + " (metadata " +
                               std::filesystem::path(metadata_csv).filename().string() +
                               "); the motion-capture pose stands in for the exteroceptive sensor";
  // Nominal rate from the median sample period.
  std::vector<double> periods;
  for (std::size_t k = 1; k < t.size(); ++k) periods.push_back(SecondsBetween(t[k - 1], t[k]));
  std::nth_element(periods.begin(), periods.begin() + static_cast<std::ptrdiff_t>(periods.size() / 2), periods.end());
  const double rate_hz = 1.0 / periods[periods.size() / 2];

  // Wheel encoders: cumulative angle [rad].
  const double ticks_per_wheel_rev = meta.gear_ratio * meta.ticks_per_motor_rev;
  Stream encoders;
  encoders.info.name = "wheel_encoders";
  encoders.info.type = StreamType::kWheelEncoders;
  encoders.info.rate_hz = rate_hz;
  encoders.info.columns = wheels;
  encoders.info.units = "rad";
  encoders.info.attributes["ticks_per_revolution"] = ticks_per_wheel_rev;
  encoders.t = t;
  encoders.values.resize(static_cast<Eigen::Index>(t.size()), m);
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(m);
  for (std::size_t k = 0; k < t.size(); ++k) {
    sum += ticks[k];
    encoders.values.row(static_cast<Eigen::Index>(k)) = (2.0 * kPi / ticks_per_wheel_rev) * sum.transpose();
  }
  // Motion capture as a pose stream and as the ground truth.
  Stream mocap;
  mocap.info.name = "mocap";
  mocap.info.type = StreamType::kPose;
  mocap.info.rate_hz = rate_hz;
  mocap.info.units = "m";
  mocap.info.noise = {{"position_m", 0.001}, {"orientation_rad", 0.005}};
  mocap.t = t;
  mocap.values.resize(static_cast<Eigen::Index>(t.size()), 7);
  Trajectory truth;
  for (std::size_t k = 0; k < t.size(); ++k) {
    const Eigen::Quaterniond q(Eigen::AngleAxisd(pose[k][2], Eigen::Vector3d::UnitZ()));
    mocap.values.row(static_cast<Eigen::Index>(k)) << pose[k][0], pose[k][1], 0.0, q.x(), q.y(), q.z(), q.w();
    truth.push_back(StampedPose{t[k], Eigen::Vector3d(pose[k][0], pose[k][1], 0.0), q});
  }
  rec.streams.push_back(std::move(encoders));
  rec.streams.push_back(std::move(mocap));
  rec.ground_truth = std::move(truth);
  return rec;
}

}  // namespace roamlab::importers
