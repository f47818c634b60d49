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

std::vector<double> AbsoluteErrors(const std::vector<Pose2>& estimate, const std::vector<Pose2>& reference) {
  ROAMLAB_CHECK(estimate.size() == reference.size(), "AbsoluteErrors: sizes differ");
  std::vector<double> errors;
  for (std::size_t k = 0; k < estimate.size(); ++k) {
    errors.push_back(Compose(Inverse(estimate[k]), reference[k]).head<2>().norm());
  }
  return errors;
}

std::vector<double> RelativeErrors(const std::vector<Pose2>& estimate, const std::vector<Pose2>& reference) {
  ROAMLAB_CHECK(estimate.size() == reference.size(), "RelativeErrors: sizes differ");
  std::vector<double> errors;
  for (std::size_t k = 0; k + 1 < estimate.size(); ++k) {
    const Pose2 step_estimate = Compose(Inverse(estimate[k]), estimate[k + 1]);
    const Pose2 step_reference = Compose(Inverse(reference[k]), reference[k + 1]);
    errors.push_back(Compose(Inverse(step_estimate), step_reference).head<2>().norm());
  }
  return errors;
}

double RootMeanSquare(const std::vector<double>& errors) {
  if (errors.empty()) return 0.0;
  double sum = 0.0;
  for (double e : errors) sum += e * e;
  return std::sqrt(sum / static_cast<double>(errors.size()));
}

}  // namespace roamlab::estimator::odometry
