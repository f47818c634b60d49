// The evaluation (eval/evaluate.h) end to end on hand-written recording and estimate directories.
#include "eval/evaluate.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "tests/recording/temp_dir.h"
#include "tests/support/html_check.h"

namespace roamlab::eval {
namespace {

using nlohmann::json;
using ::roamlab::testing::ReadFile;
using ::roamlab::testing::TempDir;
using ::roamlab::testing::WriteFile;
using ::testing::HasSubstr;
using ::testing::StartsWith;

namespace fs = std::filesystem;

constexpr double kDeg = 180.0 / 3.14159265358979323846;

constexpr const char* kGpsYaml =
    "format_version: 1\n"
    "platform:\n"
    "  kind: ackermann\n"
    "origin: {latitude_deg: 45.47, longitude_deg: 9.23, altitude_m: 120.0}\n"
    "streams:\n"
    "  - name: gps\n"
    "    type: gps\n"
    "    rate_hz: 5\n";
constexpr const char* kGpsCsv =
    "t,latitude,longitude,altitude\n"
    "0.0,45.47,9.23,120.0\n"
    "0.2,45.47001,9.23,120.0\n";

constexpr const char* kImuYaml =
    "format_version: 1\n"
    "platform:\n"
    "  kind: differential_drive\n"
    "streams:\n"
    "  - name: imu\n"
    "    type: imu\n"
    "    rate_hz: 100\n";
constexpr const char* kImuCsv =
    "t,wx,wy,wz,ax,ay,az\n"
    "0.00,0,0,0.1,0,0,9.81\n"
    "0.01,0,0,0.1,0,0,9.81\n";

// 41 poses, 0.05 s apart: 2 m/s on a circle of radius 10 m, climbing 0.1 m/s.
Trajectory Truth() {
  Trajectory trajectory(41);
  for (int i = 0; i < 41; ++i) {
    const double t = 0.05 * i;
    const double yaw = 0.2 * t;
    trajectory[i].t = Time::FromSeconds(t);
    trajectory[i].p_world_body = Eigen::Vector3d(10.0 * std::sin(yaw), 10.0 - 10.0 * std::cos(yaw), 0.1 * t);
    trajectory[i].q_world_body = Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
  }
  return trajectory;
}

class EvaluateTest : public ::testing::Test {
 protected:
  // REC with a gps stream (default alignment none), ground truth and truth.yaml; EST = truth shifted by
  // (0.3, 0.4, 0) m, a diagonal covariance and a calibration.
  void WriteGpsCase() {
    fs::create_directories(rec_dir());
    fs::create_directories(est_dir());
    WriteFile(rec("recording.yaml"), kGpsYaml);
    WriteFile(rec("gps.csv"), kGpsCsv);
    ASSERT_TRUE(WriteTum(Truth(), rec("ground_truth.tum")).ok());
    WriteFile(rec("truth.yaml"),
              "calibration:\n  gps.lever_arm: [0.5, 0, 0.2]\n  imu.misalignment: [1, 0, 0, 0]\neffects: []\n");
    Trajectory estimate = Truth();
    for (StampedPose& pose : estimate) pose.p_world_body += Eigen::Vector3d(0.3, 0.4, 0.0);
    ASSERT_TRUE(WriteTum(estimate, est("trajectory.tum")).ok());
    std::string covariance = "t,xx,xy,xz,yx,yy,yz,zx,zy,zz\n";
    for (const StampedPose& pose : estimate) covariance += FormatSeconds(pose.t) + ",0.09,0,0,0,0.16,0,0,0,1\n";
    WriteFile(est("covariance.csv"), covariance);
    const Eigen::Quaterniond q(Eigen::AngleAxisd(2.0 / kDeg, Eigen::Vector3d::UnitZ()));
    WriteFile(
        est("calibration.json"),
        json({{"parameters",
               {{"gps.lever_arm", {{"estimate", {0.6, 0.0, 0.2}}, {"std", {0.1, 0.1, nullptr}}, {"manifold", "R3"}}},
                {"imu.misalignment",
                 {{"estimate", {q.w(), q.x(), q.y(), q.z()}}, {"std", {0.01, 0.01, 0.01}}, {"manifold", "S3"}}},
                {"foo.bar", {{"estimate", {1.0}}, {"std", {0.1}}, {"manifold", "R1"}}}}}})
            .dump());
  }

