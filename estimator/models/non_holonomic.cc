#include "estimator/models/non_holonomic.h"

#include <memory>

#include "common/time.h"
#include "estimator/factor.h"

namespace roamlab::estimator {
namespace {

// The model bound to one stream: it reads only the stamps of the poses each sample joins.
class BoundNonHolonomic final : public BoundErrorModel {
 public:
  std::unique_ptr<Factor> MakeFactor(const ModelSample& sample) const override {
    if (sample.pose_times.size() != 2) return nullptr;
    const double dt_s = SecondsBetween(sample.pose_times[0], sample.pose_times[1]);
    if (!(dt_s > 0.0)) return nullptr;
    return ::roamlab::estimator::MakeFactor(NonHolonomicError(dt_s));
  }
};

// Any recording stream will do: the model reads none of its values.
Result<std::unique_ptr<BoundErrorModel>> Bind(const ModelBindContext& /*context*/) {
  return std::unique_ptr<BoundErrorModel>(std::make_unique<BoundNonHolonomic>());
}

}  // namespace

ErrorModelDefinition NonHolonomicModel() {
  ErrorModelDefinition model;
  model.spec.name = "non_holonomic";
  model.spec.source_roles = {""};
  model.spec.noise_keys = {"lateral_mps", "vertical_mps"};
  model.spec.slots = {{"lever_arm", Manifold::Euclidean(3), Eigen::VectorXd::Zero(3)}};
  model.attachment = ModelAttachment::kPair;
  model.residual_dim = NonHolonomicError::kResidualDim;
  model.absolute = false;
  model.bind = Bind;
  return model;
}

}  // namespace roamlab::estimator
