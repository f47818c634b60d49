#include "experiment/drive_family.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "experiment/design.h"
#include "sim/drive_envelope.h"

namespace roamlab::experiment {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegPerRad = 180.0 / kPi;
// The Ackermann speed term's phase: a quarter turn (slowest where the handlebar is turned most), as written.
constexpr double kSpeedPhaseRad = 1.570796327;
// The holonomic sideways term's phase [rad], so that it does not start with the forward speed's sine.
constexpr double kLateralPhaseRad = 1.0;

// `value` to a multiple of `step`, as its text reads back (10 digits), so that the drive analysed is the one written.
double Round(double value, double step) {
  std::ostringstream out;
  out << std::setprecision(10) << std::round(value / step) * step;
  return std::stod(out.str());
}

double Fraction(double value, double low, double high) {
  return high > low ? std::clamp((value - low) / (high - low), 0.0, 1.0) : 0.0;
}

double Between(double u, double low, double high) { return low + u * (high - low); }

// An offset o within +-(limit - amplitude) as u in [0, 1] (0.5: none), and back.
double OffsetFraction(double offset, double amplitude, double limit) {
  const double room = limit - amplitude;
  return room > 0.0 ? std::clamp(0.5 + 0.5 * offset / room, 0.0, 1.0) : 0.5;
}
double Offset(double u, double amplitude, double limit) { return (2.0 * u - 1.0) * (limit - amplitude); }

// The room a mean leaves in [low, high] for a swing either way.
double SwingRoom(double mean, double low, double high) { return std::min(mean - low, high - mean); }

sim::ProfileTerm Constant(double value) {
  sim::ProfileTerm t;
  t.type = sim::ProfileTerm::Type::kConstant;
  t.value = value;
  return t;
}

sim::ProfileTerm Sine(double amplitude, double period_s, double phase_rad) {
  sim::ProfileTerm t;
  t.type = sim::ProfileTerm::Type::kSine;
  t.amplitude = amplitude;
  t.period_s = period_s;
  t.phase_rad = phase_rad;
  return t;
}

// A profile's constant terms summed and its first sine's |amplitude| and period (0 and `period_s` when none).
struct ProfileShape {
  double constant = 0.0, amplitude = 0.0, period_s = 0.0;
};
ProfileShape Shape(const sim::Profile& profile, double period_s) {
  ProfileShape s;
  s.period_s = period_s;
  bool sine = false;
  for (const sim::ProfileTerm& t : profile.terms) {
    if (t.type == sim::ProfileTerm::Type::kConstant) s.constant += t.value;
    if (t.type != sim::ProfileTerm::Type::kSine || sine) continue;
    s.amplitude = std::abs(t.amplitude);
    s.period_s = t.period_s;
    sine = true;
  }
  return s;
}

std::string Number(double value, int precision) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(precision) << value;
  return out.str();
}

