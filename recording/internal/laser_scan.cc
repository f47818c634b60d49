#include "recording/internal/laser_scan.h"

namespace roamlab::recording::internal {

std::string LaserScanColumnsProblem(const std::vector<std::string>& columns) {
  const int beams = static_cast<int>(columns.size()) - 4;
  if (beams < 1 || columns != LaserScanColumns(beams)) {
    return "laser_scan columns must be angle_min_rad, angle_increment_rad, range_min_m, range_max_m, range_0, ..., "
           "range_<N-1> with N >= 1";
  }
  return "";
}

std::string LaserScanRowsProblem(const Stream& stream) {
  if (stream.info.type != StreamType::kLaserScan) return "";
  for (Eigen::Index row = 0; row < stream.values.rows(); ++row) {
    const std::string line = std::to_string(row + 2) + ": ";
    if (stream.values(row, 1) == 0.0) return line + "angle_increment_rad is 0";
    if (stream.values(row, 2) < 0.0) return line + "range_min_m is negative";
    if (!(stream.values(row, 3) > stream.values(row, 2))) return line + "range_max_m is not above range_min_m";
  }
  return "";
}

}  // namespace roamlab::recording::internal
