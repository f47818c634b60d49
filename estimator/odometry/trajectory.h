// Trajectory prediction from an odometry model and the seed's error metrics (seed 001, Section IV-A).
//
// A learned or parametric model predicts the displacement of each key interval from its wheel rotations; composing
// them from the reference's first key pose gives the odometry trajectory x^_k = x^_(k-1) (+) f(delta_(k-1)k).
//   RPE (eq. 10): e^r_k = (-)((-)x^_k (+) x^_(k+1)) (+) ((-)x_k (+) x_(k+1)), RMS of |trans(e^r_k)| over k = 1..n-1;
//   ATE (eq. 11): e^a_k = (-)x^_k (+) x_k, RMS of |trans(e^a_k)| over k = 1..n.
// Their rotational counterparts: the RMS of |rot(e^r_k)| and |rot(e^a_k)| (the heading error, wrapped to [-pi, pi]).
// No alignment beyond the common first pose: the odometry is dead reckoning from where the reference starts.
#pragma once

#include <functional>
#include <vector>

#include <Eigen/Core>

#include "estimator/odometry/se2.h"

namespace roamlab::estimator::odometry {

using DisplacementFunction = std::function<Pose2(const Eigen::VectorXd& delta)>;

// start, then start (+) f(delta row 0) (+) ...: delta.rows() + 1 poses.
std::vector<Pose2> PredictTrajectory(const DisplacementFunction& f, const Eigen::MatrixXd& delta, const Pose2& start);

// Per-pose translation errors |trans(e^a_k)| (eq. 11) and per-step |trans(e^r_k)| (eq. 10) [m]; same-length inputs.
std::vector<double> AbsoluteErrors(const std::vector<Pose2>& estimate, const std::vector<Pose2>& reference);
std::vector<double> RelativeErrors(const std::vector<Pose2>& estimate, const std::vector<Pose2>& reference);
// The same errors' rotation |rot(e^a_k)| and |rot(e^r_k)| [rad].
std::vector<double> AbsoluteHeadingErrors(const std::vector<Pose2>& estimate, const std::vector<Pose2>& reference);
std::vector<double> RelativeHeadingErrors(const std::vector<Pose2>& estimate, const std::vector<Pose2>& reference);

// Root mean square; 0 for an empty list.
double RootMeanSquare(const std::vector<double>& errors);

}  // namespace roamlab::estimator::odometry
