// The effective rolling radius of roller wheels (sim/rolling_radius.h): below the rollers' envelope by the axle's dip
// between two rollers, deterministic, and the truth of the simulated recordings' wheel radii. The ATV's rear tires:
// below their radius by half the contact's penetration, and the truth of its speed gain kv/L; driven, they slip at a
// velocity proportional to the traction, which the drive's grade sets.
#include "sim/rolling_radius.h"

#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "sim/ackermann.h"
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

// The model in `file` on the flat floor (friction 0.6; a tire's own friction rules when higher).
ModelPtr CompileOnFloor(const std::string& file) {
  TerrainOptions floor;
  floor.type = TerrainOptions::Type::kFlat;
  floor.friction = 0.6;
  const Terrain terrain = Terrain::Make(floor, Eigen::Vector2d::Zero());
  const std::map<std::string, std::string> files{
      {"robot.xml", testing::ReadText(testing::SourcePath(file))},
      {"world.xml", "<mujoco model=\"world\">\n<include file=\"robot.xml\"/>\n" + terrain.Mjcf() + "</mujoco>\n"}};
  auto model = LoadModelFromFiles("world.xml", files, file);
  EXPECT_TRUE(model.ok()) << model.status().message();
  return std::move(model).value();
}

FlatWorld Compile(const std::string& file, const std::string& kind) {
  FlatWorld world{CompileOnFloor(file), {}};
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

// The ATV on the flat floor (a plane).
struct AtvWorld {
  ModelPtr model;
  AckermannVehicle vehicle;
};

AtvWorld CompileAtv() {
  AtvWorld world{CompileOnFloor("models/atv.xml"), {}};
  auto vehicle = AckermannVehicle::Bind(world.model.get(), "atv.xml");
  EXPECT_TRUE(vehicle.ok()) << vehicle.status().message();
  world.vehicle = vehicle.value();
  return world;
}

// Free rolling on level ground: the travel per radian is the same at 1 and 3 m/s to 1 % of the 0.36 mm sink (the
// faster roll carries more of the wheels' hinge damping), and the same on every call.
TEST(RollingRadiusTest, TheAtvsRearTiresRollAtOneRadiusWhateverTheSpeed) {
  const AtvWorld world = CompileAtv();
  RearRollingDrive fast;
  fast.speed_mps = 3.0;
  auto slow_m = MeasureRearRollingRadius(world.model.get(), world.vehicle, {}, "atv");
  auto fast_m = MeasureRearRollingRadius(world.model.get(), world.vehicle, {}, "atv", fast);
  auto again_m = MeasureRearRollingRadius(world.model.get(), world.vehicle, {}, "atv");
  ASSERT_TRUE(slow_m.ok() && fast_m.ok() && again_m.ok()) << slow_m.status().message();
  EXPECT_EQ(again_m.value(), slow_m.value());
  EXPECT_NEAR(fast_m.value(), slow_m.value(), 0.01 * 3.6e-4);
  EXPECT_LT(slow_m.value(), world.vehicle.wheel_radius_m());
  std::printf("ATV rear tires on a plane: %.6f m per rad at 1 m/s, %.6f at 3 m/s (radius %.3f m)\n", slow_m.value(),
              fast_m.value(), world.vehicle.wheel_radius_m());
}

// The grade puts the weight's component along the slope on the rear tires: their traction over the level drive's is
// m g sin(atan(grade)), up to the change of the rolling resistance with the grade's load shift, a fraction of the
// resistance itself (the level drive's traction).
TEST(RollingRadiusTest, TheGradeAddsTheWeightAlongTheSlopeToTheRearTraction) {
  const AtvWorld world = CompileAtv();
  auto level = MeasureRearRoll(world.model.get(), world.vehicle, {}, "atv");
  ASSERT_TRUE(level.ok()) << level.status().message();
  for (const double grade : {-0.1, 0.1}) {
    RearRollingDrive drive;
    drive.grade = grade;
    auto graded = MeasureRearRoll(world.model.get(), world.vehicle, {}, "atv", drive);
    ASSERT_TRUE(graded.ok()) << graded.status().message();
    const double weight_along_n = world.vehicle.mass_kg() * 9.80665 * std::sin(std::atan(grade));
    EXPECT_NEAR(graded.value().traction_n - level.value().traction_n, weight_along_n, level.value().traction_n)
        << "grade " << grade;
    std::printf("grade %+.2f: rear traction %.1f N over the level drive's %.1f N (weight along the slope %.1f N)\n",
                grade, graded.value().traction_n, level.value().traction_n, weight_along_n);
  }
  RearRollingDrive steep;
  steep.grade = 1.0;
  EXPECT_FALSE(MeasureRearRoll(world.model.get(), world.vehicle, {}, "atv", steep).ok());
}

// Straight least squares y = a + b x with the residual standard deviation, b's standard error and the share of y's
// variance the line explains.
struct LineFit {
  double intercept = 0.0, slope = 0.0, residual_std = 0.0, slope_std = 0.0, r_squared = 0.0;
};

LineFit FitLine(const std::vector<double>& x, const std::vector<double>& y) {
  const double n = static_cast<double>(x.size());
  double x_mean = 0.0, y_mean = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    x_mean += x[i] / n;
    y_mean += y[i] / n;
  }
  double sxx = 0.0, sxy = 0.0, syy = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxx += (x[i] - x_mean) * (x[i] - x_mean);
    sxy += (x[i] - x_mean) * (y[i] - y_mean);
    syy += (y[i] - y_mean) * (y[i] - y_mean);
  }
  LineFit fit;
  fit.slope = sxy / sxx;
  fit.intercept = y_mean - fit.slope * x_mean;
  double ssr = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double r = y[i] - fit.intercept - fit.slope * x[i];
    ssr += r * r;
  }
  fit.residual_std = std::sqrt(ssr / (n - 2.0));
  fit.slope_std = fit.residual_std / std::sqrt(sxx);
  fit.r_squared = 1.0 - ssr / syy;
  return fit;
}

