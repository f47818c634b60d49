// Topic bookkeeping shared by the rosbag2 and MCAP readers: ROS 2 type names in the Bag's form and one BagTopic per
// topic name however many channels, tables or files name it. Private to the importers.
#pragma once

#include <string>
#include <string_view>

#include "importers/internal/bag.h"

namespace roamlab::importers::internal {

// "sensor_msgs/msg/Imu" -> "sensor_msgs/Imu"; a name without the "/msg/" part ("sensor_msgs/Imu") is kept.
inline std::string TypeWithoutMsg(std::string_view type) {
  const std::size_t slash = type.find('/');
  if (slash != std::string_view::npos && type.substr(slash, 5) == "/msg/")
    return std::string(type.substr(0, slash)) + std::string(type.substr(slash + 4));
  return std::string(type);
}

// Index of the topic `name` in `bag`, added when new. A topic already present with another type or encoding is a
// problem (returned as text, without the path); "" when fine.
inline std::string FindOrAddTopic(const BagTopic& topic, Bag* bag, std::size_t* index) {
  for (std::size_t i = 0; i < bag->topics.size(); ++i) {
    const BagTopic& known = bag->topics[i];
    if (known.name != topic.name) continue;
    if (known.type != topic.type || known.encoding != topic.encoding)
      return "topic " + topic.name + " appears with two types or encodings ('" + known.type + "' and '" + topic.type +
             "')";
    *index = i;
    return "";
  }
  bag->topics.push_back(topic);
  *index = bag->topics.size() - 1;
  return "";
}

}  // namespace roamlab::importers::internal
