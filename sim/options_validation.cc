// The checks of the options a scenario holds that the physics headers declare (ackermann.h, terrain.h): here, in the
// scenario library, so that loading and validating a scenario needs none of the physics.
#include <cmath>
#include <string>

#include "sim/ackermann.h"
#include "sim/terrain.h"

namespace roamlab::sim {
namespace {

constexpr int kMaxSamplesPerSide = 4001;

}  // namespace

int TerrainSamplesAlong(double size_m, double resolution_m) {
  return static_cast<int>(std::llround(size_m / resolution_m)) + 1;
}

std::string SpeedControllerOptions::Validate() const {
  if (!(std::isfinite(kp_nm_per_mps) && kp_nm_per_mps > 0.0)) return "kp_nm_per_mps: must be > 0";
  if (!(std::isfinite(ki_nm_per_m) && ki_nm_per_m >= 0.0)) return "ki_nm_per_m: must be >= 0";
  if (!(std::isfinite(torque_limit_nm) && torque_limit_nm > 0.0)) return "torque_limit_nm: must be > 0";
  return "";
}

std::string TerrainOptions::Validate() const {
  const auto finite = [](double x) { return std::isfinite(x); };
  if (!(finite(friction) && friction > 0.0)) return "friction: must be > 0";
  if (type == Type::kFlat) return "";
  if (!(size_m.allFinite() && size_m.minCoeff() > 0.0)) return "size_m: both extents must be > 0";
  if (!(finite(resolution_m) && resolution_m > 0.0)) return "resolution_m: must be > 0";
  if (TerrainSamplesAlong(size_m.maxCoeff(), resolution_m) > kMaxSamplesPerSide)
    return "resolution_m: too fine for size_m (at most " + std::to_string(kMaxSamplesPerSide) + " samples per side)";
  if (TerrainSamplesAlong(size_m.minCoeff(), resolution_m) < 3) return "resolution_m: too coarse for size_m";
  if (!(finite(relief_m) && relief_m > 0.0)) return "relief_m: must be > 0";
  if (!(finite(min_wavelength_m) && min_wavelength_m > 0.0 && finite(max_wavelength_m) &&
        max_wavelength_m >= min_wavelength_m))
    return "wavelength_m: must be [min, max] with 0 < min <= max";
  if (min_wavelength_m < 4.0 * resolution_m) return "wavelength_m: the minimum must be >= 4 resolution_m";
  if (waves < 1 || waves > 1000) return "waves: must be in [1, 1000]";
  return "";
}

}  // namespace roamlab::sim
