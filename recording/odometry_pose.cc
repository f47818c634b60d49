#include "recording/odometry_pose.h"

#include <string>

namespace roamlab::recording {

const Stream* PosedOdometry(const Recording& recording, const Stream& pose) {
  const std::string& name = pose.info.name;
  const std::string suffix = "_pose";
  if (pose.info.type != StreamType::kPose || name.size() <= suffix.size() ||
      name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
    return nullptr;
  const Stream* odometry = recording.Find(name.substr(0, name.size() - suffix.size()));
  return odometry && odometry->info.type == StreamType::kOdometry ? odometry : nullptr;
}

}  // namespace roamlab::recording