  EvaluateOptions Options() const {
    EvaluateOptions options;
    options.estimate_dir = est_dir();
    options.recording_dir = rec_dir();
    return options;
  }

  std::string rec_dir() const { return dir_.File("rec"); }
  std::string est_dir() const { return dir_.File("est"); }
  std::string out_dir() const { return dir_.File("out"); }
  std::string rec(const std::string& name) const { return rec_dir() + "/" + name; }
  std::string est(const std::string& name) const { return est_dir() + "/" + name; }

  // The error of Evaluate, "" (failing the test) when it succeeds.
  std::string EvaluateError(const EvaluateOptions& options) const {
    const Result<Evaluation> r = Evaluate(options);
    EXPECT_FALSE(r.ok());
    return r.ok() ? "" : r.status().message();
  }

  TempDir dir_;
};

TEST_F(EvaluateTest, MetricsOfAShiftedEstimateWithGps) {
  WriteGpsCase();
  const Result<Evaluation> r = Evaluate(Options());
  ASSERT_TRUE(r.ok()) << r.status().message();
  const json& m = r.value().metrics;
  for (const char* key : {"ate_m", "rpe_trans_m", "rpe_rot_deg", "nees_mean", "parameters", "association", "alignment",
                          "ate", "rpe", "rpe_distance", "nees"})
    EXPECT_TRUE(m.contains(key)) << key;
  // A gps stream: no alignment, so the 0.5 m shift is the ATE; RPE does not see a constant shift.
  EXPECT_EQ(m["alignment"]["kind"], "none");
  EXPECT_EQ(m["association"]["matched"], 41);
  EXPECT_NEAR(m["ate_m"].get<double>(), 0.5, 1e-9);
  EXPECT_NEAR(m["ate"]["max_m"].get<double>(), 0.5, 1e-9);
  EXPECT_NEAR(m["rpe_trans_m"].get<double>(), 0.0, 1e-9);
  EXPECT_NEAR(m["rpe_rot_deg"].get<double>(), 0.0, 1e-5);
  EXPECT_EQ(m["rpe"]["delta_poses"], 20);  // 1 s at 0.05 s
  EXPECT_EQ(m["rpe"]["pairs"], 21);
  // NEES: (0.3^2 / 0.09) + (0.4^2 / 0.16) = 2 at every pose.
  EXPECT_NEAR(m["nees_mean"].get<double>(), 2.0, 1e-9);
  EXPECT_EQ(m["nees"]["poses"], 41);
  EXPECT_EQ(m["nees"]["fraction_in_band"], 1.0);
  // Parameters with truth; foo.bar has none.
  const json& lever = m["parameters"]["gps.lever_arm"];
  EXPECT_EQ(lever["truth"], json({0.5, 0.0, 0.2}));
  EXPECT_NEAR(lever["error"][0].get<double>(), 0.1, 1e-12);
  EXPECT_NEAR(lever["error_over_std"][0].get<double>(), 1.0, 1e-10);
  EXPECT_TRUE(lever["std"][2].is_null());
  EXPECT_TRUE(lever["error_over_std"][2].is_null());
  const json& mis = m["parameters"]["imu.misalignment"];
  EXPECT_NEAR(mis["angle_error_deg"].get<double>(), 2.0, 1e-9);
  EXPECT_NEAR(mis["error"][2].get<double>(), 2.0 / kDeg, 1e-12);
  EXPECT_FALSE(m["parameters"].contains("foo.bar"));
  EXPECT_EQ(m["parameters_without_truth"], json({"foo.bar"}));
  // Figures' inputs: the gps fixes in ENU at the origin (the second one 1e-5 deg north: about 1.111 m).
  ASSERT_EQ(r.value().fixes.size(), 1u);
  EXPECT_LT(r.value().fixes[0].p_world[0].norm(), 1e-6);
  EXPECT_NEAR(r.value().fixes[0].p_world[1].y(), 1.1114, 1e-3);
  EXPECT_NEAR(r.value().fixes[0].p_world[1].x(), 0.0, 1e-6);
  EXPECT_EQ(r.value().sigma_world.size(), 41u);
  EXPECT_NEAR(r.value().sigma_world[0].y(), 0.4, 1e-12);
}

TEST_F(EvaluateTest, WithoutAbsoluteSensorTheRigidOffsetIsAlignedAway) {
  fs::create_directories(rec_dir());
  fs::create_directories(est_dir());
  WriteFile(rec("recording.yaml"), kImuYaml);
  WriteFile(rec("imu.csv"), kImuCsv);
  ASSERT_TRUE(WriteTum(Truth(), rec("ground_truth.tum")).ok());
  RigidTransform t;
  t.q_ref_est = Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d(0.2, 0.1, 1.0).normalized()));
  t.p_ref_est = Eigen::Vector3d(2.0, -1.0, 0.5);
  ASSERT_TRUE(WriteTum(TransformTrajectory(t, Truth()), est("trajectory.tum")).ok());

