// Recorded (real) minus simulated (twin) residuals of a recording's streams, matched by stamp and whitened by the
// recording's stated noise: what the re-simulation (gap/resimulate.h) and the twin diagnosis (gap/twin.h) compare.
//
// A stream is compared when the recording states its noise (recording.yaml `noise`): the imu's gyro_sigma_radps and
// accel_sigma_mps2 (compared as two series, "gyroscope" and "accelerometer"), sigma_m of a gps fix per ENU axis and
// of a position stream's x y z, position_m (or sigma_m) of a pose stream's x y (not its height), sigma_mps and
// sigma_radps of the velocity streams, a wheel encoder's tick / sqrt(12) (cumulative angles in rad with
// ticks_per_revolution) or its one stated sigma, and the one stated sigma of the other single-noise streams (gyroscope,
// accelerometer, magnetometer, steering). A gps fix is compared in the real recording's ENU frame (its origin). A
// sample of the real recording is matched by its exact stamp; a twin without that stamp leaves the entry NaN.
// With TwinResidualOptions::increment_window_s (gap/twin.h), the pose, gps and position streams are compared by their
// increments over windows instead (a pose's as the drift measures it, the twin aligned over each window's start),
// whitened by the recorded samples' noise; streams named in its left_out are not compared.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/time.h"
#include "estimator/calibration.h"
#include "gap/resimulate.h"
#include "gap/twin.h"
#include "recording/recording.h"

namespace roamlab::gap::internal {

// An absolute stream's samples matched by stamp in the real recording and the twin (a gps fix in the real recording's
// ENU frame through `origin`).
struct Track {
  std::vector<double> t_s;
  std::vector<Eigen::Vector3d> real, twin;
  std::vector<Eigen::Quaterniond> q_real, q_twin;  // pose streams only
  // The alignment's weights, 1 / sigma^2 of the stated noise: a pose stream's headings weigh 0 when it states none.
  double position_weight = 1.0, heading_weight = 0.0;
};
Track Matched(const recording::Stream& r, const recording::Stream& s, Time from, Time to,
              const std::optional<recording::GeodeticOrigin>& origin);

double Yaw(const Eigen::Quaterniond& q);

// The planar rigid transform (yaw about the vertical, then translation) of the twin onto the real track that best fits
// samples [a, b] in least squares: positions weighted by position_weight, a pose stream's headings by heading_weight,
//   cost(yaw, p) = w_p sum |R t_i + p - r_i|^2 + w_h sum (yaw + psi_twin_i - psi_real_i)^2.
// For the best p (the centroids matched) the positions' cost is w_p rho (yaw - yaw_p)^2 to second order about their
// own best yaw yaw_p (rho the size of the centred tracks' cross-covariance), the headings' w_h n (yaw - d)^2 about the
// mean heading difference d: the yaw is their weighted mean, and w_p rho + w_h n is its information (1 / variance,
// from a pose stream's stated noise). Without heading weight, a real track that moves less than 0.1 m there gives no
// yaw: the translation at `a` alone (information 0).
struct PlanarFit {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Vector3d real_centroid = Eigen::Vector3d::Zero();  // of the real samples fitted
  double yaw_information = 0.0;                             // rad^-2
};
PlanarFit PlanarAlignment(const Track& k, std::size_t a, std::size_t b);

// The stated noise of each compared column (positive), or empty when the stream states none.
std::vector<double> ColumnSigmas(const recording::StreamInfo& info);

// A windowed increment is compared only when its samples span at least this share of the window.
constexpr double kShortestWindowShare = 0.9;

// One compared series: some columns of one stream of the real recording, over its samples in a time span.
struct Series {
  std::string name;    // the stream's name, or "gyroscope" / "accelerometer" for an imu's columns
  std::string stream;  // the recording's stream
  recording::StreamType type = recording::StreamType::kImu;
  int first_column = 0;
  std::vector<double> sigma;      // per component
  std::vector<std::size_t> rows;  // the real recording's rows compared
  std::vector<Time> t;            // their stamps
  Eigen::Index offset = 0;        // first entry in the residual vector
  // Windowed increments: entry i compares the increment from the real recording's row starts[i] to rows[i] (t[i]
  // its stamp). A gps fix's or position's per ENU axis, the windows consecutive. A pose's as the drift measures it
  // (gap/twin.h TwinResidualOptions): the windows overlapping, the twin aligned over rows starts[i]..align_ends[i],
  // each entry scaled by `weight`. Empty: sample by sample.
  std::vector<std::size_t> starts, align_ends;
  double weight = 1.0;
  int components() const { return static_cast<int>(sigma.size()); }
  Eigen::Index size() const { return static_cast<Eigen::Index>(rows.size()) * components(); }
};

// The series of `real` over [from, to] (stamps inclusive), in stream order, and the entries they take; the absolute
// streams as windowed increments when options.increment_window_s > 0, the streams in options.left_out left out.
struct Layout {
  std::vector<Series> series;
  std::vector<std::string> left_out;  // "stream: reason" for the streams not compared
  std::optional<recording::GeodeticOrigin> origin;
  Eigen::Index size = 0;
};
Layout MakeLayout(const recording::Recording& real, Time from, Time to, const TwinResidualOptions& options = {});

// Whitened real - twin at the layout's samples: entry offset + i * components + c for sample i, component c of a
// series; NaN where the twin has no sample at the stamp (or lacks the stream). `missing` (may be null) gets
// "stream: reason" for each series the twin lacks.
Eigen::VectorXd WhitenedResiduals(const Layout& layout, const recording::Recording& real,
                                  const recording::Recording& twin, std::vector<std::string>* missing = nullptr);

// Per series: RMS over the finite entries, per component, and of the 1 s means (SimulatedStreamFit).
std::map<std::string, SimulatedStreamFit> SeriesFits(const Layout& layout, const Eigen::VectorXd& whitened);

// The whitened residuals as Locate (gap/locate.h) takes them: one per series and sample (finite entries only).
std::vector<estimator::MeasurementResidual> MeasurementResiduals(const Layout& layout, const Eigen::VectorXd& whitened);

// The sum of squares of the finite entries and their number.
double SumOfSquares(const Eigen::VectorXd& whitened, int* count = nullptr);

}  // namespace roamlab::gap::internal
