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
// increments over consecutive windows instead, whitened by the two recorded samples' noise; streams named in its
// left_out are not compared.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/time.h"
#include "estimator/calibration.h"
#include "gap/resimulate.h"
#include "gap/twin.h"
#include "recording/recording.h"

namespace roamlab::gap::internal {

// The stated noise of each compared column (positive), or empty when the stream states none.
std::vector<double> ColumnSigmas(const recording::StreamInfo& info);

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
  // its stamp); a pose's two components along and across the recorded displacement, the across one whitened with
  // heading_sigma too (gap/twin.h TwinResidualOptions). Empty: sample by sample.
  std::vector<std::size_t> starts;
  double heading_sigma = 0.0;  // rad: a pose stream's stated orientation_rad
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