  const Result<Evaluation> r = Evaluate(Options());
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r.value().metrics["alignment"]["kind"], "se3");
  EXPECT_LT(r.value().metrics["ate_m"].get<double>(), 1e-6);
  EXPECT_FALSE(r.value().metrics.contains("nees_mean"));   // no covariance.csv
  EXPECT_FALSE(r.value().metrics.contains("parameters"));  // no calibration.json
  EvaluateOptions none = Options();
  none.alignment = AlignmentKind::kNone;
  EXPECT_GT(Evaluate(none).value().metrics["ate_m"].get<double>(), 1.0);
}

TEST_F(EvaluateTest, ANeesWithoutAbsoluteSensorCarriesAWarning) {
  WriteGpsCase();
  // With the gps stream the position is observable: no warning.
  Result<Evaluation> r = Evaluate(Options());
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_FALSE(r.value().metrics["nees"].contains("warning"));
  // The same estimate and covariance on a recording with an IMU only.
  fs::remove(rec("gps.csv"));
  WriteFile(rec("recording.yaml"), kImuYaml);
  WriteFile(rec("imu.csv"), kImuCsv);
  r = Evaluate(Options());
  ASSERT_TRUE(r.ok()) << r.status().message();
  ASSERT_TRUE(r.value().metrics.contains("nees_mean"));
  const std::string warning = r.value().metrics["nees"].value("warning", "");
  EXPECT_NE(warning.find("not observable from " + rec_dir()), std::string::npos) << warning;
  EXPECT_NE(warning.find("no gps, position or pose stream"), std::string::npos) << warning;
}

TEST_F(EvaluateTest, TheCommandPrintsTheNeesWarningAlsoWhenQuiet) {
  WriteGpsCase();
  const std::string command = std::string(ROAMLAB_BINARY) + " evaluate --estimate " + est_dir() + " --recording " +
                              rec_dir() + " --out " + out_dir() + " --no-plots --quiet";
  testing::CommandRun run = testing::RunCommand(command, dir_.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.err.find("warning"), std::string::npos) << run.err;
  fs::remove(rec("gps.csv"));
  WriteFile(rec("recording.yaml"), kImuYaml);
  WriteFile(rec("imu.csv"), kImuCsv);
  run = testing::RunCommand(command, dir_.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.out, "");
  EXPECT_EQ(run.err.rfind("roamlab evaluate: warning: ", 0), 0u) << run.err;
  EXPECT_NE(run.err.find("not observable from " + rec_dir()), std::string::npos) << run.err;
}

