// An importer writes the pose of a nav_msgs/Odometry topic `<name>` as a pose stream `<name>_pose` beside the
// odometry stream (importers/rosbag.h). That pose is dead-reckoned in the odometry's parent frame: not an absolute
// reference, so neither the nominal configuration nor a replay's start may take it for one.
#pragma once

#include "recording/recording.h"

namespace roamlab::recording {

// The odometry stream whose pose `pose` is (a pose stream named `<odometry>_pose` beside an odometry stream
// `<odometry>`), or null when `pose` is not such a stream.
const Stream* PosedOdometry(const Recording& recording, const Stream& pose);

}  // namespace roamlab::recording
