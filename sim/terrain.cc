#include "sim/terrain.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>

#include "common/check.h"

namespace roamlab::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kBaseThicknessM = 1.0;  // solid ground under the lowest point of the heightfield

// Uniform in [0, 1) from the top 53 bits: the same sequence on every standard library.
double Uniform(std::mt19937_64& generator) { return static_cast<double>(generator() >> 11) * 0x1.0p-53; }

}  // namespace

Terrain Terrain::Make(const TerrainOptions& options, const Eigen::Vector2d& zero_at) {
  const std::string problem = options.Validate();
  ROAMLAB_CHECK(problem.empty(), "invalid TerrainOptions: " << problem);
  Terrain terrain;
  terrain.options_ = options;
  if (options.type == TerrainOptions::Type::kFlat) return terrain;

  // Draw the waves from the terrain's own seed.
  struct Wave {
    double amplitude, kx, ky, phase;
  };
  std::seed_seq sequence{static_cast<std::uint32_t>(options.seed), static_cast<std::uint32_t>(options.seed >> 32)};
  std::mt19937_64 generator(sequence);
  std::vector<Wave> waves;
  const double log_min = std::log(options.min_wavelength_m);
  const double log_max = std::log(options.max_wavelength_m);
  for (int i = 0; i < options.waves; ++i) {
    const double wavelength = std::exp(log_min + (log_max - log_min) * Uniform(generator));
    const double direction = 2.0 * kPi * Uniform(generator);
    const double phase = 2.0 * kPi * Uniform(generator);
    const double weight = 0.5 + 0.5 * Uniform(generator);
    const double k = 2.0 * kPi / wavelength;
    waves.push_back({weight * wavelength, k * std::cos(direction), k * std::sin(direction), phase});
  }

  // Sample on the grid, then rescale to [0, 1].
  terrain.cols_ = TerrainSamplesAlong(options.size_m.x(), options.resolution_m);
  terrain.rows_ = TerrainSamplesAlong(options.size_m.y(), options.resolution_m);
  std::vector<double> height(static_cast<std::size_t>(terrain.rows_) * static_cast<std::size_t>(terrain.cols_));
  for (int r = 0; r < terrain.rows_; ++r) {
    const double y = -0.5 * options.size_m.y() + r * options.size_m.y() / (terrain.rows_ - 1);
    for (int c = 0; c < terrain.cols_; ++c) {
      const double x = -0.5 * options.size_m.x() + c * options.size_m.x() / (terrain.cols_ - 1);
      double h = 0.0;
      for (const Wave& w : waves) h += w.amplitude * std::sin(w.kx * x + w.ky * y + w.phase);
      height[static_cast<std::size_t>(r) * terrain.cols_ + c] = h;
    }
  }
  const auto [low, high] = std::minmax_element(height.begin(), height.end());
  const double min_h = *low;
  const double span = std::max(*high - *low, 1e-12);
  terrain.normalized_.resize(height.size());
  for (std::size_t i = 0; i < height.size(); ++i)
    terrain.normalized_[i] = static_cast<float>((height[i] - min_h) / span);

  // Put the ground under zero_at at z = 0.
  terrain.offset_z_m_ = -terrain.HeightAt(zero_at.x(), zero_at.y());
  return terrain;
}

double Terrain::HeightAt(double x, double y) const {
  if (rows_ == 0) return 0.0;
  const double sx = options_.size_m.x();
  const double sy = options_.size_m.y();
  // Continuous grid coordinates, clamped to the field.
  const double u = std::clamp((x + 0.5 * sx) / sx * (cols_ - 1), 0.0, static_cast<double>(cols_ - 1));
  const double v = std::clamp((y + 0.5 * sy) / sy * (rows_ - 1), 0.0, static_cast<double>(rows_ - 1));
  const int c0 = std::min(static_cast<int>(u), cols_ - 2);
  const int r0 = std::min(static_cast<int>(v), rows_ - 2);
  const double fu = u - c0;
  const double fv = v - r0;
  const auto at = [this](int r, int c) {
    return static_cast<double>(normalized_[static_cast<std::size_t>(r) * cols_ + c]);
  };
  // MuJoCo's two triangles per cell share the diagonal from (r0, c0) to (r0 + 1, c0 + 1).
  const double h00 = at(r0, c0);
  const double h11 = at(r0 + 1, c0 + 1);
  const double h = fu >= fv ? h00 + fu * (at(r0, c0 + 1) - h00) + fv * (h11 - at(r0, c0 + 1))
                            : h00 + fv * (at(r0 + 1, c0) - h00) + fu * (h11 - at(r0 + 1, c0));
  return h * options_.relief_m + offset_z_m_;
}

