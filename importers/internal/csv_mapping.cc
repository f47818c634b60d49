#include "importers/internal/csv_mapping.h"

#include <cmath>
#include <set>

#include <yaml-cpp/yaml.h>
#include <Eigen/Geometry>

#include "recording/internal/stream_types.h"
#include "recording/internal/text_io.h"
#include "recording/internal/yaml_util.h"

namespace roamlab::importers::internal {

namespace rin = recording::internal;
using recording::StreamType;

namespace {

constexpr double kPi = 3.14159265358979323846;

enum class Dimension { kNone, kAngle, kRate, kAcceleration, kSpeed, kField, kLength, kTime };

const char* DimensionName(Dimension dimension) {
  switch (dimension) {
    case Dimension::kNone:
      return "dimensionless";
    case Dimension::kAngle:
      return "an angle";
    case Dimension::kRate:
      return "an angular rate";
    case Dimension::kAcceleration:
      return "an acceleration";
    case Dimension::kSpeed:
      return "a speed";
    case Dimension::kField:
      return "a magnetic field";
    case Dimension::kLength:
      return "a length";
    case Dimension::kTime:
      return "a time";
  }
  return "";
}

struct Unit {
  const char* name;
  Dimension dimension;
  double si;  // value in the SI unit of the dimension (field: uT); ticks: per tick, from ticks_per_revolution
};

// Every unit the mapping accepts, with its definition.
constexpr Unit kUnits[] = {
    {"1", Dimension::kNone, 1.0},
    {"normalized", Dimension::kNone, 1.0},
    {"rad", Dimension::kAngle, 1.0},
    {"deg", Dimension::kAngle, kPi / 180.0},
    {"ticks", Dimension::kAngle, 0.0},
    {"rad/s", Dimension::kRate, 1.0},
    {"deg/s", Dimension::kRate, kPi / 180.0},
    {"rpm", Dimension::kRate, 2.0 * kPi / 60.0},
    {"m/s^2", Dimension::kAcceleration, 1.0},
    {"g", Dimension::kAcceleration, 9.80665},
    {"m/s", Dimension::kSpeed, 1.0},
    {"km/h", Dimension::kSpeed, 1000.0 / 3600.0},
    {"mph", Dimension::kSpeed, 1609.344 / 3600.0},
    {"knots", Dimension::kSpeed, 1852.0 / 3600.0},
    {"ft/s", Dimension::kSpeed, 0.3048},
    {"uT", Dimension::kField, 1.0},
    {"nT", Dimension::kField, 1e-3},
    {"mT", Dimension::kField, 1e3},
    {"T", Dimension::kField, 1e6},
    {"gauss", Dimension::kField, 100.0},
    {"mG", Dimension::kField, 0.1},
    {"m", Dimension::kLength, 1.0},
    {"mm", Dimension::kLength, 1e-3},
    {"cm", Dimension::kLength, 1e-2},
    {"km", Dimension::kLength, 1e3},
    {"ft", Dimension::kLength, 0.3048},
    {"in", Dimension::kLength, 0.0254},
    {"s", Dimension::kTime, 1.0},
    {"ms", Dimension::kTime, 1e-3},
    {"us", Dimension::kTime, 1e-6},
    {"ns", Dimension::kTime, 1e-9},
};

const Unit* FindUnit(const std::string& name) {
  for (const Unit& unit : kUnits) {
    if (name == unit.name) return &unit;
  }
  return nullptr;
}

std::string UnitList() {
  std::string list;
  for (const Unit& unit : kUnits) list += (list.empty() ? "" : ", ") + std::string(unit.name);
  return list;
}

// The canonical unit of each column of a type; wheel_encoders and magnetometer follow the dimension of the declared
// units (`declared`, kNone when none was given).
std::vector<const Unit*> CanonicalUnits(StreamType type, std::size_t columns, Dimension declared) {
  auto repeat = [](const char* unit, std::size_t n) { return std::vector<const Unit*>(n, FindUnit(unit)); };
  auto concat = [](std::vector<const Unit*> a, const std::vector<const Unit*>& b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
  };
  switch (type) {
    case StreamType::kImu:
      return concat(repeat("rad/s", 3), repeat("m/s^2", 3));
    case StreamType::kGyroscope:
      return repeat("rad/s", 3);
    case StreamType::kAccelerometer:
      return repeat("m/s^2", 3);
    case StreamType::kMagnetometer:
      return repeat(declared == Dimension::kField ? "uT" : "normalized", 3);
    case StreamType::kGps:
      return concat(repeat("deg", 2), repeat("m", 1));
    case StreamType::kPosition:
      return repeat("m", 3);
    case StreamType::kPose:
      return concat(repeat("m", 3), repeat("1", 4));
    case StreamType::kWheelEncoders:
      return repeat(declared == Dimension::kRate ? "rad/s" : declared == Dimension::kSpeed ? "m/s" : "rad", columns);
    case StreamType::kSteering:
      return repeat("rad", 1);
    case StreamType::kOdometry:
    case StreamType::kVisualOdometry:
    case StreamType::kScanMatching:
      return concat(repeat("m/s", 3), repeat("rad/s", 3));
    default:
      return {};
  }
}

// The vector triples a fixed sensor-axis rotation applies to.
std::vector<int> Triples(StreamType type) {
  switch (type) {
    case StreamType::kImu:
    case StreamType::kOdometry:
    case StreamType::kVisualOdometry:
    case StreamType::kScanMatching:
      return {0, 3};
    case StreamType::kGyroscope:
    case StreamType::kAccelerometer:
    case StreamType::kMagnetometer:
      return {0};
    default:
      return {};
  }
}

struct Context {
  const std::string& path;
  Status Error(const YAML::Node& node, const std::string& problem) const {
    return Status::Error(rin::Where(path, node) + ": " + problem);
  }
};

Status ReadInt(const Context& ctx, const YAML::Node& node, const std::string& what, int min_value, int* out) {
  double value = 0.0;
  if (Status s = rin::ReadNumber(node, ctx.path, what, &value); !s.ok()) return s;
  if (value != std::floor(value) || value < min_value || value > 1e9) {
    return ctx.Error(node, what + " must be an integer >= " + std::to_string(min_value));
  }
  *out = static_cast<int>(value);
  return Status::Ok();
}

Status ReadBool(const Context& ctx, const YAML::Node& node, const std::string& what, bool* out) {
  const std::string text = node.IsScalar() ? node.Scalar() : "";
  if (text != "true" && text != "false") return ctx.Error(node, what + " must be true or false");
  *out = text == "true";
  return Status::Ok();
}

Status ReadColumnRef(const Context& ctx, const YAML::Node& node, bool header, const std::string& what, ColumnRef* out) {
  if (!node.IsScalar()) return ctx.Error(node, what + " must be a column name or index");
  if (header) {
    out->name = node.Scalar();
    return Status::Ok();
  }
  return ReadInt(ctx, node, what + " (a 0-based index: header is false)", 0, &out->index);
}

// Reads the csv keys present in `node` over `format`; `time` is skipped (a files entry holds it too).
Status ReadFormat(const Context& ctx, const YAML::Node& node, const std::string& context, CsvFormat* format) {
  if (node["delimiter"]) {
    std::string text;
    if (Status s = rin::ReadString(node["delimiter"], ctx.path, "delimiter", &text); !s.ok()) return s;
    format->whitespace = text == "whitespace";
    if (text == "\\t" || text == "tab") text = "\t";
    if (!format->whitespace && (text.size() != 1 || std::string(",;\t|").find(text[0]) == std::string::npos)) {
      return ctx.Error(node["delimiter"], "delimiter '" + text + "' in " + context +
                                              " is not one of \",\", \";\", \"\\t\", \"|\", whitespace");
    }
    if (!format->whitespace) format->delimiter = text[0];
  }
  if (node["header"]) {
    if (Status s = ReadBool(ctx, node["header"], "header", &format->header); !s.ok()) return s;
  }
  if (node["comment"]) {
    if (Status s = rin::ReadString(node["comment"], ctx.path, "comment", &format->comment); !s.ok()) return s;
  }
  if (node["skip_rows"]) {
    if (Status s = ReadInt(ctx, node["skip_rows"], "skip_rows", 0, &format->skip_rows); !s.ok()) return s;
  }
  if (node["non_numeric"]) {
    const YAML::Node value = node["non_numeric"];
    const std::string text = value.IsScalar() ? value.Scalar() : "";
    if (text != "error" && text != "skip_row") return ctx.Error(value, "non_numeric must be error or skip_row");
    format->skip_non_numeric = text == "skip_row";
  }
  return Status::Ok();
}

Status ReadTimeUnit(const Context& ctx, const YAML::Node& node, const std::string& what, int* exponent) {
  const std::string text = node.IsScalar() ? node.Scalar() : "";
  const char* names[] = {"s", "ms", "us", "ns"};
  for (int i = 0; i < 4; ++i) {
    if (text == names[i]) {
      *exponent = 3 * i;
      return Status::Ok();
    }
  }
  return ctx.Error(node, "unknown unit '" + text + "' for " + what + " (s, ms, us, ns)");
}

Status ReadTime(const Context& ctx, const YAML::Node& node, bool header, TimeSpec* time) {
  if (Status s = rin::CheckKeys(node, ctx.path, "time", {"column", "unit", "clock", "offset_s"}); !s.ok()) return s;
  if (Status s = rin::RequireKey(node, "column", ctx.path, "time"); !s.ok()) return s;
  if (Status s = ReadColumnRef(ctx, node["column"], header, "time column", &time->column); !s.ok()) return s;
  if (node["unit"]) {
    if (Status s = ReadTimeUnit(ctx, node["unit"], "time", &time->decimal_exponent); !s.ok()) return s;
  }
  if (node["clock"]) {
    const std::string text = node["clock"].IsScalar() ? node["clock"].Scalar() : "";
    if (text != "relative" && text != "epoch") return ctx.Error(node["clock"], "clock must be relative or epoch");
    time->epoch = text == "epoch";
  }
  if (node["offset_s"]) {
    if (Status s = rin::ReadNumber(node["offset_s"], ctx.path, "offset_s", &time->offset_s); !s.ok()) return s;
  }
  return Status::Ok();
}

Status ReadFiles(const Context& ctx, const YAML::Node& root, int file_count, std::vector<FileSpec>* files) {
  CsvFormat defaults;
  if (root["csv"]) {
    if (Status s = rin::CheckKeys(root["csv"], ctx.path, "csv",
                                  {"delimiter", "header", "comment", "skip_rows", "non_numeric"});
        !s.ok())
      return s;
    if (Status s = ReadFormat(ctx, root["csv"], "csv", &defaults); !s.ok()) return s;
  }
  const YAML::Node entries = root["files"];
  if (entries && (!entries.IsSequence() || static_cast<int>(entries.size()) > file_count)) {
    return ctx.Error(entries, "files must be a list of at most " + std::to_string(file_count) +
                                  " entries (one per input file, in command-line order)");
  }
  for (int i = 0; i < file_count; ++i) {
    FileSpec file;
    file.format = defaults;
    const bool has_entry = entries && i < static_cast<int>(entries.size());
    const YAML::Node entry = has_entry ? entries[i] : YAML::Node();
    const std::string context = "files[" + std::to_string(i) + "]";
    if (has_entry) {
      if (Status s = rin::CheckKeys(entry, ctx.path, context,
                                    {"delimiter", "header", "comment", "skip_rows", "non_numeric", "time"});
          !s.ok()) {
        return s;
      }
      if (Status s = ReadFormat(ctx, entry, context, &file.format); !s.ok()) return s;
    }
    const YAML::Node time = has_entry && entry["time"] ? entry["time"] : root["time"];
    if (!time) return ctx.Error(root, "missing required key 'time' (at the top or in " + context + ")");
    if (Status s = ReadTime(ctx, time, file.format.header, &file.time); !s.ok()) return s;
    files->push_back(file);
  }
  return Status::Ok();
}

// `axes: [x, -z, y]`, `rotation_wxyz` or `rotation_matrix` of a stream entry into R (v_out = R v_in).
Status ReadRotation(const Context& ctx, const YAML::Node& node, const std::string& context, Eigen::Matrix3d* r) {
  int given = 0;
  for (const char* key : {"axes", "rotation_wxyz", "rotation_matrix"}) given += node[key] ? 1 : 0;
  if (given > 1) return ctx.Error(node, context + ": give one of axes, rotation_wxyz, rotation_matrix");
  r->setZero();
  if (node["axes"]) {
    std::vector<std::string> axes;
    if (Status s = rin::ReadStringList(node["axes"], ctx.path, "axes of " + context, &axes); !s.ok()) return s;
    std::set<char> used;
    for (std::size_t i = 0; i < axes.size() && axes.size() == 3; ++i) {
      std::string axis = axes[i];
      const double sign = !axis.empty() && axis[0] == '-' ? -1.0 : 1.0;
      if (!axis.empty() && (axis[0] == '-' || axis[0] == '+')) axis.erase(0, 1);
      if (axis.size() != 1 || axis[0] < 'x' || axis[0] > 'z' || !used.insert(axis[0]).second) break;
      (*r)(static_cast<Eigen::Index>(i), axis[0] - 'x') = sign;
    }
    if (used.size() != 3) {
      return ctx.Error(node["axes"], "axes of " + context + " must name x, y, z once each, with optional signs");
    }
    return Status::Ok();
  }
  std::vector<double> values;
  if (node["rotation_wxyz"]) {
    if (Status s = rin::ReadNumberList(node["rotation_wxyz"], ctx.path, "rotation_wxyz of " + context, 4, &values);
        !s.ok()) {
      return s;
    }
    Eigen::Quaterniond q(values[0], values[1], values[2], values[3]);
    if (!rin::NormalizeNearUnit(&q)) return ctx.Error(node["rotation_wxyz"], "rotation_wxyz is not a unit quaternion");
    *r = q.toRotationMatrix();
    return Status::Ok();
  }
  const YAML::Node rows = node["rotation_matrix"];
  if (!rows.IsSequence() || rows.size() != 3) return ctx.Error(rows, "rotation_matrix must be 3 rows of 3 numbers");
  for (std::size_t i = 0; i < 3; ++i) {
    if (Status s = rin::ReadNumberList(rows[i], ctx.path, "rotation_matrix row", 3, &values); !s.ok()) return s;
    for (int j = 0; j < 3; ++j) (*r)(static_cast<Eigen::Index>(i), j) = values[static_cast<std::size_t>(j)];
  }
  if (!((*r) * r->transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-6)) {
    return ctx.Error(rows, "rotation_matrix of " + context + " is not orthonormal");
  }
  return Status::Ok();
}

// units: one unit (for every column of its dimension) or a list (one per column) -> spec->scale, spec->info.units.
Status ReadUnits(const Context& ctx, const YAML::Node& entry, const std::string& context, StreamSpec* spec) {
  const std::size_t n = spec->sources.size();
  const YAML::Node node = entry["units"];
  spec->scale.assign(n, 1.0);
  if (spec->info.type == StreamType::kInputs) {  // free units, kept as given
    if (node && node.IsScalar()) spec->info.units = node.Scalar();
    if (node && !node.IsScalar()) return ctx.Error(node, "units of " + context + " (inputs) must be one string");
    return Status::Ok();
  }
  if (!node) return Status::Ok();
  std::vector<std::string> names;
  const bool one = node.IsScalar();
  if (one) {
    names.assign(n, node.Scalar());
  } else if (Status s = rin::ReadStringList(node, ctx.path, "units of " + context, &names); !s.ok()) {
    return s;
  } else if (names.size() != n) {
    return ctx.Error(node, "units of " + context + " has " + std::to_string(names.size()) + " entries for " +
                               std::to_string(n) + " columns");
  }
  std::vector<const Unit*> units;
  for (const std::string& name : names) {
    const Unit* unit = FindUnit(name);
    if (!unit) return ctx.Error(node, "unknown unit '" + name + "' in " + context + " (known: " + UnitList() + ")");
    units.push_back(unit);
  }
  const std::vector<const Unit*> canonical = CanonicalUnits(spec->info.type, n, units.front()->dimension);
  bool matched = false;
  for (std::size_t c = 0; c < n; ++c) {
    const Unit* unit = units[c];
    if (unit->dimension != canonical[c]->dimension) {
      if (one) continue;
      return ctx.Error(node, "unit '" + names[c] + "' of " + context + " column " + spec->info.columns[c] + " is " +
                                 DimensionName(unit->dimension) + ", the column needs " +
                                 DimensionName(canonical[c]->dimension));
    }
    matched = true;
    double si = unit->si;
    if (std::string(unit->name) == "ticks") {
      const auto it = spec->info.attributes.find("ticks_per_revolution");
      if (it == spec->info.attributes.end() || !(it->second > 0.0)) {
        return ctx.Error(node, context + ": units ticks need a positive attributes.ticks_per_revolution");
      }
      si = 2.0 * kPi / it->second;
    }
    spec->scale[c] = si / canonical[c]->si;
  }
  if (!matched) {
    return ctx.Error(node, "unit '" + names.front() + "' (" + DimensionName(units.front()->dimension) + ") fits no " +
                               "column of " + context);
  }
  const StreamType type = spec->info.type;
  if (type == StreamType::kMagnetometer || type == StreamType::kWheelEncoders) spec->info.units = canonical[0]->name;
  return Status::Ok();
}

Status ReadCollapse(const Context& ctx, const YAML::Node& node, bool header, const std::string& context,
                    StreamSpec* spec) {
  if (node.IsScalar() && node.Scalar() == "by_change") {
    spec->collapse = Collapse::kByChange;
    return Status::Ok();
  }
  if (!node.IsMap()) return ctx.Error(node, "collapse of " + context + " must be by_change or {by_column: COLUMN}");
  if (Status s = rin::CheckKeys(node, ctx.path, "collapse of " + context, {"by_column", "unit"}); !s.ok()) return s;
  if (Status s = rin::RequireKey(node, "by_column", ctx.path, "collapse of " + context); !s.ok()) return s;
  spec->collapse = Collapse::kByColumn;
  if (Status s = ReadColumnRef(ctx, node["by_column"], header, "by_column", &spec->collapse_column); !s.ok()) return s;
  if (node["unit"]) return ReadTimeUnit(ctx, node["unit"], "by_column", &spec->collapse_exponent);
  return Status::Ok();
}

// The recording side of a stream entry: type, output columns, rate, mounting, noise, attributes.
Status ReadStreamInfo(const Context& ctx, const YAML::Node& entry, const std::string& context, StreamSpec* spec) {
  recording::StreamInfo& info = spec->info;
  std::string type_name;
  if (Status s = rin::ReadString(entry["type"], ctx.path, "type of " + context, &type_name); !s.ok()) return s;
  const std::optional<StreamType> type = recording::ParseStreamType(type_name);
  if (!type || *type == StreamType::kCamera || *type == StreamType::kLaserScan) {
    return ctx.Error(entry["type"], "type '" + type_name + "' of " + context + " cannot be imported from CSV");
  }
  info.type = *type;
  info.columns = recording::FixedColumns(info.type);
  if (info.type == StreamType::kWheelEncoders || info.type == StreamType::kInputs) {
    if (Status s = rin::RequireKey(entry, "names", ctx.path, context); !s.ok()) return s;
    if (Status s = rin::ReadStringList(entry["names"], ctx.path, "names of " + context, &info.columns); !s.ok()) {
      return s;
    }
    const std::string problem = rin::FreeColumnsProblem(info.columns);
    if (!problem.empty()) return ctx.Error(entry["names"], context + ": " + problem);
  } else if (entry["names"]) {
    return ctx.Error(entry["names"], context + ": names are fixed by type " + type_name);
  }
  if (entry["rate_hz"]) {
    if (Status s = rin::ReadNumber(entry["rate_hz"], ctx.path, "rate_hz", &info.rate_hz); !s.ok()) return s;
    if (!(info.rate_hz > 0.0)) return ctx.Error(entry["rate_hz"], "rate_hz of " + context + " must be positive");
  }
  if (entry["noise"]) {
    if (Status s = rin::ReadNumberMap(entry["noise"], ctx.path, "noise", &info.noise); !s.ok()) return s;
  }
  if (entry["attributes"]) {
    if (Status s = rin::ReadNumberMap(entry["attributes"], ctx.path, "attributes", &info.attributes); !s.ok()) return s;
  }
  if (const YAML::Node m = entry["mounting"]) {
    if (Status s = rin::CheckKeys(m, ctx.path, "mounting", {"p_body_sensor_m", "q_body_sensor_wxyz"}); !s.ok())
      return s;
    recording::Mounting mounting;
    std::vector<double> v;
    if (m["p_body_sensor_m"]) {
      if (Status s = rin::ReadNumberList(m["p_body_sensor_m"], ctx.path, "p_body_sensor_m", 3, &v); !s.ok()) return s;
      mounting.p_body_sensor = Eigen::Vector3d(v[0], v[1], v[2]);
    }
    if (m["q_body_sensor_wxyz"]) {
      if (Status s = rin::ReadNumberList(m["q_body_sensor_wxyz"], ctx.path, "q_body_sensor_wxyz", 4, &v); !s.ok())
        return s;
      mounting.q_body_sensor = Eigen::Quaterniond(v[0], v[1], v[2], v[3]);
      if (!rin::NormalizeNearUnit(&mounting.q_body_sensor)) {
        return ctx.Error(m["q_body_sensor_wxyz"], "q_body_sensor_wxyz is not a unit quaternion");
      }
    }
    info.mounting = mounting;
  }
  return Status::Ok();
}

Status ReadStream(const Context& ctx, const YAML::Node& entry, const std::string& name,
                  const std::vector<FileSpec>& files, StreamSpec* spec) {
  const std::string context = "stream '" + name + "'";
  if (Status s = rin::CheckKeys(entry, ctx.path, context,
                                {"type", "file", "columns", "names", "units", "axes", "rotation_wxyz",
                                 "rotation_matrix", "collapse", "rate_hz", "noise", "mounting", "attributes"});
      !s.ok()) {
    return s;
  }
  for (const char* key : {"type", "columns"}) {
    if (Status s = rin::RequireKey(entry, key, ctx.path, context); !s.ok()) return s;
  }
  if (!rin::IsIdentifier(name)) return ctx.Error(entry, "stream name '" + name + "' must be [A-Za-z0-9_]+");
  spec->info.name = name;
  if (Status s = ReadStreamInfo(ctx, entry, context, spec); !s.ok()) return s;
  if (entry["file"]) {
    if (Status s = ReadInt(ctx, entry["file"], "file of " + context, 0, &spec->file); !s.ok()) return s;
    if (spec->file >= static_cast<int>(files.size())) {
      return ctx.Error(entry["file"], context + " reads file " + std::to_string(spec->file) + " but " +
                                          std::to_string(files.size()) + " input file(s) were given");
    }
  }
  const bool header = files[static_cast<std::size_t>(spec->file)].format.header;
  const YAML::Node columns = entry["columns"];
  if (!columns.IsSequence() || columns.size() != spec->info.columns.size()) {
    return ctx.Error(columns, "columns of " + context + " must list " + std::to_string(spec->info.columns.size()) +
                                  " source columns, one for each of " + rin::JoinColumns(spec->info.columns));
  }
  spec->sources.resize(columns.size());
  for (std::size_t c = 0; c < columns.size(); ++c) {
    if (Status s = ReadColumnRef(ctx, columns[c], header, "column of " + context, &spec->sources[c]); !s.ok()) return s;
  }
  if (Status s = ReadUnits(ctx, entry, context, spec); !s.ok()) return s;
  if (entry["axes"] || entry["rotation_wxyz"] || entry["rotation_matrix"]) {
    spec->triples = Triples(spec->info.type);
    if (spec->triples.empty()) return ctx.Error(entry, context + ": its type has no sensor-axis vectors to rotate");
    Eigen::Matrix3d r;
    if (Status s = ReadRotation(ctx, entry, context, &r); !s.ok()) return s;
    spec->rotation = r;
  }
  if (entry["collapse"]) return ReadCollapse(ctx, entry["collapse"], header, context, spec);
  return Status::Ok();
}

Status ReadPlatformAndOrigin(const Context& ctx, const YAML::Node& root, Mapping* mapping) {
  mapping->platform.kind = "unknown";
  if (const YAML::Node p = root["platform"]) {
    if (Status s = rin::CheckKeys(p, ctx.path, "platform", {"kind", "geometry"}); !s.ok()) return s;
    if (p["kind"]) {
      if (Status s = rin::ReadString(p["kind"], ctx.path, "platform kind", &mapping->platform.kind); !s.ok()) return s;
    }
    if (p["geometry"]) {
      if (Status s = rin::ReadNumberMap(p["geometry"], ctx.path, "geometry", &mapping->platform.geometry); !s.ok())
        return s;
    }
  }
  if (const YAML::Node o = root["origin"]) {
    if (Status s = rin::CheckKeys(o, ctx.path, "origin", {"latitude_deg", "longitude_deg", "altitude_m"}); !s.ok())
      return s;
    recording::GeodeticOrigin origin;
    double* fields[] = {&origin.latitude_deg, &origin.longitude_deg, &origin.altitude_m};
    const char* keys[] = {"latitude_deg", "longitude_deg", "altitude_m"};
    for (int i = 0; i < 3; ++i) {
      if (Status s = rin::RequireKey(o, keys[i], ctx.path, "origin"); !s.ok()) return s;
      if (Status s = rin::ReadNumber(o[keys[i]], ctx.path, keys[i], fields[i]); !s.ok()) return s;
    }
    const std::string problem = rin::OriginProblem(origin);
    if (!problem.empty()) return ctx.Error(o, problem);
    mapping->origin = origin;
  }
  return Status::Ok();
}

Result<Mapping> ReadMapping(const std::string& path, const YAML::Node& root, int file_count) {
  const Context ctx{path};
  if (Status s =
          rin::CheckKeys(root, path, "the mapping file", {"csv", "time", "files", "platform", "origin", "streams"});
      !s.ok()) {
    return s;
  }
  Mapping mapping;
  if (Status s = ReadFiles(ctx, root, file_count, &mapping.files); !s.ok()) return s;
  if (Status s = ReadPlatformAndOrigin(ctx, root, &mapping); !s.ok()) return s;
  const YAML::Node streams = root["streams"];
  if (!streams || !streams.IsMap() || streams.size() == 0) {
    return ctx.Error(streams ? streams : root, "streams must be a mapping of at least one stream name to its entry");
  }
  std::set<std::string> names;
  for (const auto& item : streams) {
    StreamSpec spec;
    const std::string name = item.first.IsScalar() ? item.first.Scalar() : "";
    if (!names.insert(name).second) return ctx.Error(item.first, "duplicate stream '" + name + "'");
    if (Status s = ReadStream(ctx, item.second, name, mapping.files, &spec); !s.ok()) return s;
    mapping.streams.push_back(std::move(spec));
  }
  return mapping;
}

}  // namespace

Result<Mapping> ReadCsvMapping(const std::string& path, int file_count) {
  YAML::Node root;
  if (Status s = rin::LoadYamlFile(path, &root); !s.ok()) return s;
  try {
    return ReadMapping(path, root, file_count);
  } catch (const YAML::Exception& e) {  // a node shape the checks above did not foresee
    return Status::Error(path + ": " + e.msg);
  }
}

}  // namespace roamlab::importers::internal
