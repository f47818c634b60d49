#include "recording/trajectory.h"

#include <array>
#include <cmath>
#include <string_view>

#include "common/atomic_file.h"
#include "recording/internal/text_io.h"

namespace roamlab {
namespace {

using recording::internal::AppendFull;
using recording::internal::NormalizeNearUnit;
using recording::internal::NumberParse;
using recording::internal::ParseNumber;
using recording::internal::ReadTextFile;
using recording::internal::TimeOrderProblem;
using recording::internal::Trim;

constexpr std::array<const char*, 8> kTumFields = {"t", "x", "y", "z", "qx", "qy", "qz", "qw"};

// Splits `line` at runs of spaces and tabs.
std::vector<std::string_view> SplitFields(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const std::size_t begin = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > begin) fields.push_back(line.substr(begin, i - begin));
  }
  return fields;
}

// Parses the eight fields of one pose line; `where` is "<path>:<line>".
Status ParsePoseLine(const std::vector<std::string_view>& fields, const std::string& where, StampedPose* pose) {
  if (fields.size() != kTumFields.size()) {
    return Status::Error(where + ": expected 8 fields 't x y z qx qy qz qw', found " + std::to_string(fields.size()));
  }
  const std::optional<Time> t = ParseSeconds(fields[0]);
  if (!t) return Status::Error(where + ": field 't': not a time '" + std::string(fields[0]) + "'");
  pose->t = *t;
  // Position and quaternion (x y z w in the file).
  std::array<double, 7> v{};
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::string name = kTumFields[i + 1];
    switch (ParseNumber(fields[i + 1], &v[i])) {
      case NumberParse::kOk:
        break;
      case NumberParse::kNaN:
        return Status::Error(where + ": field '" + name + "' is NaN");
      case NumberParse::kInf:
        return Status::Error(where + ": field '" + name + "' is Inf");
      case NumberParse::kNotANumber:
        return Status::Error(where + ": field '" + name + "': not a number '" + std::string(fields[i + 1]) + "'");
    }
  }
  pose->p_world_body = Eigen::Vector3d(v[0], v[1], v[2]);
  pose->q_world_body = Eigen::Quaterniond(v[6], v[3], v[4], v[5]);
  if (!NormalizeNearUnit(&pose->q_world_body)) {
    return Status::Error(where + ": quaternion norm " + std::to_string(pose->q_world_body.norm()) +
                         " is not 1 (tolerance 1e-3)");
  }
  return Status::Ok();
}

}  // namespace

Result<Trajectory> ReadTum(const std::string& path) {
  std::string content;
  if (Status status = ReadTextFile(path, &content); !status.ok()) return status;
  Trajectory trajectory;
  std::size_t position = 0;
  int line_number = 0;
  while (position < content.size()) {
    // Next line; comments and blank lines are skipped.
    std::size_t end = content.find('\n', position);
    if (end == std::string::npos) end = content.size();
    const std::string_view line = Trim(std::string_view(content).substr(position, end - position));
    position = end + 1;
    ++line_number;
    if (line.empty() || line.front() == '#') continue;
    // Pose, strictly after the previous one.
    const std::string where = path + ":" + std::to_string(line_number);
    StampedPose pose;
    if (Status status = ParsePoseLine(SplitFields(line), where, &pose); !status.ok()) return status;
    if (!trajectory.empty() && pose.t <= trajectory.back().t) {
      return Status::Error(where + ": " + TimeOrderProblem(trajectory.back().t, pose.t));
    }
    trajectory.push_back(pose);
  }
  return trajectory;
}

Status WriteTum(const Trajectory& trajectory, const std::string& path) {
  std::string out = "# t x y z qx qy qz qw\n";
  for (std::size_t i = 0; i < trajectory.size(); ++i) {
    const StampedPose& pose = trajectory[i];
    // Refuse what ReadTum would reject: the file must read back.
    if (i > 0 && pose.t <= trajectory[i - 1].t) {
      return Status::Error(path + ": pose " + std::to_string(i) + ": " + TimeOrderProblem(trajectory[i - 1].t, pose.t));
    }
    if (!pose.p_world_body.allFinite() || !pose.q_world_body.coeffs().allFinite() ||
        std::abs(pose.q_world_body.norm() - 1.0) >= recording::internal::kQuaternionNormTolerance) {
      return Status::Error(path + ": pose " + std::to_string(i) + ": non-finite value or non-unit quaternion");
    }
    // "t x y z qx qy qz qw".
    out += FormatSeconds(pose.t);
    for (double value : {pose.p_world_body.x(), pose.p_world_body.y(), pose.p_world_body.z(), pose.q_world_body.x(),
                         pose.q_world_body.y(), pose.q_world_body.z(), pose.q_world_body.w()}) {
      out += ' ';
      AppendFull(value, &out);
    }
    out += '\n';
  }
  return WriteFileAtomic(path, out);
}

}  // namespace roamlab