TEST_F(EvaluateTest, WritesMetricsJsonAndFigures) {
  WriteGpsCase();
  const Result<Evaluation> r = Evaluate(Options());
  ASSERT_TRUE(r.ok()) << r.status().message();
  const Result<WrittenEvaluation> w = WriteEvaluation(r.value(), out_dir());
  ASSERT_TRUE(w.ok()) << w.status().message();
  EXPECT_EQ(json::parse(ReadFile(out_dir() + "/metrics.json")), r.value().metrics);
  for (const char* script : {"trajectory.gp", "position_error.gp", "nees.gp"})
    EXPECT_TRUE(fs::exists(out_dir() + "/" + script)) << script;
  if (GnuplotAvailable()) {
    EXPECT_TRUE(w.value().note.empty());
    EXPECT_EQ(w.value().images.size(), 3u);
    for (const std::string& image : w.value().images) EXPECT_GT(fs::file_size(image), 1000u) << image;
  }
}

// report.html: well-formed, the headline first, the tables with their headers (the parameter table with the
// estimator's observability), and every drawn figure embedded as a PNG data: URI.
TEST_F(EvaluateTest, WritesAWellFormedReportWithTablesAndEmbeddedFigures) {
  WriteGpsCase();
  json calibration = json::parse(ReadFile(est("calibration.json")));
  calibration["parameters"]["gps.lever_arm"]["observability"] = "weak";
  WriteFile(est("calibration.json"), calibration.dump());
  const Result<Evaluation> r = Evaluate(Options());
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r.value().metrics["parameters"]["gps.lever_arm"]["observability"], "weak");
  const Result<WrittenEvaluation> w = WriteEvaluation(r.value(), out_dir());
  ASSERT_TRUE(w.ok()) << w.status().message();
  ASSERT_EQ(w.value().report_path, out_dir() + "/report.html");
  const std::string document = ReadFile(w.value().report_path);
  const testing::HtmlSummary html = testing::CheckHtml(document);
  ASSERT_EQ(html.error, "");
  EXPECT_LT(document.find("class=\"headline\">ATE 0.5 m"), document.find("<table>"));
  std::vector<std::string> first_headers;
  for (const auto& headers : html.table_headers) first_headers.push_back(headers.empty() ? "" : headers.front());
  EXPECT_THAT(first_headers,
              ::testing::ElementsAre("item", "parameter", "error", "position error [m]", "pairs", "mean"));
  EXPECT_THAT(html.table_headers[1], ::testing::ElementsAre("parameter", "manifold", "truth", "estimate", "std",
                                                            "error", "error / std", "observability"));
  EXPECT_THAT(document, HasSubstr("<td>weak</td>"));
  EXPECT_THAT(document, HasSubstr("1 of 2 parameters within 3 std of the truth"));
  ASSERT_EQ(html.image_sources.size(), w.value().images.size());
  if (GnuplotAvailable()) {
    EXPECT_EQ(html.image_sources.size(), 3u);
  }
  for (const std::string& src : html.image_sources) {
    ASSERT_THAT(src, StartsWith("data:image/png;base64,"));
    const std::optional<std::string> png = testing::DecodeBase64(src.substr(22));
    ASSERT_TRUE(png.has_value());
    EXPECT_EQ(png->substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  }
}

TEST_F(EvaluateTest, WithoutGnuplotMetricsAreStillWritten) {
  WriteGpsCase();
  const Result<Evaluation> r = Evaluate(Options());
  ASSERT_TRUE(r.ok());
  const std::string path = std::getenv("PATH") ? std::getenv("PATH") : "";
  ::setenv("PATH", "/nonexistent", 1);
  const Result<WrittenEvaluation> w = WriteEvaluation(r.value(), out_dir());
  ::setenv("PATH", path.c_str(), 1);
  ASSERT_TRUE(w.ok()) << w.status().message();
  EXPECT_THAT(w.value().note, HasSubstr("gnuplot not found"));
  EXPECT_TRUE(w.value().images.empty());
  EXPECT_TRUE(fs::exists(out_dir() + "/metrics.json"));
  EXPECT_FALSE(fs::exists(out_dir() + "/trajectory.png"));
}

