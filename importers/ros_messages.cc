#include "importers/internal/ros_messages.h"

#include <algorithm>
#include <cstring>
#include <limits>

#include "importers/internal/byte_cursor.h"

namespace roamlab::importers::internal {
namespace {

constexpr std::size_t kCdrHeaderBytes = 4;

template <typename T>
T ByteSwapped(T value) {
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  std::reverse(bytes, bytes + sizeof(T));
  std::memcpy(&value, bytes, sizeof(T));
  return value;
}

// Reads the fields of one message in either serialization (header comment). The first problem is kept; every read
// after it returns zero, so a decoder reads all its fields and checks problem() once.
class MessageReader {
 public:
  MessageReader(std::string_view data, Encoding encoding) : cursor_(data), cdr_(encoding == Encoding::kCdr) {
    if (!cdr_) return;
    const std::string_view head = cursor_.Bytes(kCdrHeaderBytes);
    if (!cursor_.ok()) {
      Fail("shorter than the 4-byte CDR encapsulation header");
    } else if (head[0] != 0 || (head[1] != 0 && head[1] != 1)) {
      Fail("unsupported CDR encapsulation 0x" + Hex(head[0]) + Hex(head[1]) +
           " (only plain CDR, big- or little-endian, is read)");
    }
    big_endian_ = cursor_.ok() && head[1] == 0;
  }

  const std::string& problem() const { return problem_; }
  bool ok() const { return problem_.empty(); }
  // Bytes after the last field read; a CDR message may end in up to 3 bytes of padding.
  std::size_t unread() const { return cursor_.remaining(); }
  std::size_t allowed_padding() const { return cdr_ ? 3 : 0; }

  template <typename T>
  T Get() {
    Align(sizeof(T));
    const T value = cursor_.Read<T>();
    if (!cursor_.ok()) {
      Fail("the message ends before its last field");
      return T{};
    }
    return big_endian_ ? ByteSwapped(value) : value;
  }
  template <std::size_t N>
  void Doubles(std::array<double, N>* out) {
    for (double& d : *out) d = Get<double>();
  }
  std::string String() {
    const std::uint32_t n = Get<std::uint32_t>();
    if (n > cursor_.remaining()) {
      Fail("a string of " + std::to_string(n) + " bytes runs past the message");
      return "";
    }
    std::string_view s = cursor_.Bytes(n);
    if (cdr_ && !s.empty()) {
      // A CDR string counts its one terminating NUL: a length that does not end on it (or takes in padding after it)
      // was changed.
      if (s.back() != '\0' || s.substr(0, s.size() - 1).find('\0') != std::string_view::npos) {
        Fail("a string of " + std::to_string(n) + " bytes does not end with its one NUL terminator");
        return "";
      }
      s.remove_suffix(1);
    }
    return std::string(s);
  }
  // A sequence's count, refused when `count` elements of at least `min_bytes` each cannot fit in the rest.
  std::uint32_t Count(std::size_t min_bytes, const char* what) {
    const std::uint32_t n = Get<std::uint32_t>();
    if (!ok()) return 0;
    if (n > 0) Align(min_bytes);  // CDR pads before the first element
    if (static_cast<std::uint64_t>(n) * min_bytes > cursor_.remaining()) {
      Fail(std::string("a sequence of ") + std::to_string(n) + " " + what + " runs past the message");
      return 0;
    }
    return n;
  }
  template <typename T>
  std::vector<T> Sequence(const char* what) {
    std::vector<T> out(Count(sizeof(T), what));
    for (T& v : out) v = Get<T>();
    return out;
  }
  std::vector<std::string> Strings(const char* what) {
    std::vector<std::string> out(Count(4, what));
    for (std::string& s : out) s = String();
    return out;
  }
  std::string_view Bytes(const char* what) {
    const std::uint32_t n = Count(1, what);
    return cursor_.Bytes(n);
  }
  RosHeader Header() {
    RosHeader h;
    if (!cdr_) Get<std::uint32_t>();  // ROS 1 seq
    const std::int64_t sec = cdr_ ? Get<std::int32_t>() : static_cast<std::int64_t>(Get<std::uint32_t>());
    const std::int64_t nsec = Get<std::uint32_t>();
    h.stamp = Time::FromNanoseconds(sec * 1000000000 + nsec);
    h.frame_id = String();
    return h;
  }
  RosPose Pose() {
    RosPose p;
    Doubles(&p.position);
    Doubles(&p.orientation_xyzw);
    return p;
  }

 private:
  static std::string Hex(char c) {
    static const char digits[] = "0123456789abcdef";
    const auto u = static_cast<unsigned char>(c);
    return {digits[u >> 4], digits[u & 15]};
  }
  void Align(std::size_t n) {
    if (!cdr_ || !ok()) return;
    const std::size_t offset = cursor_.position() - kCdrHeaderBytes;
    cursor_.Skip((n - offset % n) % n);
  }
  void Fail(const std::string& problem) {
    if (problem_.empty()) problem_ = problem;
    cursor_.Seek(std::numeric_limits<std::size_t>::max());  // every later read returns zero
  }

