// Scans as rows of a laser_scan stream (recording.h): the geometry columns angle_min_rad, angle_increment_rad,
// range_min_m, range_max_m followed by one range per beam. A beam without a return is written as 0 and read back as
// NaN, the scan matcher's "no return", as is every range outside [range_min_m, range_max_m].
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "frontend/scan_matcher.h"
#include "recording/recording.h"

namespace roamlab::frontend {

// The row of one scan (ranges.size() == geometry.beams; a range that is not finite is no return).
Eigen::RowVectorXd LaserScanRow(const ScanGeometry& geometry, const std::vector<double>& ranges);

// The geometry and the ranges of row `row` of a laser_scan stream as read by recording::ReadRecording.
ScanGeometry LaserScanGeometry(const recording::Stream& stream, Eigen::Index row);
std::vector<double> LaserScanRanges(const recording::Stream& stream, Eigen::Index row);

}  // namespace roamlab::frontend