// Real data: no ground truth, so the estimate is compared with the GPS fixes, moved to the antenna by the calibrated
// lever arm (0.6, 0, 0.2) m. At t = 0 (yaw 0) the estimate's antenna is at (0.3 + 0.6, 0.4, 0.2), the fix at the
// origin.
TEST_F(EvaluateTest, WithoutGroundTruthTheGpsFixesAreTheReference) {
  WriteGpsCase();
  fs::remove(rec("ground_truth.tum"));
  const Result<Evaluation> r = Evaluate(Options());
  ASSERT_TRUE(r.ok()) << r.status().message();
  const json& m = r.value().metrics;
  EXPECT_EQ(m["reference"]["kind"], "stream");
  EXPECT_EQ(m["reference"]["stream"], "gps");
  EXPECT_EQ(m["reference"]["orientation"], false);
  EXPECT_THAT(m["reference"]["lever_arm_source"].get<std::string>(), StartsWith("calibration ("));
  EXPECT_EQ(m["association"]["matched"], 2);
  EXPECT_NEAR(r.value().error_world[0].x(), 0.9, 1e-6);
  EXPECT_NEAR(r.value().error_world[0].y(), 0.4, 1e-6);
  EXPECT_NEAR(r.value().error_world[0].z(), 0.2, 1e-6);
  EXPECT_TRUE(m["ate_rot_deg"].is_null());
  EXPECT_TRUE(m["rpe"].contains("skipped"));
  EXPECT_EQ(r.value().reference_label, "GPS fixes (gps)");
  EXPECT_TRUE(r.value().fixes.empty());  // the reference stream is not drawn twice
  // Without the calibration the lever arm is ignored, and says so.
  fs::remove(est("calibration.json"));
  const Result<Evaluation> ignored = Evaluate(Options());
  ASSERT_TRUE(ignored.ok()) << ignored.status().message();
  EXPECT_EQ(ignored.value().metrics["reference"]["lever_arm_source"], "none: ignored");
  EXPECT_NEAR(ignored.value().error_world[0].x(), 0.3, 1e-6);
  // The figure exists now.
  const Result<WrittenEvaluation> w = WriteEvaluation(ignored.value(), out_dir());
  ASSERT_TRUE(w.ok()) << w.status().message();
  EXPECT_TRUE(fs::exists(out_dir() + "/trajectory.gp"));
  EXPECT_THAT(ReadFile(out_dir() + "/trajectory.gp"), HasSubstr("title \"GPS fixes (gps)\""));
  // A stream that cannot be a reference, and one that does not exist.
  EvaluateOptions imu = Options();
  imu.reference_stream = "imu";
  EXPECT_THAT(EvaluateError(imu), HasSubstr("no stream 'imu'"));
}

