#include "range_beacon.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <utility>

#include "estimator/factor.h"
#include "estimator/model_registry.h"

namespace beacon {
namespace {

using roamlab::Result;
using roamlab::Status;
namespace estimator = roamlab::estimator;

// The model bound to one stream: the beacon's position and the range column.
class BoundRangeBeacon final : public estimator::BoundErrorModel {
 public:
  BoundRangeBeacon(const Eigen::Vector3d& beacon_world, int range_column)
      : beacon_world_(beacon_world), range_column_(range_column) {}

  std::unique_ptr<estimator::Factor> MakeFactor(const estimator::ModelSample& sample) const override {
    return estimator::MakeFactor(RangeToBeaconError(beacon_world_, sample.values[range_column_]));
  }

 private:
  Eigen::Vector3d beacon_world_;
  int range_column_;
};

// Checks the recording stream (an inputs stream with a range_m column) and reads options.beacon_world.
Result<std::unique_ptr<estimator::BoundErrorModel>> Bind(const estimator::ModelBindContext& context) {
  const roamlab::recording::StreamInfo& info = context.primary.info;
  if (info.type != roamlab::recording::StreamType::kInputs)
    return Status::Error("recording stream '" + info.name + "' must be an inputs stream");
  const auto column = std::find(info.columns.begin(), info.columns.end(), "range_m");
  if (column == info.columns.end()) return Status::Error("recording stream '" + info.name + "' has no range_m column");
  const auto beacon = context.config.options.find("beacon_world");
  if (beacon == context.config.options.end() || beacon->second.size() != 3)
    return Status::Error("range_beacon needs options.beacon_world: [x, y, z], the beacon in W [m]");
  const Eigen::Vector3d beacon_world(beacon->second[0], beacon->second[1], beacon->second[2]);
  return std::unique_ptr<estimator::BoundErrorModel>(
      std::make_unique<BoundRangeBeacon>(beacon_world, static_cast<int>(column - info.columns.begin())));
}

}  // namespace

Status RegisterRangeBeaconModel() {
  static const Status status = [] {
    estimator::ErrorModelDefinition model;
    model.spec.name = "range_beacon";
    model.spec.source_roles = {""};
    model.spec.noise_keys = {"sigma_m"};
    model.spec.slots = {{"lever_arm", estimator::Manifold::Euclidean(3), Eigen::VectorXd::Zero(3)}};
    model.spec.option_keys = {"beacon_world"};
    model.attachment = estimator::ModelAttachment::kOnePose;
    model.residual_dim = RangeToBeaconError::kResidualDim;
    model.absolute = true;
    model.bind = Bind;
    return estimator::RegisterErrorModel(std::move(model));
  }();
  return status;
}

}  // namespace beacon
