#include "importers/rosbag.h"

#include <bzlib.h>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

namespace roamlab::importers {

using recording::GeodeticOrigin;
using recording::Mounting;
using recording::Platform;
using recording::Recording;
using recording::Stream;
using recording::StreamType;

namespace {

constexpr char kMagic[] = "#ROSBAG V2.0\n";
constexpr std::uint8_t kOpMessage = 0x02, kOpBagHeader = 0x03, kOpChunk = 0x05, kOpConnection = 0x07;

// Little-endian reads from a byte buffer with bounds checks; `ok()` turns false on the first overrun.
class Cursor {
 public:
  explicit Cursor(std::string_view data) : data_(data) {}
  bool ok() const { return ok_; }
  std::size_t position() const { return position_; }
  bool done() const { return position_ >= data_.size(); }
  std::string_view Bytes(std::size_t n) {
    if (!ok_ || n > data_.size() - position_) {
      ok_ = false;
      return {};
    }
    const std::string_view out = data_.substr(position_, n);
    position_ += n;
    return out;
  }
  template <typename T>
  T Read() {
    T value{};
    const std::string_view b = Bytes(sizeof(T));
    if (ok_) std::memcpy(&value, b.data(), sizeof(T));
    return value;
  }
  std::uint32_t U32() { return Read<std::uint32_t>(); }
  double F64() { return Read<double>(); }
  std::string_view String() { return Bytes(U32()); }  // ROS string: u32 length, bytes
  void Skip(std::size_t n) { Bytes(n); }