// A pose stream (motion capture of a marker body mounted 0.5 m ahead, turned 90 deg about z) as the reference: the
// estimate, moved to the marker by the mounting, matches it exactly, orientation included.
TEST_F(EvaluateTest, APoseStreamIsAReferenceThroughItsMounting) {
  fs::create_directories(rec_dir());
  fs::create_directories(est_dir());
  WriteFile(rec("recording.yaml"),
            std::string(kImuYaml) +
                "  - name: mocap\n"
                "    type: pose\n"
                "    rate_hz: 20\n"
                "    mounting: {p_body_sensor_m: [0.5, 0, 0], q_body_sensor_wxyz: [0.7071067811865476, "
                "0, 0, 0.7071067811865476]}\n");
  WriteFile(rec("imu.csv"), kImuCsv);
  const Eigen::Quaterniond q_body_sensor(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  std::string mocap = "t,x,y,z,qx,qy,qz,qw\n";
  for (const StampedPose& pose : Truth()) {
    const Eigen::Vector3d p = pose.p_world_body + pose.q_world_body * Eigen::Vector3d(0.5, 0.0, 0.0);
    const Eigen::Quaterniond q = pose.q_world_body * q_body_sensor;
    char row[256];
    std::snprintf(row, sizeof row, "%s,%.12f,%.12f,%.12f,%.12f,%.12f,%.12f,%.12f\n", FormatSeconds(pose.t).c_str(),
                  p.x(), p.y(), p.z(), q.x(), q.y(), q.z(), q.w());
    mocap += row;
  }
  WriteFile(rec("mocap.csv"), mocap);
  ASSERT_TRUE(WriteTum(Truth(), est("trajectory.tum")).ok());
  const Result<Evaluation> r = Evaluate(Options());  // no ground truth: the first absolute stream, mocap
  ASSERT_TRUE(r.ok()) << r.status().message();
  const json& m = r.value().metrics;
  EXPECT_EQ(m["reference"]["stream"], "mocap");
  EXPECT_EQ(m["reference"]["lever_arm_source"], "mounting in recording.yaml");
  EXPECT_LT(m["ate_m"].get<double>(), 1e-9);
  EXPECT_LT(m["ate_rot_deg"].get<double>(), 1e-6);
  EXPECT_LT(m["rpe_trans_m"].get<double>(), 1e-9);
}

TEST_F(EvaluateTest, MissingGroundTruthWithoutAbsoluteSensorIsAClearError) {
  fs::create_directories(rec_dir());
  fs::create_directories(est_dir());
  WriteFile(rec("recording.yaml"), kImuYaml);
  WriteFile(rec("imu.csv"), kImuCsv);
  ASSERT_TRUE(WriteTum(Truth(), est("trajectory.tum")).ok());
  EXPECT_EQ(EvaluateError(Options()), rec("ground_truth.tum") +
                                          ": missing, and the recording has no gps, position or pose stream to "
                                          "compare with");
  EvaluateOptions imu = Options();
  imu.reference_stream = "imu";
  EXPECT_THAT(EvaluateError(imu), HasSubstr("stream 'imu' is of type imu; a reference stream must be gps"));
}

TEST_F(EvaluateTest, BadInputsNameTheFile) {
  WriteGpsCase();
  // A broken covariance row.
  const std::string covariance = ReadFile(est("covariance.csv"));
  WriteFile(est("covariance.csv"), "t,xx,xy,xz,yx,yy,yz,zx,zy,zz\n0.0,1,2\n");
  EXPECT_THAT(EvaluateError(Options()), StartsWith(est("covariance.csv") + ":2: expected 10 fields"));
  WriteFile(est("covariance.csv"), covariance);
  // Stamps that match nothing.
  Trajectory late = Truth();
  for (StampedPose& pose : late) pose.t = Time::FromNanoseconds(pose.t.nanoseconds() + 1'000'000'000'000);
  ASSERT_TRUE(WriteTum(late, est("trajectory.tum")).ok());
  EXPECT_THAT(EvaluateError(Options()), StartsWith(est("trajectory.tum") + ": no pose within 0.01 s"));
  // A truth that does not fit the estimate.
  ASSERT_TRUE(WriteTum(Truth(), est("trajectory.tum")).ok());
  WriteFile(rec("truth.yaml"), "calibration:\n  gps.lever_arm: [0.5, 0]\n");
  EXPECT_THAT(EvaluateError(Options()), HasSubstr("parameter 'gps.lever_arm': truth has 2 values"));
  // No trajectory at all.
  fs::remove(est("trajectory.tum"));
  EXPECT_THAT(EvaluateError(Options()), StartsWith(est("trajectory.tum") + ": missing"));
  // Options.
  EvaluateOptions bad = Options();
  bad.rpe_distance_m = 0.0;
  EXPECT_THAT(EvaluateError(bad), HasSubstr("rpe_distance_m"));
}

}  // namespace
}  // namespace roamlab::eval
