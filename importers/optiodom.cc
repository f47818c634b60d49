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
  std::string type;  // diff | omni3 | omni4 | tricyc
  double gear_ratio = 0.0;
  double ticks_per_motor_rev = 0.0;
  std::vector<double> distances_m;   // Li
  std::vector<double> diameters_m;   // Di
  double steering_offset_rad = 0.0;  // Thi (tricyc)
};

// Wheels (Di entries) and distances (Li entries) of each supported type.
struct TypeShape {
  const char* type;
  std::size_t wheels;
  std::size_t distances;
};
constexpr TypeShape kTypes[] = {{"diff", 2, 1}, {"omni3", 3, 1}, {"omni4", 4, 2}, {"tricyc", 1, 1}};

const TypeShape* FindType(const std::string& type) {
  for (const TypeShape& shape : kTypes) {
    if (type == shape.type) return &shape;
  }
  return nullptr;
}

// The largest magnitude of each numeric metadata key: gear ratio, encoder ticks per motor revolution, distances and
// diameters [m], steering offset [rad].
double Limit(const std::string& key) {
  if (key == "ngear") return 1e4;
  if (key == "encRes") return 1e7;
  if (key == "Thi") return 3.15;
  return 100.0;  // Li, Di
}

// The numbers of one metadata row (cells after the key); Thi may be zero or negative, the other keys must be positive.
Result<std::vector<double>> RowNumbers(const std::string& path, std::size_t line, const std::string& key,
                                       const std::vector<std::string>& cells) {
  std::vector<double> values;
  for (std::size_t c = 1; c < cells.size(); ++c) {
    double value = 0.0;
    const bool number = recording::internal::ParseNumber(cells[c], &value) == recording::internal::NumberParse::kOk;
    if (!number || (key != "Thi" && !(value > 0.0))) {
      return Status::Error(At(path, line) + key + ": '" + cells[c] + "' is not a " +
                           (key == "Thi" ? "finite" : "positive") + " number");
    }
    if (std::abs(value) > Limit(key)) {
      return Status::Error(At(path, line) + key + ": " + cells[c] + " is outside the physical range (|value| <= " +
                           recording::internal::FormatShortest(Limit(key)) + ")");
    }
    values.push_back(value);
  }
  return values;
}

// Checks the required keys and their sizes for the type and fills `meta`.
Status CheckShape(const std::string& path, std::map<std::string, std::vector<double>>& numbers, Metadata* meta) {
  const TypeShape* shape = FindType(meta->type);
  if (shape == nullptr) {
    return Status::Error(path + ": type '" + meta->type + "' is not supported (diff, omni3, omni4, tricyc)");
  }
  std::vector<std::string> required = {"ngear", "encRes", "Li", "Di"};
  if (meta->type == "tricyc") required.push_back("Thi");
  for (const std::string& key : required) {
    if (numbers.count(key) == 0 || numbers[key].empty()) {
      return Status::Error(path + ": missing key '" + key + "'" + (numbers.count(key) > 0 ? " (no value)" : ""));
    }
  }
  meta->gear_ratio = numbers["ngear"][0];
  meta->ticks_per_motor_rev = numbers["encRes"][0];
  meta->distances_m = numbers["Li"];
  meta->diameters_m = numbers["Di"];
  if (meta->type == "tricyc") meta->steering_offset_rad = numbers["Thi"][0];
  if (meta->diameters_m.size() != shape->wheels) {
    return Status::Error(path + ": Di has " + std::to_string(meta->diameters_m.size()) + " diameters, type " +
                         meta->type + " needs " + std::to_string(shape->wheels));
  }
  if (meta->distances_m.size() != shape->distances) {
    return Status::Error(path + ": Li has " + std::to_string(meta->distances_m.size()) + " distances, type " +
                         meta->type + " needs " + std::to_string(shape->distances));
  }
  return Status::Ok();
}

Result<Metadata> ReadMetadata(const std::string& path) {
  std::string content;
  if (Status s = recording::internal::ReadTextFile(path, &content); !s.ok()) return s;
  static const std::set<std::string> kIgnored = {"N", "L", "imarkers", "gt_ti", "gt_tf", "odo_ti", "odo_tf"};
  std::map<std::string, std::vector<double>> numbers;
  std::set<std::string> seen;
  Metadata meta;
  const std::vector<std::string> lines = Lines(content);
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (lines[i].empty()) continue;
    std::vector<std::string> cells = SplitCells(lines[i]);
    const std::string key = cells.front();
    while (!cells.empty() && cells.back().empty()) cells.pop_back();  // trailing empty cells
    if (!seen.insert(key).second) return Status::Error(At(path, i) + "duplicate key '" + key + "'");
    if (key == "type") {
      meta.type = cells.size() > 1 ? cells[1] : "";
      continue;
    }
    if (kIgnored.count(key) > 0) continue;
    if (key != "ngear" && key != "encRes" && key != "Li" && key != "Di" && key != "Thi") {
      return Status::Error(At(path, i) + "unknown key '" + key + "'");
    }
    Result<std::vector<double>> values = RowNumbers(path, i, key, cells);
    if (!values.ok()) return values.status();
    // Thi is empty for the types without a steering offset.
    if (values.value().empty() && key != "Thi") return Status::Error(At(path, i) + key + " has no value");
    numbers[key] = values.value();
  }
  if (Status s = CheckShape(path, numbers, &meta); !s.ok()) return s;
  return meta;
}

