// The effective rolling radius of roller wheels (sim/rolling_radius.h): below the rollers' envelope by the axle's dip
// between two rollers, deterministic, and the truth of the simulated recordings' wheel radii.
#include "sim/rolling_radius.h"

#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "sim/mujoco_model.h"
#include "sim/scenario.h"
#include "sim/simulator.h"
#include "sim/terrain.h"
#include "sim/wheeled_robot.h"
#include "tests/sim/sim_testing.h"

namespace roamlab::sim {
namespace {

// The robot model on the flat floor of the indoor scenarios, as the simulator compiles it.
struct FlatWorld {
  ModelPtr model;
  WheeledRobot robot;
};

FlatWorld Compile(const std::string& file, const std::string& kind) {
  TerrainOptions floor;
  floor.type = TerrainOptions::Type::kFlat;
  floor.friction = 0.6;
  const Terrain terrain = Terrain::Make(floor, Eigen::Vector2d::Zero());
  const std::map<std::string, std::string> files{
      {"robot.xml", testing::ReadText(testing::SourcePath(file))},
      {"world.xml", "<mujoco model=\"world\">\n<include file=\"robot.xml\"/>\n" + terrain.Mjcf() + "</mujoco>\n"}};
  auto model = LoadModelFromFiles("world.xml", files, file);
  EXPECT_TRUE(model.ok()) << model.status().message();
  FlatWorld world{std::move(model).value(), {}};
  auto robot = WheeledRobot::Bind(world.model.get(), kind, file);
  EXPECT_TRUE(robot.ok()) << robot.status().message();
  world.robot = robot.value();
  return world;
}

// The travel per radian of a roller wheel resting on rigid spheres (sim/rolling_radius.h): rho + c sin(x) / x over a
// pitch 2 x = 2 pi / N, from the model's roller_<i>_<k> bodies.
double RigidRollerRadius(const mjModel* model, int wheel) {
  const std::string prefix = "roller_" + std::to_string(wheel) + "_";
  const int first = IdOf(model, mjOBJ_BODY, prefix + "0");
  int rollers = 0;
  while (IdOf(model, mjOBJ_BODY, prefix + std::to_string(rollers)) >= 0) ++rollers;
  const double rho = model->geom_size[3 * model->body_geomadr[first]];
  const double c = Eigen::Vector3d(model->body_pos + 3 * first).norm();
  const double half_pitch = M_PI / rollers;
  return rho + c * std::sin(half_pitch) / half_pitch;
}

// The soft contact sinks the hub into the floor under the robot's weight by a fraction of the contact's solimp width
// (1 mm in both models): the measured radius lies below the rigid one by less than a tenth of a millimetre.
constexpr double kContactSinkM = 1e-4;

TEST(RollingRadiusTest, RollerWheelsRollBelowTheirEnvelopeByTheAxlesDip) {
  for (const auto& [file, kind] : std::vector<std::pair<std::string, std::string>>{{"models/omni3.xml", "omni3"},
                                                                                   {"models/mecanum.xml", "mecanum"}}) {
    const FlatWorld world = Compile(file, kind);
    auto radii = MeasureRollingRadii(world.model.get(), world.robot, 0.0, 0.0, 0.3, file);
    ASSERT_TRUE(radii.ok()) << radii.status().message();
    ASSERT_EQ(radii.value().size(), world.robot.wheels().size());
    for (std::size_t i = 0; i < radii.value().size(); ++i) {
      const double envelope_m = world.robot.wheels()[i].envelope_radius_m;
      const double rigid_m = RigidRollerRadius(world.model.get(), static_cast<int>(i));
      // 12 rollers of 15 mm, 35 mm from the hub: the rigid radius is 0.4 mm below the 50 mm envelope.
      EXPECT_NEAR(envelope_m - rigid_m, 4e-4, 2e-5) << kind << " wheel " << i;
      EXPECT_LT(radii.value()[i], rigid_m) << kind << " wheel " << i;
      EXPECT_GT(radii.value()[i], rigid_m - kContactSinkM) << kind << " wheel " << i;
      std::printf("%s wheel %zu: %.6f m per rad (envelope %.6f m)\n", kind.c_str(), i, radii.value()[i], envelope_m);
    }
  }
}

// Faster, the rollers' contacts bounce and the wheels' travel per radian spreads; it stays well within the axle's dip
// of the slow drive's, which is the definition of the truth.
TEST(RollingRadiusTest, TheTravelPerRadianDependsLittleOnTheSpeed) {
  for (const auto& [file, kind] : std::vector<std::pair<std::string, std::string>>{{"models/omni3.xml", "omni3"},
                                                                                   {"models/mecanum.xml", "mecanum"}}) {
    const FlatWorld world = Compile(file, kind);
    RollingRadiusDrive fast;
    fast.speed_mps = 0.4;
    auto slow_m = MeasureRollingRadii(world.model.get(), world.robot, 0.0, 0.0, 0.3, file);
    auto fast_m = MeasureRollingRadii(world.model.get(), world.robot, 0.0, 0.0, 0.3, file, fast);
    ASSERT_TRUE(slow_m.ok() && fast_m.ok());
    for (std::size_t i = 0; i < slow_m.value().size(); ++i) {
      EXPECT_NEAR(fast_m.value()[i], slow_m.value()[i], 2e-4) << kind << " wheel " << i;
      std::printf("%s wheel %zu at 0.4 m/s: %.6f m per rad\n", kind.c_str(), i, fast_m.value()[i]);
    }
  }
}

TEST(RollingRadiusTest, TheMeasurementIsDeterministic) {
  const FlatWorld world = Compile("models/omni3.xml", "omni3");
  auto first = MeasureRollingRadii(world.model.get(), world.robot, 1.0, -2.0, 0.7, "omni3");
  auto second = MeasureRollingRadii(world.model.get(), world.robot, 1.0, -2.0, 0.7, "omni3");
  ASSERT_TRUE(first.ok() && second.ok());
  EXPECT_EQ(first.value(), second.value());
}

// A sphere tire's travel per radian is its radius, which truth.yaml states for the differential drive: the soft
// contact takes less than a tenth of a millimetre off it.
TEST(RollingRadiusTest, ATireRollsAtItsRadius) {
  const FlatWorld world = Compile("models/diffdrive.xml", "differential_drive");
  auto radii = MeasureRollingRadii(world.model.get(), world.robot, 0.0, 0.0, 0.0, "diffdrive");
  ASSERT_TRUE(radii.ok()) << radii.status().message();
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_LT(radii.value()[i], world.robot.wheels()[i].mean_rolling_radius_m);
    EXPECT_GT(radii.value()[i], world.robot.wheels()[i].mean_rolling_radius_m - kContactSinkM);
  }
}

// truth.yaml's roller wheel radii are the measured travel per radian, not the envelope, which it states beside them.
TEST(RollingRadiusTest, TheTruthIsTheRollingRadiusAndKeepsTheEnvelope) {
  for (const std::string scenario : {"scenarios/indoor_omni_smooth.yaml", "scenarios/indoor_mecanum_gap.yaml"}) {
    auto loaded = LoadScenario(testing::SourcePath(scenario));
    ASSERT_TRUE(loaded.ok()) << loaded.status().message();
    Scenario s = loaded.value();
    s.duration_s = 0.2;
    s.sensors.laser.reset();
    s.sensors.camera.reset();
    SimulateOptions options;
    options.noise = false;
    auto sim = Simulate(s, options);
    ASSERT_TRUE(sim.ok()) << sim.status().message();
    const FlatWorld world = Compile(s.robot.kind == "omni3" ? "models/omni3.xml" : "models/mecanum.xml", s.robot.kind);
    const auto& truth = sim.value().truth.calibration;
    for (std::size_t i = 0; i < world.robot.wheels().size(); ++i) {
      const std::string index = std::to_string(i);
      ASSERT_TRUE(truth.count("odometer.radius_" + index) && truth.count("odometer.radius_envelope_" + index));
      EXPECT_EQ(truth.at("odometer.radius_envelope_" + index)[0], world.robot.wheels()[i].envelope_radius_m);
      const double rigid_m = RigidRollerRadius(world.model.get(), static_cast<int>(i));
      EXPECT_LT(truth.at("odometer.radius_" + index)[0], rigid_m) << scenario << " wheel " << i;
      EXPECT_GT(truth.at("odometer.radius_" + index)[0], rigid_m - kContactSinkM) << scenario << " wheel " << i;
    }
  }
}

}  // namespace
}  // namespace roamlab::sim