 private:
  std::string_view data_;
  std::size_t position_ = 0;
  bool ok_ = true;
};

struct Record {
  std::map<std::string, std::string_view> fields;
  std::string_view data;
  std::size_t offset = 0;  // of the record in its buffer
};

// Reads the next record; "" on success, else the problem.
std::string NextRecord(Cursor* in, Record* out) {
  out->offset = in->position();
  out->fields.clear();
  const std::string_view header = in->Bytes(in->U32());
  if (!in->ok()) return "truncated record header";
  Cursor h(header);
  while (!h.done()) {
    const std::string_view field = h.Bytes(h.U32());
    if (!h.ok()) return "malformed record header (a field runs past the header)";
    const std::size_t eq = field.find('=');
    if (eq == std::string_view::npos) return "malformed record header (a field without '=')";
    out->fields[std::string(field.substr(0, eq))] = field.substr(eq + 1);
  }
  out->data = in->Bytes(in->U32());
  if (!in->ok()) return "truncated record data";
  return "";
}

template <typename T>
bool Field(const Record& r, const std::string& name, T* value) {
  const auto it = r.fields.find(name);
  if (it == r.fields.end() || it->second.size() != sizeof(T)) return false;
  std::memcpy(value, it->second.data(), sizeof(T));
  return true;
}

// The value of a "name=value" field inside a connection record's data (the same layout as a header).
std::string ConnectionField(std::string_view data, const std::string& name) {
  Cursor c(data);
  while (!c.done()) {
    const std::string_view field = c.Bytes(c.U32());
    if (!c.ok()) break;
    const std::size_t eq = field.find('=');
    if (eq != std::string_view::npos && field.substr(0, eq) == name) return std::string(field.substr(eq + 1));
  }
  return "";
}

struct Message {
  std::uint32_t connection = 0;
  std::string_view data;
};

struct Connection {
  std::string topic;
  std::string type;
};

// The header stamp of a std_msgs/Header, then its frame id skipped.
Time ReadHeader(Cursor* c) {
  c->U32();  // seq
  const std::uint32_t sec = c->U32();
  const std::uint32_t nsec = c->U32();
  c->String();  // frame_id
  return Time::FromNanoseconds(static_cast<std::int64_t>(sec) * 1000000000 + nsec);
}

struct Sample {
  Time t;
  Eigen::VectorXd row;
};

// Decoded samples of one topic and the noise read off the messages' covariances.
struct TopicData {
  std::string type;
  std::vector<Sample> samples;
  std::vector<double> sigma_a, sigma_b;  // imu: gyro, accel; gps: horizontal
  int no_fix = 0;
};

// Decodes one message into `topic`; false when the message is shorter than its type.
bool Decode(std::string_view data, TopicData* topic) {
  Cursor c(data);
  const Time t = ReadHeader(&c);
  const auto read = [&](int n) {
    Eigen::VectorXd v(n);
    for (int i = 0; i < n; ++i) v[i] = c.F64();
    return v;
  };
  if (topic->type == "sensor_msgs/Imu") {
    read(4);  // orientation (not imported)
    read(9);  // its covariance
    const Eigen::VectorXd w = read(3);
    const Eigen::VectorXd cov_w = read(9);
    const Eigen::VectorXd a = read(3);
    const Eigen::VectorXd cov_a = read(9);
    if (!c.ok()) return false;
    Eigen::VectorXd row(6);
    row << w, a;
    topic->samples.push_back({t, row});
    if (cov_w[0] > 0.0) topic->sigma_a.push_back(std::sqrt(cov_w[0]));
    if (cov_a[0] > 0.0) topic->sigma_b.push_back(std::sqrt(cov_a[0]));
    return true;
  }
  if (topic->type == "nav_msgs/Odometry") {
    c.String();  // child_frame_id: the frame of the twist
    read(7);     // pose (not imported: the integral of the twist)
    read(36);
    const Eigen::VectorXd twist = read(6);
    const Eigen::VectorXd cov = read(36);
    if (!c.ok()) return false;
    Eigen::VectorXd row(27);
    row.head<6>() = twist;
    int k = 6;
    for (int i = 0; i < 6; ++i)
      for (int j = i; j < 6; ++j) row[k++] = cov[6 * i + j];
    topic->samples.push_back({t, row});
    return true;
  }
  // sensor_msgs/NavSatFix
  const auto status = c.Read<std::int8_t>();
  c.Read<std::uint16_t>();  // service
  const Eigen::VectorXd lla = read(3);
  const Eigen::VectorXd cov = read(9);
  c.Read<std::uint8_t>();  // position_covariance_type
  if (!c.ok()) return false;
  if (status < 0 || !lla.allFinite()) {
    ++topic->no_fix;
    return true;
  }
  Eigen::VectorXd row(9);
  row << lla, cov[0], cov[1], cov[2], cov[4], cov[5], cov[8];
  topic->samples.push_back({t, row});
  if (cov[0] > 0.0 && cov[4] > 0.0) topic->sigma_a.push_back(std::sqrt(0.5 * (cov[0] + cov[4])));
  return true;
}

double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

std::string StreamNameOf(const std::string& topic) {
  std::string name;
  for (char ch : topic) {
    if (std::isalnum(static_cast<unsigned char>(ch))) {
      name += ch;
    } else if (!name.empty() && name.back() != '_') {
      name += '_';
    }
  }
  while (!name.empty() && name.back() == '_') name.pop_back();
  return name.empty() ? "topic" : name;
}

// What the walk over the records collects.
struct BagContents {
  std::deque<std::string> unpacked;  // decompressed chunks (the messages point into them)
  std::map<std::uint32_t, Connection> connections;
  std::vector<Message> messages;
  bool saw_bag_header = false;
  int chunks = 0;
};

// Walks the records of `buffer` (the file after the magic line, or one chunk's data); "" or the problem. `base` is the
// buffer's offset in the file, for messages (inside a chunk: the chunk data's offset).
std::string WalkRecords(std::string_view buffer, std::size_t base, bool in_chunk, BagContents* bag) {
  Cursor in(buffer);
  Record r;
  const auto where = [&] {
    return " at byte " + std::to_string(base + r.offset) + (in_chunk ? " (inside the chunk at that offset)" : "");
  };
  while (!in.done()) {
    if (std::string problem = NextRecord(&in, &r); !problem.empty()) return problem + where();
    std::uint8_t op = 0;
    if (!Field(r, "op", &op)) return "record without op" + where();
    if (op == kOpBagHeader) {
      bag->saw_bag_header = true;
    } else if (op == kOpConnection) {
      std::uint32_t id = 0;
      if (!Field(r, "conn", &id)) return "connection record without conn" + where();
      bag->connections[id] = {std::string(r.fields["topic"]), ConnectionField(r.data, "type")};
    } else if (op == kOpMessage) {
      std::uint32_t id = 0;
      if (!Field(r, "conn", &id)) return "message record without conn" + where();
      bag->messages.push_back({id, r.data});
    } else if (op == kOpChunk && !in_chunk) {
      ++bag->chunks;
      std::uint32_t size = 0;
      const std::string compression(r.fields["compression"]);
      if (!Field(r, "size", &size)) return "chunk without size" + where();
      if (compression == "none") {
        bag->unpacked.emplace_back(r.data);
      } else if (compression == "bz2") {
        std::string out(size, '\0');
        unsigned int out_size = size;
        const int rc = BZ2_bzBuffToBuffDecompress(out.data(), &out_size, const_cast<char*>(r.data.data()),
                                                  static_cast<unsigned int>(r.data.size()), 0, 0);
        if (rc != BZ_OK || out_size != size)
          return "corrupt bz2 chunk (bzip2 error " + std::to_string(rc) + ")" + where();
        bag->unpacked.push_back(std::move(out));
      } else {
        return "chunk compressed with '" + compression + "', which this reader does not support (only none and bz2)" +
               where();
      }
      if (std::string problem = WalkRecords(bag->unpacked.back(), base + r.offset, true, bag); !problem.empty())
        return problem;
    }
  }
  return "";
}

}  // namespace

Result<Recording> ImportRosbag(const std::string& bag_path, const RosbagImportOptions& options,
                               RosbagImportReport* report) {
  RosbagImportReport local;
  RosbagImportReport& rep = report ? *report : local;
  const auto fail = [&](const std::string& problem) { return Status::Error(bag_path + ": " + problem); };

  // The whole file (bags of this kind are megabytes).
  std::ifstream file(bag_path, std::ios::binary);
  if (!file) return fail("cannot open the file");
  const std::string content((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  const std::size_t magic = sizeof(kMagic) - 1;
  if (content.size() < magic || content.compare(0, magic, kMagic) != 0) {
    if (content.compare(0, 9, "#ROSBAG V") == 0)
      return fail("unsupported bag version '" + content.substr(9, content.find('\n') - 9) + "' (only 2.0 is read)");
    return fail("not a ROS bag (no '#ROSBAG V2.0' line at the start)");
  }
  BagContents bag;
  if (std::string problem = WalkRecords(std::string_view(content).substr(magic), magic, false, &bag); !problem.empty())
    return fail(problem);
  if (!bag.saw_bag_header) return fail("no bag header record");
  rep.chunks = bag.chunks;

  // Decode the messages of the supported types, per topic.
  static const std::vector<std::string> kTypes = {"sensor_msgs/Imu", "nav_msgs/Odometry", "sensor_msgs/NavSatFix"};
  std::map<std::string, TopicData> topics;
  for (const Message& m : bag.messages) {
    const auto conn = bag.connections.find(m.connection);
    if (conn == bag.connections.end())
      return fail("a message refers to connection " + std::to_string(m.connection) + ", which the bag never defines");
    const Connection& c = conn->second;
    rep.types[c.topic] = c.type;
    ++rep.messages[c.topic];
    if (std::find(kTypes.begin(), kTypes.end(), c.type) == kTypes.end()) continue;
    TopicData& topic = topics[c.topic];
    topic.type = c.type;
    if (!Decode(m.data, &topic))
      return fail("message " + std::to_string(rep.messages[c.topic]) + " on " + c.topic + " is shorter than a " +
                  c.type);
  }
  if (topics.empty()) return fail("no sensor_msgs/Imu, nav_msgs/Odometry or sensor_msgs/NavSatFix topic");

  // One stream per topic, sorted by header stamp.
  Recording rec;
  rec.platform = options.platform;
  std::map<std::string, int> per_type;
  for (const auto& [name, topic] : topics) ++per_type[topic.type];
  for (auto& [name, topic] : topics) {
    Stream s;
    const bool imu = topic.type == "sensor_msgs/Imu";
    const bool odometry = topic.type == "nav_msgs/Odometry";
    s.info.type = imu ? StreamType::kImu : odometry ? StreamType::kOdometry : StreamType::kGps;
    s.info.name = per_type[topic.type] > 1 ? StreamNameOf(name) : imu ? "imu" : odometry ? "odometry" : "gps";
    s.info.columns = FixedColumns(s.info.type);
    const std::vector<std::string>& cov = CovarianceColumns(s.info.type);
    if (!imu) s.info.columns.insert(s.info.columns.end(), cov.begin(), cov.end());
    if (topic.no_fix > 0) rep.skipped[name + ": no fix"] = topic.no_fix;
    std::stable_sort(topic.samples.begin(), topic.samples.end(),
                     [](const Sample& a, const Sample& b) { return a.t < b.t; });
    std::vector<const Sample*> kept;
    for (const Sample& sample : topic.samples) {
      if (!kept.empty() && !(kept.back()->t < sample.t)) {
        ++rep.skipped[name + ": repeated header stamp"];
        continue;
      }
      kept.push_back(&sample);
    }
    if (kept.size() < 2) return fail(name + " has fewer than two usable messages");
    s.values.resize(static_cast<Eigen::Index>(kept.size()), static_cast<Eigen::Index>(s.info.columns.size()));
    for (std::size_t i = 0; i < kept.size(); ++i) {
      s.t.push_back(kept[i]->t);
      s.values.row(static_cast<Eigen::Index>(i)) = kept[i]->row.transpose();
    }
    s.info.rate_hz = static_cast<double>(kept.size() - 1) / SecondsBetween(s.t.front(), s.t.back());
    if (imu) {
      if (!topic.sigma_a.empty()) s.info.noise["gyro_sigma_radps"] = Median(topic.sigma_a);
      if (!topic.sigma_b.empty()) s.info.noise["accel_sigma_mps2"] = Median(topic.sigma_b);
      if (options.q_body_imu) s.info.mounting = Mounting{Eigen::Vector3d::Zero(), options.q_body_imu->normalized()};
    }
    if (!imu && !odometry) {
      if (!topic.sigma_a.empty()) s.info.noise["sigma_m"] = Median(topic.sigma_a);
      if (!rec.origin) rec.origin = GeodeticOrigin{s.values(0, 0), s.values(0, 1), s.values(0, 2)};
    }
    rec.streams.push_back(std::move(s));
  }
  // Wheel angles re-expressed from the odometry (header comment).
  if (options.wheels_from_odometry) {
    const auto r = rec.platform.geometry.find("wheel_radius_m");
    const auto b = rec.platform.geometry.find("baseline_m");
    if (r == rec.platform.geometry.end() || b == rec.platform.geometry.end() || !(r->second > 0.0) ||
        !(b->second > 0.0))
      return fail("wheels from odometry need positive wheel_radius_m and baseline_m in the platform geometry");
    const Stream* odo = nullptr;
    for (const Stream& s : rec.streams) {
      if (s.info.type != StreamType::kOdometry) continue;
      if (odo) return fail("wheels from odometry need exactly one nav_msgs/Odometry topic");
      odo = &s;
    }
    if (!odo) return fail("wheels from odometry need a nav_msgs/Odometry topic");
    Stream wheels;
    wheels.info.name = "wheels";
    wheels.info.type = StreamType::kWheelEncoders;
    wheels.info.columns = {"left", "right"};
    wheels.info.units = "rad";
    wheels.info.rate_hz = odo->info.rate_hz;
    wheels.info.attributes["derived_from_odometry"] = 1.0;
    wheels.t = odo->t;
    wheels.values = Eigen::MatrixXd::Zero(odo->values.rows(), 2);
    // Wheel rate of side `side` (-1 left, +1 right) at sample k [rad/s].
    const auto rate = [&](Eigen::Index k, double side) {
      return (odo->values(k, 0) + side * 0.5 * odo->values(k, 5) * b->second) / r->second;
    };
    for (Eigen::Index k = 1; k < odo->values.rows(); ++k) {
      const double dt = SecondsBetween(odo->t[static_cast<std::size_t>(k - 1)], odo->t[static_cast<std::size_t>(k)]);
      wheels.values(k, 0) = wheels.values(k - 1, 0) + 0.5 * dt * (rate(k - 1, -1.0) + rate(k, -1.0));
      wheels.values(k, 1) = wheels.values(k - 1, 1) + 0.5 * dt * (rate(k - 1, 1.0) + rate(k, 1.0));
    }
    rec.streams.push_back(std::move(wheels));
  }
  rec.provenance.source = "imported";
  std::ostringstream description;
  description << "ROS1 bag " << std::filesystem::path(bag_path).filename().string() << " (header stamps; topics:";
  for (const auto& [name, topic] : topics) description << " " << name;
  description << ")";
  rec.provenance.description = description.str();
  return rec;
}

}  // namespace roamlab::importers
