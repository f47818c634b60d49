// Test and benchmark helper: ROS messages serialized by hand, in ROS 1 (packed little-endian, u32-length strings)
// or CDR (a 4-byte encapsulation header, then each primitive aligned to its size from the byte after it; strings
// count a trailing NUL), written from the formats' documentation rather than from the reader under test.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

namespace roamlab::importers::testing {

enum class Wire { kRos1, kCdrLittle, kCdrBig };

class MessageWriter {
 public:
  explicit MessageWriter(Wire wire) : wire_(wire) {
    if (wire == Wire::kCdrLittle) bytes_ = std::string("\x00\x01\x00\x00", 4);
    if (wire == Wire::kCdrBig) bytes_ = std::string("\x00\x00\x00\x00", 4);
  }
  bool cdr() const { return wire_ != Wire::kRos1; }
  const std::string& bytes() const { return bytes_; }

  template <typename T>
  MessageWriter& Put(T value) {
    if (cdr()) {
      while ((bytes_.size() - 4) % sizeof(T) != 0) bytes_ += '\0';
    }
    char raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    if (wire_ == Wire::kCdrBig) std::reverse(raw, raw + sizeof(T));
    bytes_.append(raw, sizeof(T));
    return *this;
  }
  MessageWriter& Doubles(const std::vector<double>& values) {
    for (double v : values) Put(v);
    return *this;
  }
  MessageWriter& Count(std::size_t n) { return Put(static_cast<std::uint32_t>(n)); }
  MessageWriter& String(const std::string& s) {
    Count(s.size() + (cdr() ? 1 : 0));
    bytes_ += s;
    if (cdr()) bytes_ += '\0';
    return *this;
  }
  MessageWriter& Raw(const std::string& s) {
    bytes_ += s;
    return *this;
  }
  // std_msgs/Header: ROS 1 seq, sec, nsec, frame_id; ROS 2 int32 sec, uint32 nanosec, frame_id.
  MessageWriter& Header(std::int32_t sec, std::uint32_t nsec, const std::string& frame) {
    if (!cdr()) Put(std::uint32_t{7});
    Put(sec).Put(nsec);
    return String(frame);
  }