// Driven up and down slopes at constant speed, the rear wheels turn faster than their hubs advance by a slip velocity
// s = omega (r_level - r) (r: the travel per radian, r_level the level drive's) that grows in proportion to the
// traction per unit of the vehicle's mass, f_x / m: s = s_0 + c f_x / m. The slope c [s] is positive and many
// standard errors from zero, the line explains 99 % of the slips' variance, and a drive at twice the speed up a slope
// in between falls on the same line within three of its residual standard deviations (MuJoCo's soft friction: the
// slip velocity depends on the force, not the speed). The line is not exact: braking slips a little more per
// newton than driving (the residuals curve), which the residual spread carries.
TEST(RollingRadiusTest, TheAtvsRearTiresSlipAtAVelocityProportionalToTheTraction) {
  const AtvWorld world = CompileAtv();
  const double mass_kg = world.vehicle.mass_kg();
  auto level = MeasureRearRoll(world.model.get(), world.vehicle, {}, "atv");
  ASSERT_TRUE(level.ok()) << level.status().message();
  const double r_level_m = level.value().travel_per_rad_m;
  const auto slip_mps = [r_level_m](const RearRoll& roll) {
    return roll.wheel_rate_radps * (r_level_m - roll.travel_per_rad_m);
  };
  std::vector<double> traction_mps2, slips_mps;
  for (const double grade : {-0.15, -0.1, -0.05, 0.0, 0.05, 0.1, 0.15}) {
    RearRollingDrive drive;
    drive.grade = grade;
    auto roll = MeasureRearRoll(world.model.get(), world.vehicle, {}, "atv", drive);
    ASSERT_TRUE(roll.ok()) << roll.status().message();
    traction_mps2.push_back(roll.value().traction_n / mass_kg);
    slips_mps.push_back(slip_mps(roll.value()));
    std::printf("grade %+.2f: f_x/m %+.4f m/s^2, travel per rad %.6f m, slip %+.6f m/s\n", grade, traction_mps2.back(),
                roll.value().travel_per_rad_m, slips_mps.back());
  }
  const LineFit fit = FitLine(traction_mps2, slips_mps);
  std::printf("slip = %+.6f m/s + %.6f s * f_x/m (+- %.6f s), residual std %.2e m/s, R^2 %.5f\n", fit.intercept,
              fit.slope, fit.slope_std, fit.residual_std, fit.r_squared);
  EXPECT_GT(fit.slope, 0.0);
  EXPECT_GT(fit.slope, 20.0 * fit.slope_std);
  EXPECT_GT(fit.r_squared, 0.99);

  RearRollingDrive faster;
  faster.speed_mps = 2.0;
  faster.grade = 0.075;
  auto fast = MeasureRearRoll(world.model.get(), world.vehicle, {}, "atv", faster);
  ASSERT_TRUE(fast.ok()) << fast.status().message();
  const double predicted_mps = fit.intercept + fit.slope * fast.value().traction_n / mass_kg;
  std::printf("2 m/s up 0.075: f_x/m %+.4f m/s^2, slip %+.6f m/s, the line's %+.6f m/s\n",
              fast.value().traction_n / mass_kg, slip_mps(fast.value()), predicted_mps);
  EXPECT_NEAR(slip_mps(fast.value()), predicted_mps, 3.0 * fit.residual_std);
}