// The speed and handlebar weave of an Ackermann vehicle (the header comment).
class AckermannFamily : public DriveFamily {
 public:
  explicit AckermannFamily(const DesignLimits& l) : l_(l) {}
  int dimension() const override { return 6; }
  // The handlebar's amplitude and period first (the steering range excites most parameters), the heading last.
  std::vector<int> SearchOrder() const override { return {2, 3, 0, 1, 4, 5}; }
  int Wrapping() const override { return 5; }
  // Start headings turned by 0, 90, 180, 270 deg and handlebar offsets at a quarter, none and three quarters.
  std::vector<std::vector<double>> Grid(const std::vector<double>& start) const override {
    std::vector<std::vector<double>> out;
    for (double heading_deg : {0.0, 90.0, 180.0, 270.0})
      for (double offset : {0.5, 0.25, 0.75}) {
        std::vector<double> u = start;
        u[4] = offset;
        u[5] = std::fmod(u[5] + heading_deg / 360.0, 1.0);
        out.push_back(u);
      }
    return out;
  }
  DriveDesign FromCoordinates(const std::vector<double>& u) const override {
    const double mean = Between(u[0], l_.min_speed_mps, l_.max_speed_mps);
    const double amplitude = u[2] * l_.max_handlebar_rad;
    DriveDesign d;
    d.values["speed_mean_mps"] = Round(mean, 0.01);
    d.values["speed_swing_mps"] = Round(u[1] * SwingRoom(mean, l_.min_speed_mps, l_.max_speed_mps), 0.01);
    d.values["handlebar_amplitude_rad"] = Round(amplitude, 0.001);
    d.values["handlebar_period_s"] = Round(Between(u[3], l_.min_period_s, l_.max_period_s), 0.01);
    d.values["handlebar_offset_rad"] = Round(Offset(u[4], amplitude, l_.max_handlebar_rad), 0.001);
    d.values["heading_deg"] = Round(std::fmod(std::fmod(360.0 * u[5], 360.0) + 360.0, 360.0), 0.1);
    return d;
  }
  std::vector<double> ToCoordinates(const DriveDesign& d) const override {
    std::vector<double> u(6);
    u[0] = Fraction(d.at("speed_mean_mps"), l_.min_speed_mps, l_.max_speed_mps);
    const double mean = Between(u[0], l_.min_speed_mps, l_.max_speed_mps);
    u[1] = Fraction(d.at("speed_swing_mps"), 0.0, SwingRoom(mean, l_.min_speed_mps, l_.max_speed_mps));
    u[2] = Fraction(d.at("handlebar_amplitude_rad"), 0.0, l_.max_handlebar_rad);
    u[3] = Fraction(d.at("handlebar_period_s"), l_.min_period_s, l_.max_period_s);
    u[4] = OffsetFraction(d.at("handlebar_offset_rad"), u[2] * l_.max_handlebar_rad, l_.max_handlebar_rad);
    u[5] = std::fmod(std::fmod(d.at("heading_deg"), 360.0) + 360.0, 360.0) / 360.0;
    return u;
  }
  DriveDesign StartDrive(const sim::Scenario& scenario) const override {
    const ProfileShape speed = Shape(scenario.driver.speed_mps, 0.0);
    const ProfileShape handlebar = Shape(scenario.driver.handlebar_rad, 10.0);
    DriveDesign d;
    d.values = {{"speed_mean_mps", speed.constant},
                {"speed_swing_mps", speed.amplitude},
                {"handlebar_amplitude_rad", handlebar.amplitude},
                {"handlebar_period_s", handlebar.period_s},
                {"handlebar_offset_rad", handlebar.constant},
                {"heading_deg", scenario.robot.start_heading_rad * kDegPerRad}};
    return FromCoordinates(ToCoordinates(d));
  }
  std::vector<std::pair<std::string, sim::Profile>> Profiles(const DriveDesign& d) const override {
    const double period_s = d.at("handlebar_period_s");
    return {{"speed_mps",
             {{Constant(d.at("speed_mean_mps")), Sine(d.at("speed_swing_mps"), 0.5 * period_s, kSpeedPhaseRad)}}},
            {"handlebar_rad",
             {{Constant(d.at("handlebar_offset_rad")), Sine(d.at("handlebar_amplitude_rad"), period_s, 0.0)}}}};
  }
  double HeadingDeg(const sim::Scenario&, const DriveDesign& d) const override { return d.at("heading_deg"); }
  std::string Formula() const override {
    return "speed = v0 + dv cos(4 pi t / P), handlebar = d0 + da sin(2 pi t / P), start heading h";
  }
  std::string Describe(const DriveDesign& d) const override {
    const std::string period = Number(d.at("handlebar_period_s"), 2);
    return "speed " + Number(d.at("speed_mean_mps"), 2) + " + " + Number(d.at("speed_swing_mps"), 2) +
           " cos(4 pi t / " + period + ") m/s, handlebar " + Number(d.at("handlebar_offset_rad"), 3) + " + " +
           Number(d.at("handlebar_amplitude_rad"), 3) + " sin(2 pi t / " + period + ") rad, heading " +
           Number(d.at("heading_deg"), 1) + " deg";
  }

 private:
  DesignLimits l_;
};

