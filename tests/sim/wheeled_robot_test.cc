// Deformed tires (sim/wheeled_robot.h, WheelDeformation): the deformation lives in the physics. The differential-drive
// robot of models/diffdrive.xml on a floor, both wheels driven at the same rate: the oval left tire lifts its axle
// twice per revolution by about ovality_m (the rolling radius varies with the wheel angle), its centre advances by the
// ellipse's mean rolling radius per radian, and the right tire stays round.
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include "sim/mujoco_model.h"
#include "sim/wheeled_robot.h"
#include "tests/sim/sim_testing.h"

namespace roamlab::sim {
namespace {

struct WheelTrace {
  std::vector<double> angle_rad;  // wheel angle
  std::vector<double> height_m;   // wheel centre above the floor
  double travel_m = 0.0;          // wheel centre's travel along the body's forward axis
};

// Drives models/diffdrive.xml (with `deformations`) straight at 0.3 m/s for `seconds` after a 0.5 s settle and traces
// both wheels.
std::vector<WheelTrace> DriveStraight(const std::vector<WheelDeformation>& deformations, double seconds,
                                      WheeledRobot* bound) {
  const std::map<std::string, std::string> files{
      {"robot.xml", testing::ReadText(testing::SourcePath("models/diffdrive.xml"))},
      {"world.xml",
       "<mujoco><include file=\"robot.xml\"/><worldbody><geom name=\"floor\" type=\"plane\" "
       "size=\"50 50 0.1\" contype=\"1\" conaffinity=\"1\" group=\"0\" friction=\"0.6\"/>"
       "</worldbody></mujoco>"}};
  auto model = LoadModelFromFiles("world.xml", files, "diffdrive");
  EXPECT_TRUE(model.ok()) << model.status().message();
  if (!model.ok()) return {};
  mjModel* m = model.value().get();
  auto robot = WheeledRobot::Bind(m, "differential_drive", "diffdrive");
  EXPECT_TRUE(robot.ok()) << robot.status().message();
  if (!robot.ok()) return {};
  Status deformed = robot.value().Deform(m, deformations, "diffdrive");
  EXPECT_TRUE(deformed.ok()) << deformed.message();
  *bound = robot.value();
  DataPtr data = MakeData(m);
  bound->Place(m, data.get(), 0.0, 0.0, 0.0, 0.005);
  const int bodies[2] = {IdOf(m, mjOBJ_BODY, "wheel_left"), IdOf(m, mjOBJ_BODY, "wheel_right")};
  const int settle = static_cast<int>(0.5 / m->opt.timestep);
  const int steps = static_cast<int>(seconds / m->opt.timestep);
  std::vector<WheelTrace> traces(2);
  for (int k = 0; k < settle + steps; ++k) {
    bound->Apply(k < settle ? 0.0 : 0.3, 0.0, 0.0, data.get());
    const Eigen::Vector3d before[2] = {Eigen::Vector3d(data->xpos + 3 * bodies[0]),
                                       Eigen::Vector3d(data->xpos + 3 * bodies[1])};
    mj_step(m, data.get());
    if (k < settle + 250) continue;  // 0.5 s to reach the speed
    const Eigen::Vector3d forward(data->xmat[9 * bound->root_body()], data->xmat[9 * bound->root_body() + 3], 0.0);
    for (int w = 0; w < 2; ++w) {
      const Eigen::Vector3d p(data->xpos + 3 * bodies[w]);
      traces[w].angle_rad.push_back(bound->WheelAngle(data.get(), w));
      traces[w].height_m.push_back(p.z());
      traces[w].travel_m += (p - before[w]).dot(forward.normalized());
    }
  }
  return traces;
}

// Least-squares fit of h(phi) = a + b cos 2 phi + c sin 2 phi: returns the peak-to-peak 2 sqrt(b^2 + c^2) and the RMS
// of the residual.
std::pair<double, double> TwicePerRevolution(const WheelTrace& trace) {
  const auto n = static_cast<Eigen::Index>(trace.angle_rad.size());
  Eigen::MatrixXd A(n, 3);
  Eigen::VectorXd h(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double phi = trace.angle_rad[static_cast<std::size_t>(k)];
    A.row(k) << 1.0, std::cos(2.0 * phi), std::sin(2.0 * phi);
    h[k] = trace.height_m[static_cast<std::size_t>(k)];
  }
  const Eigen::Vector3d x = A.colPivHouseholderQr().solve(h);
  return {2.0 * std::hypot(x[1], x[2]), std::sqrt((A * x - h).squaredNorm() / static_cast<double>(n))};
}

TEST(WheelDeformationTest, OvalTireRollingRadiusVariesWithWheelAngle) {
  constexpr double kOvality = 0.003;
  WheeledRobot robot;
  const std::vector<WheelTrace> traces = DriveStraight({{0, 1.0, kOvality}}, 4.0, &robot);
  ASSERT_EQ(traces.size(), 2u);
  // Over 4 s at 4 rad/s the wheels turn about 2.5 revolutions.
  const double turned = traces[0].angle_rad.back() - traces[0].angle_rad.front();
  ASSERT_GT(turned, 4.0 * M_PI);
  // The axle height follows the ellipse: between r and r + ovality, twice per revolution.
  const auto [left_p2p, left_rms] = TwicePerRevolution(traces[0]);
  const auto [right_p2p, right_rms] = TwicePerRevolution(traces[1]);
  EXPECT_NEAR(left_p2p, kOvality, 0.05 * kOvality) << "residual " << left_rms;
  EXPECT_LT(left_rms, 0.1 * kOvality);
  EXPECT_LT(right_p2p, 0.1 * kOvality);
  // Travel per radian: the ellipse's mean rolling radius on the left, the round tire's radius on the right. Both
  // tires sink the same into the soft contact, so their ratio is compared.
  const double left_radius = traces[0].travel_m / turned;
  const double right_radius = traces[1].travel_m / (traces[1].angle_rad.back() - traces[1].angle_rad.front());
  const double expected_ratio = robot.wheels()[0].mean_rolling_radius_m / robot.wheels()[1].mean_rolling_radius_m;
  EXPECT_GT(expected_ratio, 1.015);
  EXPECT_NEAR(left_radius / right_radius, expected_ratio, 0.001);
  // The nominal geometry (platform metadata and the driver) keeps the undeformed tire.
  EXPECT_DOUBLE_EQ(robot.wheels()[0].radius_m, 0.075);
  EXPECT_DOUBLE_EQ(robot.PlatformGeometry().at("wheel_radius_m"), 0.075);
}

TEST(WheelDeformationTest, RoundTireKeepsItsHeightAndBadDeformationsAreRefused) {
  WheeledRobot robot;
  const std::vector<WheelTrace> traces = DriveStraight({}, 2.0, &robot);
  ASSERT_EQ(traces.size(), 2u);
  EXPECT_LT(TwicePerRevolution(traces[0]).first, 0.0003);
  // A scaled tire: its mean rolling radius; a wheel that does not exist and an oval beyond half the radius are errors
  // naming the wheel.
  auto model = LoadModelFromString(testing::ReadText(testing::SourcePath("models/diffdrive.xml")), "diffdrive");
  ASSERT_TRUE(model.ok());
  auto bound = WheeledRobot::Bind(model.value().get(), "differential_drive", "diffdrive");
  ASSERT_TRUE(bound.ok());
  ASSERT_TRUE(bound.value().Deform(model.value().get(), {{1, 1.02, 0.0}}, "F").ok());
  EXPECT_NEAR(bound.value().wheels()[1].mean_rolling_radius_m, 0.0765, 1e-12);
  const Status missing = bound.value().Deform(model.value().get(), {{2, 1.0, 0.0}}, "F");
  EXPECT_EQ(missing.message(), "F: robot.wheel_deformation: wheel 2: the differential_drive robot has 2 wheels");
  EXPECT_FALSE(bound.value().Deform(model.value().get(), {{0, 1.0, 0.05}}, "F").ok());
}

}  // namespace
}  // namespace roamlab::sim