  ByteCursor cursor_;
  bool cdr_ = false;
  bool big_endian_ = false;
  std::string problem_;
};

RosBody Imu(MessageReader* in) {
  RosImu m;
  in->Doubles(&m.orientation_xyzw);
  in->Doubles(&m.orientation_covariance);
  in->Doubles(&m.angular_velocity);
  in->Doubles(&m.angular_velocity_covariance);
  in->Doubles(&m.linear_acceleration);
  in->Doubles(&m.linear_acceleration_covariance);
  return m;
}
RosBody NavSatFix(MessageReader* in) {
  RosNavSatFix m;
  m.status = in->Get<std::int8_t>();
  m.service = in->Get<std::uint16_t>();
  m.latitude_deg = in->Get<double>();
  m.longitude_deg = in->Get<double>();
  m.altitude_m = in->Get<double>();
  in->Doubles(&m.position_covariance);
  m.position_covariance_type = in->Get<std::uint8_t>();
  return m;
}
RosBody MagneticField(MessageReader* in) {
  RosMagneticField m;
  in->Doubles(&m.field_t);
  in->Doubles(&m.covariance);
  return m;
}
RosBody JointState(MessageReader* in) {
  RosJointState m;
  m.name = in->Strings("names");
  m.position = in->Sequence<double>("positions");
  m.velocity = in->Sequence<double>("velocities");
  m.effort = in->Sequence<double>("efforts");
  return m;
}
RosBody LaserScan(MessageReader* in) {
  RosLaserScan m;
  for (float* f :
       {&m.angle_min, &m.angle_max, &m.angle_increment, &m.time_increment, &m.scan_time, &m.range_min, &m.range_max})
    *f = in->Get<float>();
  m.ranges = in->Sequence<float>("ranges");
  m.intensities = in->Sequence<float>("intensities");
  return m;
}
RosBody Image(MessageReader* in) {
  RosImage m;
  m.height = in->Get<std::uint32_t>();
  m.width = in->Get<std::uint32_t>();
  m.encoding = in->String();
  m.is_bigendian = in->Get<std::uint8_t>();
  m.step = in->Get<std::uint32_t>();
  m.data = in->Bytes("image bytes");
  return m;
}
RosBody CompressedImage(MessageReader* in) {
  RosCompressedImage m;
  m.format = in->String();
  m.data = in->Bytes("image bytes");
  return m;
}
RosBody Odometry(MessageReader* in) {
  RosOdometry m;
  m.child_frame_id = in->String();
  m.pose = in->Pose();
  in->Doubles(&m.pose_covariance);
  in->Doubles(&m.twist);
  in->Doubles(&m.twist_covariance);
  return m;
}
RosBody TwistStamped(MessageReader* in) {
  RosTwistStamped m;
  in->Doubles(&m.twist);
  return m;
}
RosBody PoseStamped(MessageReader* in) { return RosPoseStamped{in->Pose()}; }
RosBody PoseWithCovarianceStamped(MessageReader* in) {
  RosPoseWithCovarianceStamped m;
  m.pose = in->Pose();
  in->Doubles(&m.covariance);
  return m;
}

using Decoder = RosBody (*)(MessageReader*);
struct TypeEntry {
  const char* name;
  Decoder decode;
};
const std::vector<TypeEntry>& Types() {
  static const std::vector<TypeEntry> types = {
      {"sensor_msgs/Imu", Imu},
      {"sensor_msgs/NavSatFix", NavSatFix},
      {"sensor_msgs/MagneticField", MagneticField},
      {"sensor_msgs/JointState", JointState},
      {"sensor_msgs/LaserScan", LaserScan},
      {"sensor_msgs/Image", Image},
      {"sensor_msgs/CompressedImage", CompressedImage},
      {"nav_msgs/Odometry", Odometry},
      {"geometry_msgs/TwistStamped", TwistStamped},
      {"geometry_msgs/PoseStamped", PoseStamped},
      {"geometry_msgs/PoseWithCovarianceStamped", PoseWithCovarianceStamped},
  };
  return types;
}

}  // namespace

const std::vector<std::string>& SupportedRosTypes() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const TypeEntry& t : Types()) out.emplace_back(t.name);
    return out;
  }();
  return names;
}

bool IsSupportedRosType(const std::string& type) {
  const std::vector<std::string>& names = SupportedRosTypes();
  return std::find(names.begin(), names.end(), type) != names.end();
}

Result<RosMessage> DecodeRosMessage(const std::string& type, std::string_view data, Encoding encoding) {
  const auto entry = std::find_if(Types().begin(), Types().end(), [&](const TypeEntry& t) { return type == t.name; });
  if (entry == Types().end()) return Status::Error("message type '" + type + "' is not decoded");
  MessageReader in(data, encoding);
  RosMessage message;
  message.header = in.Header();
  message.body = entry->decode(&in);
  if (!in.ok()) return Status::Error(in.problem());
  // Bytes left after the last field: a length or count changed inside the message shifted every field after it.
  if (in.unread() > in.allowed_padding()) {
    return Status::Error(std::to_string(in.unread()) +
                         " bytes follow the message's last field (a length inside the message does not match it)");
  }
  return message;
}

}  // namespace roamlab::importers::internal