// The forward, yaw-rate and (holonomic) sideways sines of an indoor robot (the header comment).
class BodyVelocityFamily : public DriveFamily {
 public:
  BodyVelocityFamily(const DesignLimits& l, bool holonomic) : l_(l), holonomic_(holonomic) {}
  int dimension() const override { return holonomic_ ? 8 : 6; }
  // The yaw rate's amplitude and period first (they excite the track and the IMU), then the forward speed's.
  std::vector<int> SearchOrder() const override {
    std::vector<int> order = {2, 3, 5, 0, 1, 4};
    if (holonomic_) order.insert(order.end(), {6, 7});
    return order;
  }
  // Forward means at the start's, a quarter and three quarters of the range; yaw offsets none, negative, positive.
  std::vector<std::vector<double>> Grid(const std::vector<double>& start) const override {
    std::vector<std::vector<double>> out;
    for (double mean : {start[0], 0.25, 0.75})
      for (double offset : {0.5, 0.25, 0.75}) {
        std::vector<double> u = start;
        u[0] = mean;
        u[4] = offset;
        out.push_back(u);
      }
    return out;
  }
  DriveDesign FromCoordinates(const std::vector<double>& u) const override {
    const double mean = Between(u[0], l_.min_speed_mps, l_.max_speed_mps);
    const double yaw_amplitude = u[2] * l_.max_yaw_rate_radps;
    DriveDesign d;
    d.values["linear_mean_mps"] = Round(mean, 0.01);
    d.values["linear_swing_mps"] = Round(u[1] * SwingRoom(mean, l_.min_speed_mps, l_.max_speed_mps), 0.01);
    d.values["yaw_rate_amplitude_radps"] = Round(yaw_amplitude, 0.001);
    d.values["yaw_rate_period_s"] = Round(Between(u[3], l_.min_period_s, l_.max_period_s), 0.01);
    d.values["yaw_rate_offset_radps"] = Round(Offset(u[4], yaw_amplitude, l_.max_yaw_rate_radps), 0.001);
    d.values["linear_period_s"] = Round(Between(u[5], l_.min_period_s, l_.max_period_s), 0.01);
    if (!holonomic_) return d;
    d.values["lateral_amplitude_mps"] = Round(u[6] * l_.max_lateral_mps, 0.01);
    d.values["lateral_period_s"] = Round(Between(u[7], l_.min_period_s, l_.max_period_s), 0.01);
    return d;
  }
  std::vector<double> ToCoordinates(const DriveDesign& d) const override {
    std::vector<double> u(static_cast<std::size_t>(dimension()));
    u[0] = Fraction(d.at("linear_mean_mps"), l_.min_speed_mps, l_.max_speed_mps);
    const double mean = Between(u[0], l_.min_speed_mps, l_.max_speed_mps);
    u[1] = Fraction(d.at("linear_swing_mps"), 0.0, SwingRoom(mean, l_.min_speed_mps, l_.max_speed_mps));
    u[2] = Fraction(d.at("yaw_rate_amplitude_radps"), 0.0, l_.max_yaw_rate_radps);
    u[3] = Fraction(d.at("yaw_rate_period_s"), l_.min_period_s, l_.max_period_s);
    u[4] = OffsetFraction(d.at("yaw_rate_offset_radps"), u[2] * l_.max_yaw_rate_radps, l_.max_yaw_rate_radps);
    u[5] = Fraction(d.at("linear_period_s"), l_.min_period_s, l_.max_period_s);
    if (!holonomic_) return u;
    u[6] = Fraction(d.at("lateral_amplitude_mps"), 0.0, l_.max_lateral_mps);
    u[7] = Fraction(d.at("lateral_period_s"), l_.min_period_s, l_.max_period_s);
    return u;
  }
  DriveDesign StartDrive(const sim::Scenario& scenario) const override {
    const ProfileShape linear = Shape(scenario.driver.linear_mps, l_.min_period_s);
    const ProfileShape yaw = Shape(scenario.driver.angular_radps, l_.min_period_s);
    const ProfileShape lateral = Shape(scenario.driver.lateral_mps, l_.min_period_s);
    DriveDesign d;
    d.values = {{"linear_mean_mps", linear.constant},         {"linear_swing_mps", linear.amplitude},
                {"linear_period_s", linear.period_s},         {"yaw_rate_amplitude_radps", yaw.amplitude},
                {"yaw_rate_period_s", yaw.period_s},          {"yaw_rate_offset_radps", yaw.constant},
                {"lateral_amplitude_mps", lateral.amplitude}, {"lateral_period_s", lateral.period_s}};
    return FromCoordinates(ToCoordinates(d));
  }
  std::vector<std::pair<std::string, sim::Profile>> Profiles(const DriveDesign& d) const override {
    std::vector<std::pair<std::string, sim::Profile>> out = {
        {"linear_mps",
         {{Constant(d.at("linear_mean_mps")), Sine(d.at("linear_swing_mps"), d.at("linear_period_s"), 0.0)}}},
        {"angular_radps",
         {{Constant(d.at("yaw_rate_offset_radps")),
           Sine(d.at("yaw_rate_amplitude_radps"), d.at("yaw_rate_period_s"), 0.0)}}}};
    if (holonomic_)
      out.push_back(
          {"lateral_mps", {{Sine(d.at("lateral_amplitude_mps"), d.at("lateral_period_s"), kLateralPhaseRad)}}});
    return out;
  }
  double HeadingDeg(const sim::Scenario& scenario, const DriveDesign&) const override {
    return Round(scenario.robot.start_heading_rad * kDegPerRad, 0.1);
  }
  std::string Formula() const override {
    return std::string("forward = v0 + dv sin(2 pi t / Pv), yaw rate = w0 + wa sin(2 pi t / Pw)") +
           (holonomic_ ? ", sideways = ua sin(2 pi t / Pu + 1)" : "");
  }
  std::string Describe(const DriveDesign& d) const override {
    std::string out = "forward " + Number(d.at("linear_mean_mps"), 2) + " + " + Number(d.at("linear_swing_mps"), 2) +
                      " sin(2 pi t / " + Number(d.at("linear_period_s"), 2) + ") m/s, yaw rate " +
                      Number(d.at("yaw_rate_offset_radps"), 3) + " + " + Number(d.at("yaw_rate_amplitude_radps"), 3) +
                      " sin(2 pi t / " + Number(d.at("yaw_rate_period_s"), 2) + ") rad/s";
    if (holonomic_)
      out += ", sideways " + Number(d.at("lateral_amplitude_mps"), 2) + " sin(2 pi t / " +
             Number(d.at("lateral_period_s"), 2) + " + 1) m/s";
    return out;
  }

