#include "estimator/odometry/trajectory.h"

#include <cmath>

#include "common/check.h"

namespace roamlab::estimator::odometry {

std::vector<Pose2> PredictTrajectory(const DisplacementFunction& f, const Eigen::MatrixXd& delta, const Pose2& start) {
  std::vector<Pose2> poses;
  poses.reserve(static_cast<std::size_t>(delta.rows()) + 1);
  poses.push_back(start);
  for (Eigen::Index k = 0; k < delta.rows(); ++k) {
    poses.push_back(Compose(poses.back(), f(delta.row(k).transpose())));
  }
  return poses;
}

namespace {

// e^a_k for every k.
std::vector<Pose2> AbsoluteErrorPoses(const std::vector<Pose2>& estimate, const std::vector<Pose2>& reference) {
  ROAMLAB_CHECK(estimate.size() == reference.size(), "AbsoluteErrors: sizes differ");
  std::vector<Pose2> errors;
  for (std::size_t k = 0; k < estimate.size(); ++k) errors.push_back(Compose(Inverse(estimate[k]), reference[k]));
  return errors;
}

// e^r_k for every step.
std::vector<Pose2> RelativeErrorPoses(const std::vector<Pose2>& estimate, const std::vector<Pose2>& reference) {
  ROAMLAB_CHECK(estimate.size() == reference.size(), "RelativeErrors: sizes differ");
  std::vector<Pose2> errors;
  for (std::size_t k = 0; k + 1 < estimate.size(); ++k) {
    const Pose2 step_estimate = Compose(Inverse(estimate[k]), estimate[k + 1]);
    const Pose2 step_reference = Compose(Inverse(reference[k]), reference[k + 1]);
    errors.push_back(Compose(Inverse(step_estimate), step_reference));
  }
  return errors;
}

std::vector<double> Translations(const std::vector<Pose2>& errors) {
  std::vector<double> out;
  for (const Pose2& e : errors) out.push_back(e.head<2>().norm());
  return out;
}

std::vector<double> Rotations(const std::vector<Pose2>& errors) {
  constexpr double kTwoPi = 6.28318530717958647692;
  std::vector<double> out;
  for (const Pose2& e : errors) out.push_back(std::abs(std::remainder(e[2], kTwoPi)));
  return out;
}

}  // namespace

std::vector<double> AbsoluteErrors(const std::vector<Pose2>& estimate, const std::vector<Pose2>& reference) {
  return Translations(AbsoluteErrorPoses(estimate, reference));
}

std::vector<double> RelativeErrors(const std::vector<Pose2>& estimate, const std::vector<Pose2>& reference) {
  return Translations(RelativeErrorPoses(estimate, reference));
}

std::vector<double> AbsoluteHeadingErrors(const std::vector<Pose2>& estimate, const std::vector<Pose2>& reference) {
  return Rotations(AbsoluteErrorPoses(estimate, reference));
}

std::vector<double> RelativeHeadingErrors(const std::vector<Pose2>& estimate, const std::vector<Pose2>& reference) {
  return Rotations(RelativeErrorPoses(estimate, reference));
}

double RootMeanSquare(const std::vector<double>& errors) {
  if (errors.empty()) return 0.0;
  double sum = 0.0;
  for (double e : errors) sum += e * e;
  return std::sqrt(sum / static_cast<double>(errors.size()));
}

}  // namespace roamlab::estimator::odometry
