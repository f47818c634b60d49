// Private helpers of the recording module: the checks of a laser_scan stream (recording.h, the stream type table).
#pragma once

#include <string>
#include <vector>

#include "recording/recording.h"

namespace roamlab::recording::internal {

// Problem with the columns of a laser_scan stream (LaserScanColumns of at least one beam), or "" when they are fine.
std::string LaserScanColumnsProblem(const std::vector<std::string>& columns);

// Problem with the geometry columns of a laser_scan stream's values as "<line>: <problem>" for the first bad row, or
// "" when fine (or when the stream is not a laser_scan). Row i is on line i + 2 of its file (after the header).
std::string LaserScanRowsProblem(const Stream& stream);

}  // namespace roamlab::recording::internal