bool Terrain::Contains(double x, double y, double margin_m) const {
  if (rows_ == 0) return true;
  return std::abs(x) <= 0.5 * options_.size_m.x() - margin_m && std::abs(y) <= 0.5 * options_.size_m.y() - margin_m;
}

double Terrain::Relief() const {
  if (rows_ == 0) return 0.0;
  const auto [low, high] = std::minmax_element(normalized_.begin(), normalized_.end());
  return (static_cast<double>(*high) - static_cast<double>(*low)) * options_.relief_m;
}

std::string Terrain::Mjcf() const {
  std::ostringstream xml;
  xml.precision(17);
  // The robot's MJCF is included in the same document, so its <default> applies here too: every contact attribute
  // of the ground is explicit. solmix 0 lets the robot's geoms alone set the contact softness (solref, solimp);
  // MuJoCo takes the larger friction and condim of the pair.
  std::ostringstream ground_attributes;
  ground_attributes.precision(17);
  ground_attributes << "material=\"terrain\" rgba=\"1 1 1 1\" contype=\"1\" conaffinity=\"1\" condim=\"3\" "
                    << "friction=\"" << options_.friction << " 0.005 0.0001\" solmix=\"0\" margin=\"0\" gap=\"0\"";
  const std::string ground = ground_attributes.str();
  // A fine checker with random marks: visual texture for cameras; one tile is about 2 m.
  xml << "<asset>\n"
      << "  <texture name=\"terrain\" type=\"2d\" builtin=\"checker\" width=\"512\" height=\"512\""
      << " rgb1=\"0.45 0.38 0.26\" rgb2=\"0.36 0.30 0.20\" mark=\"random\" random=\"0.08\""
      << " markrgb=\"0.62 0.56 0.42\"/>\n";
  if (rows_ == 0) {
    xml << "  <material name=\"terrain\" texture=\"terrain\" texrepeat=\"0.25 0.25\" texuniform=\"true\"/>\n"
        << "</asset>\n<worldbody>\n"
        << "  <geom name=\"terrain\" type=\"plane\" size=\"0 0 1\" " << ground << "/>\n";
  } else {
    xml << "  <material name=\"terrain\" texture=\"terrain\" texrepeat=\"" << options_.size_m.x() / 4.0 << " "
        << options_.size_m.y() / 4.0 << "\"/>\n"
        << "  <hfield name=\"terrain\" nrow=\"" << rows_ << "\" ncol=\"" << cols_ << "\" size=\""
        << 0.5 * options_.size_m.x() << " " << 0.5 * options_.size_m.y() << " " << options_.relief_m << " "
        << kBaseThicknessM << "\"/>\n"
        << "</asset>\n<worldbody>\n"
        << "  <geom name=\"terrain\" type=\"hfield\" hfield=\"terrain\" pos=\"0 0 " << offset_z_m_ << "\" " << ground
        << "/>\n";
  }
  xml << "  <light name=\"sun\" directional=\"true\" pos=\"0 0 100\" dir=\"0.3 0.2 -1\" castshadow=\"false\"/>\n"
      << "</worldbody>\n";
  return xml.str();
}

Status Terrain::Fill(mjModel* model) const {
  if (rows_ == 0) return Status::Ok();
  const int id = mj_name2id(model, mjOBJ_HFIELD, "terrain");
  if (id < 0) return Status::Error("the compiled world has no hfield 'terrain'");
  if (model->hfield_nrow[id] != rows_ || model->hfield_ncol[id] != cols_)
    return Status::Error("hfield 'terrain' has a different size than the generated terrain");
  std::copy(normalized_.begin(), normalized_.end(), model->hfield_data + model->hfield_adr[id]);
  return Status::Ok();
}

}  // namespace roamlab::sim
