#include "estimator/internal/after_gap.h"

#include <cmath>

#include <Eigen/Cholesky>

#include "common/check.h"
#include "common/chi_square.h"
#include "estimator/model_registry.h"
#include "recording/stream_health.h"

namespace roamlab::estimator::internal {

std::map<std::string, std::vector<Time>> GapResumes(const EstimatorConfig& config, const recording::Recording& rec,
                                                    bool absolute_only) {
  std::map<std::string, std::vector<Time>> out;
  for (const auto& [name, stream] : config.streams) {
    if (stream.sources.size() != 1) continue;
    if (absolute_only) {
      const ErrorModelDefinition* model = FindErrorModel(stream.model);
      if (model == nullptr || !model->absolute) continue;
    }
    for (const recording::Stream& source : rec.streams) {
      if (source.info.name != stream.sources.begin()->second) continue;
      for (const recording::StreamGap& gap : recording::CheckStreamHealth(source).gaps)
        out[name].push_back(Time::FromNanoseconds(gap.after.nanoseconds() + std::llround(gap.length_s * 1e9)));
    }
  }
  return out;
}

bool InnovationWithin(double probability, const WhitenedFactor& wf, const std::vector<int>& free,
                      const Eigen::MatrixXd& covariance) {
  // (A robust loss scales the whitened error and Jacobians alike: the test takes them before it.)
  const double unweight = wf.residual.norm() > 0.0 ? std::sqrt(wf.squared_norm) / wf.residual.norm() : 1.0;
  const Eigen::VectorXd r = unweight * wf.residual;
  Eigen::MatrixXd J(r.size(), covariance.rows());
  Eigen::Index column = 0;
  for (const int i : free) {
    const Eigen::MatrixXd& block = wf.jacobians[static_cast<std::size_t>(i)];
    J.middleCols(column, block.cols()) = unweight * block;
    column += block.cols();
  }
  ROAMLAB_CHECK(column == covariance.rows(), "an innovation test's covariance of the wrong size");
  const Eigen::MatrixXd innovation = Eigen::MatrixXd::Identity(r.size(), r.size()) + J * covariance * J.transpose();
  return r.dot(innovation.ldlt().solve(r)) <= ChiSquareQuantile(probability, static_cast<int>(r.size()));
}

}  // namespace roamlab::estimator::internal
