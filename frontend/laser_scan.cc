#include "frontend/laser_scan.h"

#include <cmath>
#include <limits>

#include "common/check.h"

namespace roamlab::frontend {

Eigen::RowVectorXd LaserScanRow(const ScanGeometry& geometry, const std::vector<double>& ranges) {
  ROAMLAB_CHECK(static_cast<int>(ranges.size()) == geometry.beams,
                "a scan of " << ranges.size() << " ranges for " << geometry.beams << " beams");
  Eigen::RowVectorXd row(static_cast<Eigen::Index>(ranges.size()) + 4);
  row[0] = geometry.first_angle_rad;
  row[1] = geometry.increment_rad;
  row[2] = geometry.min_range_m;
  row[3] = geometry.max_range_m;
  for (std::size_t k = 0; k < ranges.size(); ++k) {
    row[static_cast<Eigen::Index>(k) + 4] = std::isfinite(ranges[k]) ? ranges[k] : 0.0;
  }
  return row;
}

ScanGeometry LaserScanGeometry(const recording::Stream& stream, Eigen::Index row) {
  ScanGeometry geometry;
  geometry.beams = static_cast<int>(stream.values.cols()) - 4;
  geometry.first_angle_rad = stream.values(row, 0);
  geometry.increment_rad = stream.values(row, 1);
  geometry.min_range_m = stream.values(row, 2);
  geometry.max_range_m = stream.values(row, 3);
  return geometry;
}

std::vector<double> LaserScanRanges(const recording::Stream& stream, Eigen::Index row) {
  const ScanGeometry geometry = LaserScanGeometry(stream, row);
  std::vector<double> ranges(static_cast<std::size_t>(geometry.beams));
  for (int k = 0; k < geometry.beams; ++k) {
    const double r = stream.values(row, k + 4);
    const bool ret = r != 0.0 && r >= geometry.min_range_m && r <= geometry.max_range_m;
    ranges[static_cast<std::size_t>(k)] = ret ? r : std::numeric_limits<double>::quiet_NaN();
  }
  return ranges;
}

}  // namespace roamlab::frontend