// One run: time, planar pose and the columns after the ground truth (ticks per cycle; for a tricycle the front wheel's
// ticks and the steering angle).
struct Run {
  std::vector<Time> t;
  std::vector<Eigen::Vector3d> pose;
  std::vector<Eigen::VectorXd> readings;
};

Result<Run> ReadRun(const std::string& run_csv, std::size_t readings, const std::string& what) {
  std::string content;
  if (Status s = recording::internal::ReadTextFile(run_csv, &content); !s.ok()) return s;
  const std::size_t columns = 4 + readings;
  Run run;
  const std::vector<std::string> lines = Lines(content);
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (lines[i].empty()) continue;
    const std::vector<std::string> cells = SplitCells(lines[i]);
    if (cells.size() != columns) {
      return Status::Error(At(run_csv, i) + std::to_string(cells.size()) + " columns, expected " +
                           std::to_string(columns) + " (t, x, y, theta, " + what + ")");
    }
    Eigen::VectorXd row(static_cast<Eigen::Index>(columns));
    for (std::size_t c = 0; c < columns; ++c) {
      if (recording::internal::ParseNumber(cells[c], &row[static_cast<Eigen::Index>(c)]) !=
          recording::internal::NumberParse::kOk) {
        return Status::Error(At(run_csv, i) + "column " + std::to_string(c + 1) + ": '" + cells[c] +
                             "' is not a finite number");
      }
    }
    const std::optional<Time> stamp = Time::FromSecondsChecked(row[0]);
    if (!stamp) return Status::Error(At(run_csv, i) + "time " + cells[0] + " s is outside +-9e9 s");
    const Time time = *stamp;
    if (!run.t.empty() && time <= run.t.back()) {
      return Status::Error(At(run_csv, i) + recording::internal::TimeOrderProblem(run.t.back(), time));
    }
    run.t.push_back(time);
    run.pose.emplace_back(row[1], row[2], row[3]);
    run.readings.push_back(row.tail(static_cast<Eigen::Index>(readings)));
  }
  if (run.t.size() < 2) return Status::Error(run_csv + ": fewer than two samples");
  return run;
}

// Encoder column names per type.
std::vector<std::string> WheelNames(const std::string& type) {
  if (type == "diff") return {"right", "left"};
  if (type == "omni3") return {"w1", "w2", "w3"};
  if (type == "omni4") return {"front_left", "front_right", "rear_left", "rear_right"};
  return {"front"};
}

Platform MakePlatform(const Metadata& meta, const std::vector<std::string>& wheels) {
  Platform platform;
  const std::map<std::string, std::string> kinds = {
      {"diff", "differential_drive"}, {"omni3", "omni3"}, {"omni4", "omni4"}, {"tricyc", "tricycle"}};
  platform.kind = kinds.at(meta.type);
  platform.geometry["gear_ratio"] = meta.gear_ratio;
  platform.geometry["encoder_ticks_per_motor_revolution"] = meta.ticks_per_motor_rev;
  for (std::size_t w = 0; w < wheels.size(); ++w) {
    platform.geometry["wheel_radius_" + wheels[w] + "_m"] = 0.5 * meta.diameters_m[w];
  }
  if (meta.type == "diff") {
    platform.geometry["track_m"] = meta.distances_m[0];
  } else if (meta.type == "omni3") {
    platform.geometry["wheel_distance_m"] = meta.distances_m[0];
    const double omni_angles_rad[] = {-kPi / 3.0, kPi / 3.0, kPi};
    for (std::size_t w = 0; w < wheels.size(); ++w) {
      platform.geometry["wheel_angle_" + wheels[w] + "_rad"] = omni_angles_rad[w];
      platform.geometry["wheel_direction_" + wheels[w]] = -1.0;
    }
  } else if (meta.type == "omni4") {
    platform.geometry["wheelbase_m"] = meta.distances_m[0];
    platform.geometry["track_m"] = meta.distances_m[1];
  } else {
    platform.geometry["wheel_to_axle_m"] = meta.distances_m[0];
    platform.geometry["steering_offset_rad"] = meta.steering_offset_rad;
  }
  return platform;
}

