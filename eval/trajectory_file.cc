#include "eval/trajectory_file.h"

#include <array>
#include <cstdint>
#include <filesystem>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>

#include "recording/internal/text_io.h"

namespace roamlab::eval {
namespace {

using recording::internal::NormalizeNearUnit;
using recording::internal::NumberParse;
using recording::internal::ParseNumber;
using recording::internal::ReadTextFile;
using recording::internal::TimeOrderProblem;
using recording::internal::Trim;

// One non-blank, non-comment line and its 1-based number.
struct Line {
  std::string_view text;
  int number = 0;
};

// The data lines of a file: blank lines and lines starting with '#' are left out.
std::vector<Line> DataLines(const std::string& content) {
  std::vector<Line> lines;
  std::size_t position = 0;
  int number = 0;
  while (position < content.size()) {
    std::size_t end = content.find('\n', position);
    if (end == std::string::npos) end = content.size();
    const std::string_view line = Trim(std::string_view(content).substr(position, end - position));
    position = end + 1;
    ++number;
    if (!line.empty() && line.front() != '#') lines.push_back({line, number});
  }
  return lines;
}

// Splits at commas (every cell kept, trimmed) or at runs of spaces and tabs.
std::vector<std::string_view> Split(std::string_view line, bool commas) {
  std::vector<std::string_view> fields;
  if (commas) {
    std::size_t begin = 0;
    while (true) {
      const std::size_t end = line.find(',', begin);
      fields.push_back(Trim(line.substr(begin, end == std::string_view::npos ? std::string_view::npos : end - begin)));
      if (end == std::string_view::npos) break;
      begin = end + 1;
    }
    return fields;
  }
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const std::size_t begin = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > begin) fields.push_back(line.substr(begin, i - begin));
  }
  return fields;
}

// Parses fields [first, first + n) as finite numbers; `where` is "<path>:<line>".
Status ParseNumbers(const std::vector<std::string_view>& fields, std::size_t first, std::size_t n,
                    const std::string& where, double* out) {
  for (std::size_t i = 0; i < n; ++i) {
    const std::string column = "column " + std::to_string(first + i + 1);
    switch (ParseNumber(fields[first + i], &out[i])) {
      case NumberParse::kOk:
        break;
      case NumberParse::kNaN:
        return Status::Error(where + ": " + column + " is NaN");
      case NumberParse::kInf:
        return Status::Error(where + ": " + column + " is Inf");
      case NumberParse::kNotANumber:
        return Status::Error(where + ": " + column + ": not a number '" + std::string(fields[first + i]) + "'");
    }
  }
  return Status::Ok();
}

// A non-negative integer of nanoseconds.
std::optional<Time> ParseNanoseconds(std::string_view text) {
  if (text.empty() || text.size() > 19) return std::nullopt;
  std::int64_t ns = 0;
  for (char c : text) {
    if (c < '0' || c > '9') return std::nullopt;
    ns = ns * 10 + (c - '0');
  }
  return Time::FromNanoseconds(ns);
}

