// The Ackermann vehicle (sim/ackermann.h): steering geometry, the speed controller, and the binding to MJCF models.
#include "sim/ackermann.h"

#include <cmath>

#include <gtest/gtest.h>

#include "sim/mujoco_model.h"
#include "tests/sim/sim_testing.h"

namespace roamlab::sim {
namespace {

constexpr double kL = 1.25;
constexpr double kTrack = 0.95;

TEST(AckermannGeometryTest, InnerWheelSteersMoreAndBothShareTheBicycleTurningCentre) {
  for (double delta : {-0.5, -0.2, -0.01, 0.01, 0.2, 0.5}) {
    double left = 0.0, right = 0.0;
    AckermannWheelAngles(delta, kL, kTrack, &left, &right);
    // The wheel on the inside of the turn (left for a left turn) steers more than the bicycle, the outer one less.
    const double inner = delta > 0 ? left : right;
    const double outer = delta > 0 ? right : left;
    EXPECT_GT(std::abs(inner), std::abs(delta));
    EXPECT_LT(std::abs(outer), std::abs(delta));
    // Turning centre on the rear-axle line at R = L / tan(delta) from O, to the left for positive R.
    const double radius = kL / std::tan(delta);
    EXPECT_NEAR(kL / std::tan(left), radius - 0.5 * kTrack, 1e-9) << delta;
    EXPECT_NEAR(kL / std::tan(right), radius + 0.5 * kTrack, 1e-9) << delta;
  }
  double left = 1.0, right = 1.0;
  AckermannWheelAngles(0.0, kL, kTrack, &left, &right);
  EXPECT_EQ(left, 0.0);
  EXPECT_EQ(right, 0.0);
}

TEST(AckermannGeometryTest, BicycleEquivalentAngleInvertsTheWheelAngles) {
  for (double delta = -0.6; delta <= 0.6; delta += 0.05) {
    double left = 0.0, right = 0.0;
    AckermannWheelAngles(delta, kL, kTrack, &left, &right);
    EXPECT_NEAR(BicycleEquivalentAngle(left, right), delta, 1e-12) << delta;
  }
  // Wheels toed to opposite sides (never an Ackermann pair): the mean.
  EXPECT_NEAR(BicycleEquivalentAngle(0.01, -0.03), -0.01, 1e-15);
}

TEST(SpeedControllerTest, ProportionalIntegralWithAntiWindup) {
  SpeedControllerOptions options;
  options.kp_nm_per_mps = 100.0;
  options.ki_nm_per_m = 50.0;
  options.torque_limit_nm = 300.0;
  ASSERT_EQ(options.Validate(), "");
  SpeedController controller(options);
  // Unsaturated: kp e + ki (integral of e).
  EXPECT_NEAR(controller.Update(1.0, 0.0, 0.1), 100.0 + 50.0 * 0.1, 1e-12);
  // A long saturated stretch does not wind the integral up ...
  for (int i = 0; i < 1000; ++i) EXPECT_EQ(controller.Update(10.0, 0.0, 0.1), 300.0);
  // ... so the torque reverses as soon as the error does.
  EXPECT_LT(controller.Update(0.0, 1.0, 0.1), 0.0);
  options.torque_limit_nm = 0.0;
  EXPECT_NE(options.Validate().find("torque_limit_nm"), std::string::npos);
}

TEST(AckermannVehicleTest, MeasuresTheAtvModel) {
  auto model = LoadModelFromString(testing::ReadText(testing::SourcePath("models/atv.xml")));
  ASSERT_TRUE(model.ok()) << model.status().message();
  EXPECT_NEAR(mj_getTotalmass(model.value().get()), 354.0, 1e-9);
  EXPECT_DOUBLE_EQ(model.value()->opt.gravity[2], -9.80665);  // the estimator's kStandardGravity
  auto vehicle = AckermannVehicle::Bind(model.value().get(), "atv.xml");
  ASSERT_TRUE(vehicle.ok()) << vehicle.status().message();
  EXPECT_NEAR(vehicle.value().wheelbase_m(), 1.25, 1e-12);
  EXPECT_NEAR(vehicle.value().front_track_m(), 0.95, 1e-12);
  EXPECT_NEAR(vehicle.value().rear_track_m(), 0.95, 1e-12);
  EXPECT_NEAR(vehicle.value().wheel_radius_m(), 0.28, 1e-12);
  // The inner wheel reaches the 0.6 rad servo limit at this handlebar angle.
  double left = 0.0, right = 0.0;
  AckermannWheelAngles(vehicle.value().max_handlebar_rad(), 1.25, 0.95, &left, &right);
  EXPECT_NEAR(left, 0.6, 1e-12);
}

TEST(AckermannVehicleTest, MissingElementsAreNamed) {
  // A box with a free joint and the odometric site, but no wheels.
  auto model = LoadModelFromString(R"(<mujoco><worldbody><body name="b"><freejoint name="root"/>
      <site name="odom"/><geom type="box" size="1 0.5 0.2"/></body></worldbody></mujoco>)");
  ASSERT_TRUE(model.ok()) << model.status().message();
  auto vehicle = AckermannVehicle::Bind(model.value().get(), "box.xml");
  ASSERT_FALSE(vehicle.ok());
  EXPECT_NE(vehicle.status().message().find("box.xml"), std::string::npos);
  EXPECT_NE(vehicle.status().message().find("steer_left"), std::string::npos);

  // The odometric frame moved off the rear axle.
  std::string xml = testing::ReadText(testing::SourcePath("models/atv.xml"));
  const std::string site = "<site name=\"odom\" pos=\"0 0 0\"";
  ASSERT_NE(xml.find(site), std::string::npos);
  xml.replace(xml.find(site), site.size(), "<site name=\"odom\" pos=\"0.6 0 0\"");
  auto moved = LoadModelFromString(xml);
  ASSERT_TRUE(moved.ok()) << moved.status().message();
  auto bad = AckermannVehicle::Bind(moved.value().get(), "moved.xml");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("midpoint of the rear axle"), std::string::npos);
}

TEST(MujocoModelTest, CompilerErrorsComeBackAsOneLine) {
  auto model = LoadModelFromString("<mujoco><worldbody><geom type=\"nonsense\"/></worldbody></mujoco>", "bad.xml");
  ASSERT_FALSE(model.ok());
  const std::string& message = model.status().message();
  EXPECT_EQ(message.rfind("bad.xml: MuJoCo: ", 0), 0u) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

TEST(MujocoModelTest, ErrorHandlerThrowsInsteadOfWaitingForEnter) {
  InstallMujocoHandlers();
  EXPECT_THROW(mju_error("deliberate"), MujocoError);
  TakeMujocoWarnings();
  mju_warning("deliberate warning");
  const auto warnings = TakeMujocoWarnings();
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("deliberate warning"), std::string::npos);
}

}  // namespace
}  // namespace roamlab::sim
