// Terrain (sim/terrain.h): seeded generation, relief, and agreement of HeightAt with the surface MuJoCo collides with.
#include "sim/terrain.h"

#include <cmath>
#include <sstream>

#include <gtest/gtest.h>

#include "sim/mujoco_model.h"

namespace roamlab::sim {
namespace {

TerrainOptions SmallHills(std::uint64_t seed) {
  TerrainOptions o;
  o.type = TerrainOptions::Type::kHills;
  o.seed = seed;
  o.size_m = Eigen::Vector2d(40.0, 30.0);
  o.resolution_m = 1.0;
  o.relief_m = 3.0;
  o.min_wavelength_m = 8.0;
  o.max_wavelength_m = 20.0;
  o.waves = 6;
  return o;
}

TEST(TerrainTest, SeededReliefAndZeroAtTheStart) {
  const Eigen::Vector2d start(3.0, -2.0);
  const Terrain a = Terrain::Make(SmallHills(7), start);
  const Terrain b = Terrain::Make(SmallHills(7), start);
  const Terrain c = Terrain::Make(SmallHills(8), start);
  EXPECT_EQ(a.rows(), 31);
  EXPECT_EQ(a.cols(), 41);
  EXPECT_NEAR(a.Relief(), 3.0, 1e-5);  // samples are floats
  EXPECT_NEAR(a.HeightAt(start.x(), start.y()), 0.0, 1e-12);
  EXPECT_EQ(a.Mjcf(), b.Mjcf());
  double difference = 0.0;
  for (double x = -19.0; x <= 19.0; x += 1.7)
    for (double y = -14.0; y <= 14.0; y += 1.3) {
      EXPECT_EQ(a.HeightAt(x, y), b.HeightAt(x, y));
      difference = std::max(difference, std::abs(a.HeightAt(x, y) - c.HeightAt(x, y)));
    }
  EXPECT_GT(difference, 0.3);  // another seed, other hills
  EXPECT_TRUE(a.Contains(19.0, 14.0));
  EXPECT_FALSE(a.Contains(19.0, 14.0, 2.0));
}

TEST(TerrainTest, ValidateNamesTheField) {
  TerrainOptions o = SmallHills(1);
  EXPECT_EQ(o.Validate(), "");
  o.relief_m = 0.0;
  EXPECT_EQ(o.Validate().rfind("relief_m:", 0), 0u);
  o = SmallHills(1);
  o.min_wavelength_m = 30.0;
  EXPECT_EQ(o.Validate().rfind("wavelength_m:", 0), 0u);
  o = SmallHills(1);
  o.resolution_m = 0.001;
  EXPECT_EQ(o.Validate().rfind("resolution_m:", 0), 0u);
}

// Balls on vertical slides come to rest on the compiled heightfield: their lowest point is where HeightAt says the
// ground is. This checks the sample layout (rows along y, columns along x), the triangulation, the vertical offset
// and Fill() together.
TEST(TerrainTest, HeightAtIsTheSurfaceMujocoCollidesWith) {
  const Terrain terrain = Terrain::Make(SmallHills(3), Eigen::Vector2d(1.0, 1.0));
  const double points[][2] = {{-15.3, -10.1}, {-4.5, 6.2}, {0.0, 0.0}, {7.7, -3.3}, {12.25, 9.9}, {17.0, 12.6}};
  constexpr double kRadius = 0.02;
  std::ostringstream xml;
  xml << "<mujoco><option timestep=\"0.001\"/>\n" << terrain.Mjcf() << "<worldbody>\n";
  for (const auto& p : points) {
    xml << "<body pos=\"" << p[0] << " " << p[1] << " " << terrain.HeightAt(p[0], p[1]) + kRadius + 0.05
        << "\"><joint type=\"slide\" axis=\"0 0 1\"/><geom type=\"sphere\" size=\"" << kRadius
        << "\" mass=\"1\"/></body>\n";
  }
  xml << "</worldbody></mujoco>";
  auto model = LoadModelFromString(xml.str());
  ASSERT_TRUE(model.ok()) << model.status().message();
  ASSERT_TRUE(terrain.Fill(model.value().get()).ok());
  DataPtr data = MakeData(model.value().get());
  for (int i = 0; i < 2000; ++i) mj_step(model.value().get(), data.get());
  for (int i = 0; i < 6; ++i) {
    const double x = points[i][0];
    const double y = points[i][1];
    // On a plane of gradient g a resting ball's centre is r sqrt(1 + |g|^2) above the plane's height under it.
    const double e = 1e-4;
    const double gx = (terrain.HeightAt(x + e, y) - terrain.HeightAt(x - e, y)) / (2 * e);
    const double gy = (terrain.HeightAt(x, y + e) - terrain.HeightAt(x, y - e)) / (2 * e);
    const double expected = terrain.HeightAt(x, y) + kRadius * std::sqrt(1.0 + gx * gx + gy * gy);
    // Soft contact: a 1 kg ball sinks a fraction of a millimetre.
    EXPECT_NEAR(data->xpos[3 * (i + 1) + 2], expected, 1e-3) << x << ", " << y;
  }
}

TEST(TerrainTest, FlatFloorIsAPlaneAtZero) {
  TerrainOptions o;
  o.type = TerrainOptions::Type::kFlat;
  const Terrain flat = Terrain::Make(o, Eigen::Vector2d::Zero());
  EXPECT_EQ(flat.HeightAt(123.0, -45.0), 0.0);
  EXPECT_EQ(flat.Relief(), 0.0);
  EXPECT_NE(flat.Mjcf().find("type=\"plane\""), std::string::npos);
}

}  // namespace
}  // namespace roamlab::sim
