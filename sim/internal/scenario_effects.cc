#include "sim/internal/scenario_effects.h"

#include <algorithm>

namespace roamlab::sim::internal {

bool HasEffect(const Scenario& s, const std::string& name) {
  return std::any_of(s.effects.begin(), s.effects.end(), [&](const EffectOptions& e) { return e.name == name; });
}

std::vector<WheelDeformation> TireDeformations(const Scenario& s) {
  std::vector<WheelDeformation> out = s.robot.wheel_deformation;
  const auto entry = [&out](int wheel) -> WheelDeformation& {
    for (WheelDeformation& d : out)
      if (d.wheel == wheel) return d;
    out.push_back(WheelDeformation{wheel, 1.0, 0.0});
    return out.back();
  };
  if (HasEffect(s, "wheel_radius_asymmetry"))
    entry(1).radius_scale *= EffectParameter(s.effects, "wheel_radius_asymmetry", "ratio_right_left", 1.0);
  if (HasEffect(s, "wheel_radius_scale")) {
    const int wheels = s.robot.kind == "differential_drive" ? 2 : s.robot.kind == "omni3" ? 3 : 4;
    for (int w = 0; w < wheels; ++w)
      entry(w).radius_scale *= EffectParameter(s.effects, "wheel_radius_scale", "scale", 1.0);
  }
  if (HasEffect(s, "wheel_deformation")) {
    const int wheel = static_cast<int>(EffectParameter(s.effects, "wheel_deformation", "wheel", 0.0));
    entry(wheel).ovality_m += EffectParameter(s.effects, "wheel_deformation", "ovality_m", 0.0);
    entry(wheel).keep_mean_radius = true;
  }
  return out;
}

}  // namespace roamlab::sim::internal
