#include "sim/laser.h"

#include <cmath>
#include <limits>

namespace roamlab::sim {

std::vector<double> CastScan(const mjModel* model, const mjData* data, int laser_site,
                             const frontend::ScanGeometry& geometry) {
  const mjtNum* origin = data->site_xpos + 3 * laser_site;
  const mjtNum* R = data->site_xmat + 9 * laser_site;  // row-major, site -> world
  const mjtByte world_only[mjNGROUP] = {1, 0, 0, 0, 0, 0};
  std::vector<double> ranges(static_cast<std::size_t>(geometry.beams), std::numeric_limits<double>::quiet_NaN());
  for (int k = 0; k < geometry.beams; ++k) {
    const double c = std::cos(geometry.Angle(k));
    const double s = std::sin(geometry.Angle(k));
    const mjtNum direction[3] = {R[0] * c + R[1] * s, R[3] * c + R[4] * s, R[6] * c + R[7] * s};
    int geom = -1;
    const mjtNum distance = mj_ray(model, data, origin, direction, world_only, 1, -1, &geom);
    if (geom >= 0 && distance >= geometry.min_range_m && distance <= geometry.max_range_m) ranges[k] = distance;
  }
  return ranges;
}

}  // namespace roamlab::sim
