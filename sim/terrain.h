// Terrain of a simulated world: a flat textured floor or a procedural hilly heightfield, as MJCF text plus the height
// samples that fill the MuJoCo heightfield after compilation.
//
// Hills: a sum of `waves` plane sinusoids, h(x, y) = sum_i a_i sin(k_i . (x, y) + phi_i), drawn from the terrain's own
// seed: wavelengths log-uniform in [min_wavelength_m, max_wavelength_m], directions and phases uniform, amplitudes
// proportional to the wavelength (so every scale has about the same slope). The sum is sampled on a grid of spacing
// resolution_m over size_m and rescaled so that its lowest sample is at 0 and its highest at relief_m (the relief is
// the peak-to-peak height over the whole field). The field is centred on the world origin and shifted vertically so
// that the ground under `zero_at` is at z = 0.
//
// MuJoCo heightfield layout (verified on 2.2.2): hfield_data[r * ncol + c] is the normalized height at
// x = -size_x/2 + c * size_x/(ncol - 1), y = -size_y/2 + r * size_y/(nrow - 1); height = data * relief_m + geom z.
// MuJoCo's collision surface splits each grid cell into two triangles along the diagonal from (r, c) to
// (r + 1, c + 1); HeightAt interpolates on the same triangles, so it is the height the tires touch.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <mujoco/mujoco.h>
#include <Eigen/Core>

#include "common/status.h"

namespace roamlab::sim {

struct TerrainOptions {
  enum class Type { kFlat, kHills };
  Type type = Type::kHills;
  std::uint64_t seed = 7;                // hills only; independent of the sensor-noise seed
  Eigen::Vector2d size_m{300.0, 300.0};  // extent along x (east) and y (north) [m]
  double resolution_m = 1.0;             // grid spacing [m]
  double relief_m = 4.0;                 // peak-to-peak height [m]
  double min_wavelength_m = 20.0;
  double max_wavelength_m = 60.0;
  int waves = 16;
  double friction = 0.8;  // sliding friction coefficient of the ground

  // Empty when usable; otherwise "<field>: <problem>" with the field as named in the scenario.
  std::string Validate() const;
};

// Grid samples along an extent of `size_m` at `resolution_m`, both ends included.
int TerrainSamplesAlong(double size_m, double resolution_m);

// A sampled heightfield (hills) or the flat floor (rows = cols = 0).
class Terrain {
 public:
  // Builds the terrain; `zero_at` [m] (x, y) is where the ground is put at z = 0.
  static Terrain Make(const TerrainOptions& options, const Eigen::Vector2d& zero_at);

  const TerrainOptions& options() const { return options_; }
  int rows() const { return rows_; }
  int cols() const { return cols_; }
  // Ground height [m] at (x, y); 0 on the flat floor. Outside the field: the nearest edge sample.
  double HeightAt(double x, double y) const;
  // Whether (x, y) lies on the field (always true for the flat floor).
  bool Contains(double x, double y, double margin_m = 0.0) const;
  // Peak-to-peak height over the field [m] (0 for the flat floor).
  double Relief() const;

  // <asset> and <worldbody> sections with the textured ground (geom "terrain", hfield "terrain"); to be placed at the
  // top level of an MJCF document.
  std::string Mjcf() const;
  // Copies the samples into the compiled model's hfield "terrain" (hills only). Error when the model has no such
  // hfield or its size differs.
  Status Fill(mjModel* model) const;

 private:
  TerrainOptions options_;
  int rows_ = 0;
  int cols_ = 0;
  std::vector<float> normalized_;  // rows * cols in [0, 1]
  double offset_z_m_ = 0.0;        // geom z: height = normalized * relief + offset
};

}  // namespace roamlab::sim