// The slip's regressor on a drive. Beyond the level drive's traction (which truth.yaml's kv/L includes), the rear
// tires carry m times O's forward specific force f_x = a_x + g sin(pitch) (what an IMU reads and the estimator's
// slip_per_mps2 regresses on) plus the steered front tires' drag in turns, about the front axle's share (0.44 of the
// ATV's weight, models/atv.xml) of m a_y tan(delta). Over the noise-free weave of atv_hills.yaml, the speed-weighted
// traction per unit mass that the speed row's gain sees, <v (F - F_level) / m>, lies between the two (f_x alone and
// with the drag estimate), which bracket the slip's effect on kv/L in tools/atv_slip_kv.py.
TEST(RollingRadiusTest, TheWeavesRearTractionLiesBetweenTheSpecificForceAndItsFrontDragEstimate) {
  constexpr double kFrontShare = 0.44;
  const Scenario s = testing::AtvHills(30.0);
  double level_n = 0.0, mass_kg = 0.0;
  double vv = 0.0, v_traction = 0.0, v_specific = 0.0, v_drag = 0.0;  // sums over the samples
  long samples = 0;
  Status measured = Status::Ok();
  SimulateOptions options;
  options.noise = false;
  options.observer = [&](Time, const mjModel* m, const mjData* d) {
    auto vehicle = AckermannVehicle::Bind(m, "atv");
    if (!vehicle.ok()) return;
    if (mass_kg == 0.0) {
      auto level = MeasureRearRoll(m, vehicle.value(), s.robot.speed_controller, "atv");
      if (!level.ok()) measured = level.status();
      level_n = level.ok() ? level.value().traction_n : 0.0;
      mass_kg = vehicle.value().mass_kg();
    }
    // O's velocity and specific force in O ([angular, linear]; mj_rnePostConstraint has run for the sensors).
    mjtNum velocity[6], acceleration[6];
    mj_objectVelocity(m, d, mjOBJ_SITE, vehicle.value().odom_site(), velocity, 1);
    mj_objectAcceleration(m, d, mjOBJ_SITE, vehicle.value().odom_site(), acceleration, 1);
    const double v_mps = velocity[3], a_y_mps2 = velocity[3] * velocity[2];
    vv += v_mps * v_mps;
    v_traction += v_mps * (RearTractionN(m, d) - level_n) / mass_kg;
    v_specific += v_mps * acceleration[3];
    v_drag += v_mps * kFrontShare * a_y_mps2 * std::tan(vehicle.value().SteeringAngle(d));
    ++samples;
  };
  auto sim = Simulate(s, options);
  ASSERT_TRUE(sim.ok()) << sim.status().message();
  ASSERT_TRUE(measured.ok()) << measured.message();
  ASSERT_GT(mass_kg, 0.0);
  EXPECT_GT(v_traction, v_specific);
  EXPECT_LT(v_traction, v_specific + v_drag);
  const double n = static_cast<double>(samples);
  std::printf(
      "weave, %ld samples: <v^2> %.3f m^2/s^2; <v (F - F_level)/m> %+.4f, <v f_x> %+.4f, "
      "<v (f_x + %.2f a_y tan(delta))> %+.4f m^2/s^3 (F_level %.1f N, m %.1f kg)\n",
      samples, vv / n, v_traction / n, v_specific / n, kFrontShare, (v_specific + v_drag) / n, level_n, mass_kg);
}

