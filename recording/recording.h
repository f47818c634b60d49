// The recording directory: one format for simulated and real data.
//
//   REC/recording.yaml     format version, platform, origin (when GPS is present), one entry per stream, provenance
//   REC/<stream>.csv       header row "t,<columns...>", first column time in seconds with nine fractional digits
//   REC/ground_truth.tum   optional: "t x y z qx qy qz qw" of the odometric frame O in the world frame W
//   REC/truth.yaml         simulated recordings only: true calibration and hidden effects (see truth.h). The reader in
//                          this header never opens it; only evaluation does, through ReadTruth.
//
// Values are held in the canonical unit of each column (SI: m, rad, s; magnetometer in the unit the stream names).
// The reader converts declared units (deg, deg/s, g, ticks) to the canonical ones; the writer writes canonical units.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/status.h"
#include "common/time.h"
#include "recording/trajectory.h"

namespace roamlab::recording {

inline constexpr int kFormatVersion = 1;

// Stream types and their CSV columns (after "t"), in canonical units:
//   imu              wx wy wz [rad/s] ax ay az [m/s^2]    specific force: at rest the up axis reads +9.81
//   gyroscope        wx wy wz [rad/s]
//   accelerometer    ax ay az [m/s^2]
//   magnetometer     mx my mz [units: normalized | uT | nT | gauss, kept as given]
//   gps              latitude longitude [deg] altitude [m, above the ellipsoid], optionally followed by the 6
//                    CovarianceColumns(): the upper triangle of the fix's 3x3 ENU covariance, row by row (cov_e_e,
//                    cov_e_n, cov_e_u, cov_n_n, cov_n_u, cov_u_u) [m^2] (a ROS NavSatFix's position_covariance)
//   position         x y z [m] absolute position of the sensor in W (SLAM, motion capture)
//   pose             x y z [m] qx qy qz qw: absolute pose of the sensor in W
//   wheel_encoders   one column per wheel, named in the stream entry; [rad] cumulative angle, [rad/s] angular speed
//                    or [m/s] rim speed with the nominal radius (units: rad | rad/s | m/s | ticks, ticks -> rad)
//   steering         angle [rad]
//   odometry, visual_odometry, scan_matching
//                    vx vy vz [m/s] wx wy wz [rad/s]: linear and angular velocity of the sensor, in the sensor frame,
//                    optionally followed by the 21 CovarianceColumns(): the upper triangle of the 6x6 covariance of
//                    [vx vy vz wx wy wz], row by row (cov_vx_vx, cov_vx_vy, ..., cov_vx_wz, cov_vy_vy, ..., cov_wz_wz)
//                    [(m/s)^2, m/s rad/s, (rad/s)^2]; the reader refuses a negative diagonal entry
//   camera           frame: image file name relative to the recording directory
// Camera intrinsics (camera and visual_odometry streams): the attributes width_px, height_px, fx_px, fy_px, cx_px,
// cy_px, all six or none: the pinhole model u = fx x / z + cx, v = fy y / z + cy in OpenCV's pixel coordinates (the
// centre of the top-left pixel is (0, 0)) for a point (x, y, z) in the camera frame (x right, y down, z forward).
// Sizes are positive integers, focal lengths positive, the principal point inside the image. Other attributes are free;
// the visual odometry front end reads its floor reference from a camera stream's (frontend/visual_odometry_stream.h).
//   inputs           free columns named in the stream entry (control commands)
//   laser_scan       angle_min_rad angle_increment_rad range_min_m range_max_m range_0 ... range_<N-1> [rad, m]: one
//                    raw planar scan per row; beam k points at angle_min_rad + k angle_increment_rad in the sensor
//                    frame (x forward, angles counter-clockwise); a range outside [range_min_m, range_max_m] (the
//                    simulator writes 0) is no return. The columns are named in the stream entry (LaserScanColumns);
//                    the reader refuses a row with angle_increment_rad = 0, range_min_m < 0 or range_max_m <=
//                    range_min_m. units: rad,m (the only accepted value).
enum class StreamType {
  kImu,
  kGyroscope,
  kAccelerometer,
  kMagnetometer,
  kGps,
  kPosition,
  kPose,
  kWheelEncoders,
  kSteering,
  kOdometry,
  kVisualOdometry,
  kScanMatching,
  kCamera,
  kInputs,
  kLaserScan,
};

// "imu", "gyroscope", ..., as written in recording.yaml; ParseStreamType is its inverse (nullopt for unknown names).
const char* StreamTypeName(StreamType type);
std::optional<StreamType> ParseStreamType(const std::string& name);

// The CSV columns (after "t") that a type fixes, in the table above; empty for wheel_encoders, inputs and laser_scan,
// whose columns come from the stream entry.
const std::vector<std::string>& FixedColumns(StreamType type);
// The covariance columns that may follow the fixed columns of a velocity type or gps (table above); empty for the other
// types.
// A stream carries them when its info.columns are FixedColumns() followed by these.
const std::vector<std::string>& CovarianceColumns(StreamType type);

// The columns (after "t") of a laser_scan stream of `beams` beams: the four geometry columns, then range_0 ...
// range_<beams - 1>.
std::vector<std::string> LaserScanColumns(int beams);

// Nominal mounting of a sensor frame S in the odometric frame O.
struct Mounting {
  Eigen::Vector3d p_body_sensor = Eigen::Vector3d::Zero();            // [m], lever arm S^(O)
  Eigen::Quaterniond q_body_sensor = Eigen::Quaterniond::Identity();  // rotates S coordinates into O
};

struct StreamInfo {
  std::string name;  // unique; the CSV file is <name>.csv
  StreamType type = StreamType::kInputs;
  double rate_hz = 0.0;              // nominal rate
  std::vector<std::string> columns;  // after "t"; fixed by the type except wheel_encoders and inputs (and the
                                     // optional covariance columns of the velocity types and gps)
  std::string units;                 // after reading: the canonical unit of the type (table above; magnetometer,
                                     // camera and inputs keep what was declared); empty = canonical
  std::optional<Mounting> mounting;
  std::map<std::string, double> noise;       // nominal noise, keys carry units, e.g. "sigma_m", "sigma_radps"
  std::map<std::string, double> attributes;  // type-specific scalars, e.g. "ticks_per_revolution", "fx_px"
};

// A stream as read is strictly increasing in time. A row identical to the one before it in the file (the same stamp
// and values: a message delivered twice) is dropped by ReadRecording and counted in duplicate_rows_dropped; a row
// that repeats a stamp with other values is an error. A stream built in memory may hold such identical rows (the
// simulator's `duplicates` fault); WriteRecording writes them as they are.
struct Stream {
  StreamInfo info;
  std::vector<Time> t;                      // strictly increasing (but for identical rows, see above)
  Eigen::MatrixXd values;                   // rows = samples, columns = info.columns, canonical units
  std::vector<std::string> text;            // camera only: one file name per row
  std::int64_t duplicate_rows_dropped = 0;  // ReadRecording: rows identical to the previous one, not kept
};

struct Platform {
  std::string kind;                        // "ackermann", "differential_drive", "omni3", "mecanum", "skid_steer", ...
  std::map<std::string, double> geometry;  // nominal geometry, keys with units: "wheelbase_m", "track_m", ...
};

struct GeodeticOrigin {
  double latitude_deg = 0.0;
  double longitude_deg = 0.0;
  double altitude_m = 0.0;
};

struct Provenance {
  std::string source;                 // "simulated" or "imported"
  std::string scenario;               // scenario file, when simulated
  std::optional<std::uint64_t> seed;  // when simulated
  std::string description;            // free text: importer and original file, ...
};

struct Recording {
  int format_version = kFormatVersion;
  Platform platform;
  std::optional<GeodeticOrigin> origin;  // required when a gps stream is present
  std::vector<Stream> streams;
  Provenance provenance;
  std::optional<Trajectory> ground_truth;

  const Stream* Find(const std::string& name) const;
};

struct ReadOptions {
  // Streams that must be present (by name); a missing one is an error naming the stream.
  std::vector<std::string> required_streams;
  // Skip loading ground_truth.tum (the estimator does not need it).
  bool load_ground_truth = true;
};

// Reads and validates REC. Errors name the file, the line (and column or key) and the problem: unknown or missing
// keys, unknown stream type, unknown units, wrong column count or header, non-numeric cells, NaN/Inf, timestamps that
// go backwards or repeat with other values (an identical repeated row is dropped and counted, see Stream), missing
// required streams, missing files, a gps stream without origin. Never opens truth.yaml.
Result<Recording> ReadRecording(const std::string& directory, const ReadOptions& options = {});

// Writes REC (creating the directory). Deterministic: the same Recording gives byte-identical files. Values are
// printed with 17 significant digits, time with nine fractional digits. Does not write truth.yaml (see truth.h).
Status WriteRecording(const Recording& recording, const std::string& directory);

}  // namespace roamlab::recording