double MedianRateHz(const std::vector<Time>& t) {
  std::vector<double> periods;
  for (std::size_t k = 1; k < t.size(); ++k) periods.push_back(SecondsBetween(t[k - 1], t[k]));
  std::nth_element(periods.begin(), periods.begin() + static_cast<std::ptrdiff_t>(periods.size() / 2), periods.end());
  return 1.0 / periods[periods.size() / 2];
}

// Wheel encoders: cumulative angle [rad] from the first `wheels` readings (ticks per cycle).
Stream EncoderStream(const Metadata& meta, const Run& run, const std::vector<std::string>& wheels, double rate_hz) {
  const auto m = static_cast<Eigen::Index>(wheels.size());
  const double ticks_per_wheel_rev = meta.gear_ratio * meta.ticks_per_motor_rev;
  Stream encoders;
  encoders.info.name = "wheel_encoders";
  encoders.info.type = StreamType::kWheelEncoders;
  encoders.info.rate_hz = rate_hz;
  encoders.info.columns = wheels;
  encoders.info.units = "rad";
  encoders.info.attributes["ticks_per_revolution"] = ticks_per_wheel_rev;
  encoders.t = run.t;
  encoders.values.resize(static_cast<Eigen::Index>(run.t.size()), m);
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(m);
  for (std::size_t k = 0; k < run.t.size(); ++k) {
    sum += run.readings[k].head(m);
    encoders.values.row(static_cast<Eigen::Index>(k)) = (2.0 * kPi / ticks_per_wheel_rev) * sum.transpose();
  }
  return encoders;
}

// The tricycle's steering angle [rad] (the run's last column, as measured: the offset is in the geometry).
Stream SteeringStream(const Run& run, double rate_hz) {
  Stream steering;
  steering.info.name = "steering";
  steering.info.type = StreamType::kSteering;
  steering.info.rate_hz = rate_hz;
  steering.info.columns = {"angle"};
  steering.info.units = "rad";
  steering.t = run.t;
  steering.values.resize(static_cast<Eigen::Index>(run.t.size()), 1);
  for (std::size_t k = 0; k < run.t.size(); ++k) {
    steering.values(static_cast<Eigen::Index>(k), 0) = run.readings[k][run.readings[k].size() - 1];
  }
  return steering;
}

// Motion capture as a pose stream; `truth` receives the same poses.
Stream MocapStream(const Run& run, double rate_hz, Trajectory* truth) {
  Stream mocap;
  mocap.info.name = "mocap";
  mocap.info.type = StreamType::kPose;
  mocap.info.rate_hz = rate_hz;
  mocap.info.units = "m";
  mocap.info.noise = {{"position_m", 0.001}, {"orientation_rad", 0.005}};
  mocap.t = run.t;
  mocap.values.resize(static_cast<Eigen::Index>(run.t.size()), 7);
  for (std::size_t k = 0; k < run.t.size(); ++k) {
    const Eigen::Vector3d& p = run.pose[k];
    const Eigen::Quaterniond q(Eigen::AngleAxisd(p[2], Eigen::Vector3d::UnitZ()));
    mocap.values.row(static_cast<Eigen::Index>(k)) << p[0], p[1], 0.0, q.x(), q.y(), q.z(), q.w();
    truth->push_back(StampedPose{run.t[k], Eigen::Vector3d(p[0], p[1], 0.0), q});
  }
  return mocap;
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
  const bool tricycle = meta.type == "tricyc";
  const std::vector<std::string> wheels = WheelNames(meta.type);
  const std::string what =
      tricycle ? "front wheel ticks, steering angle" : "ticks of " + std::to_string(wheels.size()) + " wheels";
  Result<Run> run_result = ReadRun(run_csv, wheels.size() + (tricycle ? 1 : 0), what);
  if (!run_result.ok()) return run_result.status();
  const Run& run = run_result.value();

  Recording rec;
  rec.platform = MakePlatform(meta, wheels);
  rec.provenance.source = "imported";
  rec.provenance.description = "OptiOdom run " + std::filesystem::path(run_csv).filename().string() + " (metadata " +
                               std::filesystem::path(metadata_csv).filename().string() +
                               "); the motion-capture pose stands in for the exteroceptive sensor";
  const double rate_hz = MedianRateHz(run.t);
  rec.streams.push_back(EncoderStream(meta, run, wheels, rate_hz));
  if (tricycle) rec.streams.push_back(SteeringStream(run, rate_hz));
  Trajectory truth;
  rec.streams.push_back(MocapStream(run, rate_hz, &truth));
  rec.ground_truth = std::move(truth);
  return rec;
}

}  // namespace roamlab::importers