// A short straight roll of the scenario on a flat floor, simulated: O's travel over the rear wheels' rotation is the
// travel per radian truth.yaml's kv/L states (over its geometric value, times the tire radius), and it lies below the
// tire's radius by half the rear tires' penetration (MuJoCo's contact point is midway through it).
TEST(RollingRadiusTest, TheAtvsKvOverLTruthIsTheRearTiresTravelPerRadian) {
  Scenario s = testing::AtvHills(6.0);
  s.terrain.type = TerrainOptions::Type::kFlat;
  s.driver.speed_mps = Profile::Constant(2.0);
  s.driver.handlebar_rad = Profile::Constant(0.0);
  constexpr double kFromS = 2.0;  // the speed controller has settled
  struct Roll {
    Eigen::Vector3d first_m = Eigen::Vector3d::Zero(), last_m = Eigen::Vector3d::Zero();
    double first_rad = 0.0, last_rad = 0.0, penetration_m = 0.0;
    int contacts = 0;
    bool started = false;
  } roll;
  SimulateOptions options;
  options.noise = false;
  options.observer = [&roll](Time t, const mjModel* m, const mjData* d) {
    if (t.seconds() < kFromS) return;
    const Eigen::Vector3d p(d->site_xpos + 3 * IdOf(m, mjOBJ_SITE, "odom"));
    const double angle_rad = 0.5 * (d->qpos[m->jnt_qposadr[IdOf(m, mjOBJ_JOINT, "wheel_rear_left")]] +
                                    d->qpos[m->jnt_qposadr[IdOf(m, mjOBJ_JOINT, "wheel_rear_right")]]);
    if (!roll.started) {
      roll.first_m = p;
      roll.first_rad = angle_rad;
      roll.started = true;
    }
    roll.last_m = p;
    roll.last_rad = angle_rad;
    const int left = IdOf(m, mjOBJ_GEOM, "tire_rear_left"), right = IdOf(m, mjOBJ_GEOM, "tire_rear_right");
    for (int i = 0; i < d->ncon; ++i) {
      const mjContact& c = d->contact[i];
      if (c.geom1 != left && c.geom2 != left && c.geom1 != right && c.geom2 != right) continue;
      roll.penetration_m -= c.dist;
      ++roll.contacts;
    }
  };
  auto sim = Simulate(s, options);
  ASSERT_TRUE(sim.ok()) << sim.status().message();
  const double travel_per_rad_m = (roll.last_m - roll.first_m).norm() / (roll.last_rad - roll.first_rad);
  const double penetration_m = roll.penetration_m / roll.contacts;

  const auto& truth = sim.value().truth.calibration;
  ASSERT_TRUE(truth.count("odometer.kv_over_L") && truth.count("odometer.kv_over_L_geometric"));
  EXPECT_EQ(truth.at("odometer.kv_over_L_geometric")[0], s.sensors.odometer->kv_over_L);
  const double radius_m = 0.28;  // models/atv.xml's tires
  const double stated_m = radius_m * truth.at("odometer.kv_over_L")[0] / truth.at("odometer.kv_over_L_geometric")[0];
  // Both measure the same roll, over windows a few revolutions long: a micrometre apart against a 0.35 mm sink.
  EXPECT_NEAR(stated_m, travel_per_rad_m, 2e-6);
  EXPECT_NEAR(radius_m - stated_m, 0.5 * penetration_m, 1e-5);
  EXPECT_GT(penetration_m, 5e-4);  // solimp's 1 mm width under 1.8 kN per rear tire
  std::printf("ATV: stated %.6f m per rad, rolled %.6f, sink %.3f mm, rear tires' penetration %.3f mm\n", stated_m,
              travel_per_rad_m, 1e3 * (radius_m - stated_m), 1e3 * penetration_m);
}

}  // namespace
}  // namespace roamlab::sim
