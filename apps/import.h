// `roamlab import optiodom RUN.csv --out REC [--metadata FILE]`: converts a real OptiOdom run (recording/
// import_optiodom.h) into a recording directory.
// `roamlab import rosbag BAG (--out REC | --list) [--topic TOPIC=STREAM ...] [--imu-mounting W X Y Z]
// [--platform KIND] [--geometry KEY=VALUE ...] [--joints NAME ...] [--joint-velocities] [--wheels-from-odometry
// [--odometry-topic TOPIC] [--odometry-wheel-separation M]]`: converts the supported topics of a ROS 1 bag, a rosbag2
// directory or an MCAP file
// (importers/rosbag.h) into a recording, printing each imported topic with its message type and every check's
// warning; --list prints the bag's topics (type, count, rate, span) and imports nothing. The IMU mounting and the
// platform's nominal geometry, which a bag does not hold, come from the options and go into recording.yaml.
// `roamlab import csv FILE... --map MAP.yaml --out REC`: CSV/TSV files with a column mapping (importers/csv.h,
// docs/import-csv.md); prints rows read per file, samples per stream and every skipped or collapsed row count.
// All return the exit code: 0, 2 with one line "roamlab import: <file>[:<line>]: <problem>" on bad input, 1 when the
// recording cannot be written.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace roamlab::apps {

struct ImportOptiOdomArgs {
  std::string run_csv;
  std::string metadata;  // "" = <set>_metadata.csv next to the run
  std::string out;
  bool quiet = false;
};
int RunImportOptiOdom(const ImportOptiOdomArgs& args);

struct ImportRosbagArgs {
  std::string bag;  // a ROS 1 .bag, a rosbag2 directory or an .mcap
  std::string out;
  bool list = false;                      // print the topics, import nothing
  std::vector<std::string> topics;        // "topic=stream"; empty = every supported topic
  std::vector<std::string> joints;        // JointState joints (empty = the first message's)
  bool joint_velocities = false;          // JointState velocities instead of positions
  std::string odometry_topic;             // the wheels' odometry topic when there are several
  std::vector<double> imu_mounting_wxyz;  // q_body_imu; empty = identity (no mounting written)
  std::string platform_kind = "unknown";
  std::vector<std::string> geometry;  // "key=value", e.g. "baseline_m=0.555"
  bool wheels_from_odometry = false;  // also write the `wheels` stream (importers/rosbag.h)
  bool quiet = false;
  // The wheel separation the odometry's controller divides by, for the wheels (importers/rosbag.h)
  std::optional<double> odometry_wheel_separation_m;
};
int RunImportRosbag(const ImportRosbagArgs& args);

struct ImportCsvArgs {
  std::vector<std::string> files;
  std::string map;
  std::string out;
  bool quiet = false;
};
int RunImportCsv(const ImportCsvArgs& args);

}  // namespace roamlab::apps
