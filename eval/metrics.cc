#include "eval/metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/check.h"

namespace roamlab::eval {
namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

// The error transform E_ij of one pair and its two magnitudes.
void AddPair(const Trajectory& estimate, const Trajectory& reference, std::size_t i, std::size_t j,
             RelativePoseError* rpe) {
  const StampedPose& qi = reference[i];
  const StampedPose& qj = reference[j];
  const StampedPose& pi = estimate[i];
  const StampedPose& pj = estimate[j];
  // Relative motions i -> j in the body frame at i: reference (Q_i^-1 Q_j) and estimate (P_i^-1 P_j).
  const Eigen::Quaterniond q_ref = qi.q_world_body.conjugate() * qj.q_world_body;
  const Eigen::Vector3d p_ref = qi.q_world_body.conjugate() * (qj.p_world_body - qi.p_world_body);
  const Eigen::Quaterniond q_est = pi.q_world_body.conjugate() * pj.q_world_body;
  const Eigen::Vector3d p_est = pi.q_world_body.conjugate() * (pj.p_world_body - pi.p_world_body);
  // E = (ref motion)^-1 (est motion) = (q_ref^-1 q_est, q_ref^-1 (p_est - p_ref)).
  const Eigen::Quaterniond q_error = q_ref.conjugate() * q_est;
  const Eigen::Vector3d p_error = q_ref.conjugate() * (p_est - p_ref);
  rpe->first.push_back(i);
  rpe->second.push_back(j);
  rpe->translation_m.push_back(p_error.norm());
  rpe->rotation_deg.push_back(RotationAngleDeg(q_error));
}

void Finish(RelativePoseError* rpe) {
  rpe->translation = Summarize(rpe->translation_m);
  rpe->rotation = Summarize(rpe->rotation_deg);
}

}  // namespace

ErrorStatistics Summarize(const std::vector<double>& errors) {
  ErrorStatistics s;
  s.count = errors.size();
  if (errors.empty()) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    s.rmse = s.mean = s.median = s.std = s.min = s.max = nan;
    return s;
  }
  double sum = 0.0;
  double sum_sq = 0.0;
  for (double e : errors) {
    sum += e;
    sum_sq += e * e;
  }
  const double n = static_cast<double>(errors.size());
  s.rmse = std::sqrt(sum_sq / n);
  s.mean = sum / n;
  std::vector<double> sorted = errors;
  std::sort(sorted.begin(), sorted.end());
  const std::size_t mid = sorted.size() / 2;
  s.median = sorted.size() % 2 == 1 ? sorted[mid] : 0.5 * (sorted[mid - 1] + sorted[mid]);
  s.min = sorted.front();
  s.max = sorted.back();
  double sum_centred = 0.0;
  for (double e : errors) sum_centred += (e - s.mean) * (e - s.mean);
  s.std = std::sqrt(sum_centred / n);
  return s;
}

AbsoluteTrajectoryError ComputeAte(const Trajectory& estimate, const Trajectory& reference, AlignmentKind kind) {
  return ComputeAte(estimate, reference, kind, AlignTrajectories(estimate, reference, kind));
}

AbsoluteTrajectoryError ComputeAte(const Trajectory& estimate, const Trajectory& reference, AlignmentKind kind,
                                   const RigidTransform& alignment) {
  ROAMLAB_CHECK(estimate.size() == reference.size(), "ATE needs matched trajectories");
  AbsoluteTrajectoryError ate;
  ate.alignment_kind = kind;
  ate.alignment = alignment;
  ate.aligned_estimate = TransformTrajectory(ate.alignment, estimate);
  std::vector<double> axis[3], horizontal, vertical;
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    const Eigen::Vector3d e = ate.aligned_estimate[i].p_world_body - reference[i].p_world_body;
    ate.error_world.push_back(e);
    ate.error_m.push_back(e.norm());
    ate.rotation_deg.push_back(
        RotationAngleDeg(reference[i].q_world_body.conjugate() * ate.aligned_estimate[i].q_world_body));
    for (int a = 0; a < 3; ++a) axis[a].push_back(e[a]);
    horizontal.push_back(e.head<2>().norm());
    vertical.push_back(std::abs(e.z()));
  }
  ate.statistics = Summarize(ate.error_m);
  ate.rotation = Summarize(ate.rotation_deg);
  for (int a = 0; a < 3; ++a) ate.axis[a] = Summarize(axis[a]);
  ate.horizontal = Summarize(horizontal);
  ate.vertical = Summarize(vertical);
  return ate;
}

RelativePoseError RpeByStep(const Trajectory& estimate, const Trajectory& reference, std::size_t step) {
  ROAMLAB_CHECK(estimate.size() == reference.size(), "RPE needs matched trajectories");
  ROAMLAB_CHECK(step >= 1, "RPE step must be at least 1");
  RelativePoseError rpe;
  for (std::size_t i = 0; i + step < estimate.size(); ++i) AddPair(estimate, reference, i, i + step, &rpe);
  Finish(&rpe);
  return rpe;
}

RelativePoseError RpeByDistance(const Trajectory& estimate, const Trajectory& reference, double distance_m) {
  ROAMLAB_CHECK(estimate.size() == reference.size(), "RPE needs matched trajectories");
  ROAMLAB_CHECK(distance_m > 0.0 && std::isfinite(distance_m), "RPE distance must be positive, got " << distance_m);
  // Path length travelled along the reference up to each pose.
  std::vector<double> travelled(reference.size(), 0.0);
  for (std::size_t i = 1; i < reference.size(); ++i)
    travelled[i] = travelled[i - 1] + (reference[i].p_world_body - reference[i - 1].p_world_body).norm();
  // For each start, the first pose at least distance_m further along (two pointers: j never moves back).
  RelativePoseError rpe;
  std::size_t j = 0;
  for (std::size_t i = 0; i < reference.size(); ++i) {
    j = std::max(j, i);
    while (j < reference.size() && travelled[j] - travelled[i] < distance_m) ++j;
    if (j == reference.size()) break;
    AddPair(estimate, reference, i, j, &rpe);
  }
  Finish(&rpe);
  return rpe;
}

std::size_t StepForDuration(const Trajectory& trajectory, double seconds) {
  if (trajectory.size() < 2) return 1;
  std::vector<double> periods;
  periods.reserve(trajectory.size() - 1);
  for (std::size_t i = 1; i < trajectory.size(); ++i)
    periods.push_back(SecondsBetween(trajectory[i - 1].t, trajectory[i].t));
  std::nth_element(periods.begin(), periods.begin() + static_cast<std::ptrdiff_t>(periods.size() / 2), periods.end());
  const double median = periods[periods.size() / 2];
  if (!(median > 0.0)) return 1;
  return std::max<std::size_t>(1, static_cast<std::size_t>(std::llround(seconds / median)));
}

double RotationAngleDeg(const Eigen::Quaterniond& q) {
  return 2.0 * std::atan2(q.vec().norm(), std::abs(q.w())) * kRadToDeg;
}

}  // namespace roamlab::eval