Status KittiPose(const std::vector<std::string_view>& fields, const std::string& where, StampedPose* pose) {
  if (fields.size() != 12)
    return Status::Error(where + ": expected 12 fields (a 3x4 pose matrix, row-major), found " +
                         std::to_string(fields.size()));
  std::array<double, 12> v{};
  if (Status s = ParseNumbers(fields, 0, 12, where, v.data()); !s.ok()) return s;
  Eigen::Matrix3d r;
  r << v[0], v[1], v[2], v[4], v[5], v[6], v[8], v[9], v[10];
  const double orthonormality = (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (orthonormality > 1e-3 || r.determinant() < 0.0)
    return Status::Error(where + ": the rotation is not a proper orthonormal matrix (|R^T R - I| = " +
                         std::to_string(orthonormality) + ", det " + std::to_string(r.determinant()) + ")");
  pose->p_world_body = Eigen::Vector3d(v[3], v[7], v[11]);
  pose->q_world_body = Eigen::Quaterniond(r).normalized();
  return Status::Ok();
}

Status EurocPose(const std::vector<std::string_view>& fields, const std::string& where, StampedPose* pose) {
  if (fields.size() < 8)
    return Status::Error(where + ": expected at least 8 comma-separated fields 'timestamp [ns], p x y z, q w x y z', " +
                         "found " + std::to_string(fields.size()));
  const std::optional<Time> t = ParseNanoseconds(fields[0]);
  if (!t) return Status::Error(where + ": column 1: not a timestamp in nanoseconds '" + std::string(fields[0]) + "'");
  std::array<double, 7> v{};
  if (Status s = ParseNumbers(fields, 1, 7, where, v.data()); !s.ok()) return s;
  pose->t = *t;
  pose->p_world_body = Eigen::Vector3d(v[0], v[1], v[2]);
  pose->q_world_body = Eigen::Quaterniond(v[3], v[4], v[5], v[6]);
  if (!NormalizeNearUnit(&pose->q_world_body))
    return Status::Error(where + ": quaternion norm " + std::to_string(pose->q_world_body.norm()) +
                         " is not 1 (tolerance 1e-3)");
  return Status::Ok();
}

// True when the line's first field is not a number: a header such as EuRoC's without '#'.
bool IsHeader(std::string_view line) {
  const std::vector<std::string_view> fields = Split(line, line.find(',') != std::string_view::npos);
  double value = 0.0;
  return fields.empty() || ParseNumber(fields[0], &value) == NumberParse::kNotANumber;
}

Result<TrajectoryFile> ReadLines(const std::string& path, const std::vector<Line>& lines, TrajectoryFormat format) {
  TrajectoryFile file;
  file.format = format;
  file.timed = format != TrajectoryFormat::kKitti;
  for (std::size_t k = 0; k < lines.size(); ++k) {
    if (k == 0 && format == TrajectoryFormat::kEuroc && IsHeader(lines[k].text)) continue;
    const std::string where = path + ":" + std::to_string(lines[k].number);
    StampedPose pose;
    Status s = format == TrajectoryFormat::kKitti ? KittiPose(Split(lines[k].text, false), where, &pose)
                                                  : EurocPose(Split(lines[k].text, true), where, &pose);
    if (!s.ok()) return s;
    if (format == TrajectoryFormat::kKitti)
      pose.t = Time::FromNanoseconds(1000000000LL * static_cast<std::int64_t>(file.poses.size()));
    if (!file.poses.empty() && pose.t <= file.poses.back().t)
      return Status::Error(where + ": " + TimeOrderProblem(file.poses.back().t, pose.t));
    file.poses.push_back(pose);
  }
  return file;
}

}  // namespace

const char* TrajectoryFormatName(TrajectoryFormat format) {
  switch (format) {
    case TrajectoryFormat::kTum:
      return "tum";
    case TrajectoryFormat::kKitti:
      return "kitti";
    case TrajectoryFormat::kEuroc:
      return "euroc";
  }
  return "tum";
}

std::optional<TrajectoryFormat> ParseTrajectoryFormat(const std::string& name) {
  for (TrajectoryFormat format : {TrajectoryFormat::kTum, TrajectoryFormat::kKitti, TrajectoryFormat::kEuroc})
    if (name == TrajectoryFormatName(format)) return format;
  return std::nullopt;
}

Result<TrajectoryFormat> DetectTrajectoryFormat(const std::string& path) {
  const std::string extension = std::filesystem::path(path).extension().string();
  if (extension == ".tum") return TrajectoryFormat::kTum;
  if (extension == ".kitti") return TrajectoryFormat::kKitti;
  std::string content;
  if (Status s = ReadTextFile(path, &content); !s.ok()) return s;
  std::vector<Line> lines = DataLines(content);
  if (!lines.empty() && lines.front().text.find(',') != std::string_view::npos) return TrajectoryFormat::kEuroc;
  if (lines.empty()) return Status::Error(path + ": no poses");
  const std::size_t fields = Split(lines.front().text, false).size();
  if (fields == 12) return TrajectoryFormat::kKitti;
  if (fields == 8) return TrajectoryFormat::kTum;
  return Status::Error(path + ":" + std::to_string(lines.front().number) + ": " + std::to_string(fields) +
                       " fields fit no trajectory format (tum: 8 't x y z qx qy qz qw', kitti: 12, euroc: comma-" +
                       "separated); give the format explicitly");
}

Result<TrajectoryFile> ReadTrajectoryFile(const std::string& path, std::optional<TrajectoryFormat> format) {
  if (!format) {
    Result<TrajectoryFormat> detected = DetectTrajectoryFormat(path);
    if (!detected.ok()) return detected.status();
    format = detected.value();
  }
  if (*format == TrajectoryFormat::kTum) {
    Result<Trajectory> poses = ReadTum(path);
    if (!poses.ok()) return poses.status();
    TrajectoryFile file;
    file.poses = std::move(poses).value();
    return file;
  }
  std::string content;
  if (Status s = ReadTextFile(path, &content); !s.ok()) return s;
  return ReadLines(path, DataLines(content), *format);
}

}  // namespace roamlab::eval