 private:
  DesignLimits l_;
  bool holonomic_;
};

}  // namespace

Result<std::unique_ptr<DriveFamily>> MakeDriveFamily(const sim::Scenario& scenario, const DesignLimits& limits) {
  if (scenario.driver.type == "ackermann") return std::unique_ptr<DriveFamily>(new AckermannFamily(limits));
  if (scenario.driver.type == "body_velocity") {
    auto envelope = sim::DesignEnvelope(scenario.robot.kind);
    if (!envelope.ok()) return envelope.status();
    return std::unique_ptr<DriveFamily>(new BodyVelocityFamily(limits, envelope.value().max_lateral_mps > 0.0));
  }
  return Status::Error("driver.type: no drive family for a " + scenario.driver.type +
                       " driver (ackermann, body_velocity)");
}

sim::Scenario WithDrive(const DriveFamily& family, const sim::Scenario& scenario, const DriveDesign& drive) {
  sim::Scenario out = scenario;
  out.robot.start_heading_rad = family.HeadingDeg(scenario, drive) / kDegPerRad;
  for (const auto& [key, profile] : family.Profiles(drive)) {
    if (key == "speed_mps") out.driver.speed_mps = profile;
    if (key == "handlebar_rad") out.driver.handlebar_rad = profile;
    if (key == "linear_mps") out.driver.linear_mps = profile;
    if (key == "angular_radps") out.driver.angular_radps = profile;
    if (key == "lateral_mps") out.driver.lateral_mps = profile;
  }
  return out;
}

}  // namespace roamlab::experiment
