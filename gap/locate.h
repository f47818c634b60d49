// Locating a reality gap (the diagnosis's step 2, gap/diagnose.h): where the whitened residuals of a calibrated
// estimate stop looking like N(0, 1) noise. Per stream and residual component: the chi-square per degree of freedom
// against the level expected of the nominal model (1, or what the nominal simulation gives: MuJoCo's suspension and
// tire compliance already make some streams inconsistent); when: sliding-window statistics flag the intervals whose
// chi-square exceeds that level beyond its 99.9 % quantile; under which conditions: the correlation of the residual
// with the motion (speed, accelerations, yaw rate, slope, steering, world-frame velocity), each at the lag within
// +-kMaxLagS that correlates best (a time offset shows as a lagged copy of the motion).
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/time.h"
#include "estimator/calibration.h"
#include "recording/recording.h"
#include "recording/trajectory.h"

namespace roamlab::gap {

// Motion conditions at the poses of a calibrated trajectory: one column per name, one row per pose.
struct Conditions {
  std::vector<std::string> names;
  std::vector<Time> t;
  Eigen::MatrixXd values;
  // The value of condition `c` at time `t` (nearest pose; clamped at the ends).
  double At(int c, Time t) const;
};

// Computes, by finite differences over the poses (central, smoothed over about 0.1 s): speed_mps (forward, O),
// accel_long_mps2, accel_lat_mps2 (v_x omega_z), yaw_rate_radps, yaw_accel_radps2, slope_rad (pitch of O),
// v_east_mps, v_north_mps, and steering_rad (the recording's steering stream, when there is one).
Conditions ComputeConditions(const Trajectory& trajectory, const recording::Recording& recording);

// Totals of one stream's whitened residuals (active measurements only).
struct StreamFit {
  int measurements = 0;
  int dof = 0;        // scalar residuals
  double chi2 = 0.0;  // sum of squared whitened residuals
  double chi2_per_dof = 0.0;
  double rms = 0.0;  // sqrt(chi2_per_dof): whitened RMS
  // The systematic part: the RMS over components and 1 s windows (kSystematicWindowS, from the stream's first
  // residual) of each window's mean whitened residual. White noise averages out of it (by sqrt of the samples in a
  // window: 10x at 100 Hz), a bias or a slowly varying mismatch does not; it is what a residual plot shows as a trend.
  double rms_1s = 0.0;
};
inline constexpr double kSystematicWindowS = 1.0;
std::map<std::string, StreamFit> StreamFits(const std::vector<estimator::MeasurementResidual>& residuals);

// The systematic part of one stream's whitened residuals (StreamFit::rms_1s): each residual added to the mean of its
// kSystematicWindowS window, counted from the first one added; a residual of another size than its window's first is
// left out.
class WindowMeans {
 public:
  void Add(Time t, const Eigen::VectorXd& whitened);
  // RMS over windows and components of the windows' means (0 before anything was added).
  double Rms() const;

 private:
  std::optional<Time> first_;
  std::map<long, std::pair<Eigen::VectorXd, int>> windows_;  // window index -> (sum, count)
};

struct Correlate {
  std::string condition;
  double rho = 0.0;  // Pearson correlation of the residual with the condition at t + lag_s
  double lag_s = 0.0;
};

struct LocatedComponent {
  std::string stream;
  int component = 0;
  int count = 0;
  double chi2_per_dof = 0.0;
  double expected_chi2_per_dof = 1.0;  // the nominal level it was compared with
  bool inconsistent = false;           // above the level by more than kInconsistencyRatio and its quantile
  std::vector<std::pair<double, double>> intervals;  // [t0, t1] in seconds where the windows exceed the level
  std::vector<Correlate> correlates;                 // the strongest first, at most three
};

struct LocateOptions {
  double window_s = 2.0;
  double max_lag_s = 0.3;
  double lag_step_s = 0.02;
  // A component is inconsistent when chi2_per_dof > ratio * expected and above expected's 99.9 % chi-square quantile.
  double inconsistency_ratio = 1.3;
};

// expected: per "stream/component" the nominal chi2_per_dof (missing keys: 1).
std::vector<LocatedComponent> Locate(const std::vector<estimator::MeasurementResidual>& residuals,
                                     const Conditions& conditions, const std::map<std::string, double>& expected,
                                     const LocateOptions& options = {});

// "stream/component", the key of `expected`.
std::string ComponentKey(const std::string& stream, int component);
// Per component chi2_per_dof, keyed as above.
std::map<std::string, double> ComponentLevels(const std::vector<estimator::MeasurementResidual>& residuals);

// One component's chi-square per dof over `count` scalar residuals.
struct ComponentLevel {
  double chi2_per_dof = 0.0;
  int count = 0;
};
// Per component, keyed as above (active measurements only).
std::map<std::string, ComponentLevel> ComponentStatistics(const std::vector<estimator::MeasurementResidual>& residuals);
// The p-quantile of the chi-square of `count` residuals whose chi2_per_dof is expected at `expected_chi2_per_dof`.
// Above 1 (a model mismatch the nominal model already shows): that level times chi2(count). Below 1 the fit absorbs
// part of the noise (the poses follow the IMU: its components sit at 0.01-0.4): the residuals are the noise projected
// away from what the fit moves, whose chi-square has mean expected * count and a variance between 2 expected^2 count
// (the projection's eigenvalues all equal) and 2 expected count (each 0 or 1); the quantile takes the wider,
// chi2(expected * count). Between noise seeds of one nominal drive, a low level (the gyroscope's world x and y at
// 0.01-0.04) spreads as chi2(expected * count) predicts, far more than chi2(count) scaled: with the latter, a
// nominal drive's component would be "inconsistent" with no effect hidden.
double LevelQuantile(double p, double expected_chi2_per_dof, int count);
// Locate's rule: chi2_per_dof above `ratio` times the expected level and above the level's 99.9 % quantile
// (LevelQuantile) for `count` residuals.
bool Inconsistent(const ComponentLevel& level, double expected_chi2_per_dof, double ratio);
// Whether the chi-square above the expected level, (chi2_per_dof - expected) count, exceeds what `count` residuals
// of the stated noise (chi2(count)) exceed their mean by with 0.1 % probability: an excess the stated noise model can
// tell from noise, whatever the level (a component far below 1, e.g. a gyroscope axis a planar drive hardly moves,
// can double its level by a few hundredths of a chi-square unit).
bool SignificantExcess(const ComponentLevel& level, double expected_chi2_per_dof);

}  // namespace roamlab::gap