 private:
  Wire wire_;
  std::string bytes_;
};

// The messages of the tests, each with distinct values the decoders must return.
// An IMU sample: angular velocity `w_xyz` [rad/s], linear acceleration `a_xyz` [m/s^2], gyro sigma 0.02 rad/s, accel
// sigma 0.1 m/s^2, an identity orientation without covariance.
inline std::string ImuMessage(Wire wire, std::int32_t sec, std::uint32_t nsec, const std::vector<double>& w_xyz,
                              const std::vector<double>& a_xyz) {
  std::vector<double> cov_w(9, 0.0), cov_a(9, 0.0);
  cov_w[0] = cov_w[4] = cov_w[8] = 0.0004;
  cov_a[0] = cov_a[4] = cov_a[8] = 0.01;
  MessageWriter w(wire);
  w.Header(sec, nsec, "imu_link").Doubles({0, 0, 0, 1}).Doubles(std::vector<double>(9, 0.0));
  w.Doubles(w_xyz).Doubles(cov_w).Doubles(a_xyz).Doubles(cov_a);
  return w.bytes();
}
inline std::string ImuMessage(Wire wire, std::int32_t sec, std::uint32_t nsec, double wz) {
  return ImuMessage(wire, sec, nsec, {0.01, wz, -0.02}, {0.1, 9.81, 0.2});
}
inline std::string FixMessage(Wire wire, std::int32_t sec, std::uint32_t nsec, std::int8_t status, double lat) {
  std::vector<double> cov(9, 0.0);
  cov[0] = 0.64;
  cov[4] = 0.81;
  cov[8] = 2.0;
  cov[1] = cov[3] = 0.1;
  MessageWriter w(wire);
  w.Header(sec, nsec, "gps").Put(status).Put(std::uint16_t{1}).Doubles({lat, 7.5, 100.0}).Doubles(cov);
  w.Put(std::uint8_t{2});
  return w.bytes();
}
inline std::string MagneticFieldMessage(Wire wire, std::int32_t sec, std::uint32_t nsec, double x_t) {
  MessageWriter w(wire);
  w.Header(sec, nsec, "mag").Doubles({x_t, -2e-5, 4e-5}).Doubles(std::vector<double>(9, 1e-12));
  return w.bytes();
}
// Joints "left_wheel", "right_wheel", "arm": positions p + {0, 1, 2}, velocities v + {0, 1, 2}, no efforts.
inline std::string JointStateMessage(Wire wire, std::int32_t sec, std::uint32_t nsec, double p, double v) {
  MessageWriter w(wire);
  w.Header(sec, nsec, "").Count(3).String("left_wheel").String("right_wheel").String("arm");
  w.Count(3).Doubles({p, p + 1, p + 2}).Count(3).Doubles({v, v + 1, v + 2}).Count(0);
  return w.bytes();
}
// Three beams from -0.5 rad by 0.5 rad, range 0.1-10 m: ranges r, +inf (no return), r + 1; two intensities.
inline std::string LaserScanMessage(Wire wire, std::int32_t sec, std::uint32_t nsec, float r) {
  MessageWriter w(wire);
  w.Header(sec, nsec, "laser");
  for (float f : {-0.5f, 0.5f, 0.5f, 0.0f, 0.1f, 0.1f, 10.0f}) w.Put(f);
  w.Count(3).Put(r).Put(std::numeric_limits<float>::infinity()).Put(r + 1.0f).Count(2).Put(5.0f).Put(6.0f);
  return w.bytes();
}
// A 2 x 2 image with one padding byte per row (step = width * channels + 1); pixel bytes start at `first`.
inline std::string ImageMessage(Wire wire, std::int32_t sec, std::uint32_t nsec, const std::string& encoding,
                                char first) {
  const std::uint32_t channels = encoding == "mono8" ? 1 : 3, step = 2 * channels + 1;
  std::string data;
  for (std::uint32_t i = 0; i < 2 * step; ++i) data += static_cast<char>(first + static_cast<char>(i));
  MessageWriter w(wire);
  w.Header(sec, nsec, "camera").Put(std::uint32_t{2}).Put(std::uint32_t{2}).String(encoding);
  w.Put(std::uint8_t{0}).Put(step).Count(data.size()).Raw(data);
  return w.bytes();
}
inline std::string CompressedImageMessage(Wire wire, std::int32_t sec, std::uint32_t nsec, const std::string& data) {
  MessageWriter w(wire);
  w.Header(sec, nsec, "camera").String("jpeg").Count(data.size()).Raw(data);
  return w.bytes();
}
// Odometry with position (1, 2, 0), orientation (qx, qy, qz, qw), twist (vx, vy, 0, 0, 0, wz) and a twist covariance
// diagonal 0.001 (i + 1) with a vx-wz correlation 1e-5.
inline std::string OdometryMessage(Wire wire, std::int32_t sec, std::uint32_t nsec, const std::string& parent,
                                   const std::string& child, const std::vector<double>& q_xyzw, double vx, double vy,
                                   double wz) {
  std::vector<double> cov(36, 0.0);
  for (int i = 0; i < 6; ++i) cov[static_cast<std::size_t>(7 * i)] = 0.001 * (i + 1);
  cov[5] = cov[30] = 1e-5;
  MessageWriter w(wire);
  w.Header(sec, nsec, parent).String(child).Doubles({1, 2, 0}).Doubles(q_xyzw).Doubles(std::vector<double>(36, 0.0));
  w.Doubles({vx, vy, 0, 0, 0, wz}).Doubles(cov);
  return w.bytes();
}
inline std::string TwistStampedMessage(Wire wire, std::int32_t sec, std::uint32_t nsec, double vx, double wz) {
  MessageWriter w(wire);
  w.Header(sec, nsec, "base_link").Doubles({vx, 0, 0, 0, 0, wz});
  return w.bytes();
}
inline std::string PoseStampedMessage(Wire wire, std::int32_t sec, std::uint32_t nsec, double x) {
  MessageWriter w(wire);
  w.Header(sec, nsec, "map").Doubles({x, 2, 3, 0, 0, 0.6, 0.8});
  return w.bytes();
}
inline std::string PoseWithCovarianceMessage(Wire wire, std::int32_t sec, std::uint32_t nsec, double x) {
  std::vector<double> cov(36, 0.0);
  cov[0] = cov[7] = 0.25;  // sigma 0.5 m
  MessageWriter w(wire);
  w.Header(sec, nsec, "map").Doubles({x, 2, 3, 0, 0, 0.6, 0.8}).Doubles(cov);
  return w.bytes();
}

}  // namespace roamlab::importers::testing
