// The evaluation (eval/evaluate.h) of plain trajectory files: known transforms recovered under noise, the same ATE as
// the directory form, time offset, alignment on part of the poses, KITTI by index, and several estimates compared.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>

#include <Eigen/Eigenvalues>

#include "eval/evaluate.h"
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

// 601 poses, 0.1 s apart: a figure-eight 40 m x 20 m over hills 3 m high (spread in all three axes, so that every
// rotation is determined).
Trajectory Drive() {
  Trajectory trajectory(601);
  for (int i = 0; i < 601; ++i) {
    const double t = 0.1 * i;
    const double a = 2.0 * M_PI * t / 60.0;
    trajectory[i].t = Time::FromSeconds(100.0 + t);
    trajectory[i].p_world_body = Eigen::Vector3d(20.0 * std::sin(a), 10.0 * std::sin(2.0 * a), 3.0 * std::cos(3.0 * a));
    const double yaw = std::atan2(20.0 * std::cos(2.0 * a), 20.0 * std::cos(a));
    trajectory[i].q_world_body = Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
  }
  return trajectory;
}

class EvaluateFilesTest : public ::testing::Test {
 protected:
  std::string File(const std::string& name) const { return dir_.File(name); }
  EvaluateOptions Options(const std::string& reference, const std::string& estimate) const {
    EvaluateOptions options;
    options.reference_file = File(reference);
    options.estimate_dir = File(estimate);
    return options;
  }
  Evaluation MustEvaluate(const EvaluateOptions& options) const {
    const Result<Evaluation> r = Evaluate(options);
    EXPECT_TRUE(r.ok()) << r.status().message();
    return r.ok() ? r.value() : Evaluation();
  }
  std::string Error(const EvaluateOptions& options) const {
    const Result<Evaluation> r = Evaluate(options);
    EXPECT_FALSE(r.ok());
    return r.ok() ? "" : r.status().message();
  }
  TempDir dir_;
};

// The reference is the drive with N(0, sigma) noise on every coordinate; the estimate is the noise-free drive seen
// from another frame, smaller by `scale`: p_est = T^-1 p_true. Alignment must recover T within what the noise allows:
// the rotation's standard deviation about its worst axis is sqrt(max eig(sigma^2 (sum |a|^2 I - a a^T)^-1)) with a
// the centred points of T applied to the estimate, the scale's sigma / sqrt(sum |a|^2) (relative), the centroid's
// sigma / sqrt(N) per axis. Bounds are five standard deviations.
void ExpectRecovered(AlignmentKind kind, double scale, unsigned seed, const std::string& dir) {
  const double sigma = 0.05;
  RigidTransform truth;
  truth.q_ref_est = Eigen::Quaterniond(Eigen::AngleAxisd(0.8, Eigen::Vector3d(0.3, -0.2, 1.0).normalized()));
  truth.p_ref_est = Eigen::Vector3d(12.0, -4.0, 2.0);
  truth.scale = scale;
  const Trajectory drive = Drive();
  Trajectory reference = drive, estimate = drive;
  std::mt19937_64 random(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  for (std::size_t i = 0; i < drive.size(); ++i) {
    reference[i].p_world_body += Eigen::Vector3d(noise(random), noise(random), noise(random));
    estimate[i].p_world_body = truth.q_ref_est.conjugate() * (drive[i].p_world_body - truth.p_ref_est) / truth.scale;
    estimate[i].q_world_body = truth.q_ref_est.conjugate() * drive[i].q_world_body;
  }
  ASSERT_TRUE(WriteTum(reference, dir + "/gt.tum").ok());
  ASSERT_TRUE(WriteTum(estimate, dir + "/est.txt").ok());
  EvaluateOptions options;
  options.reference_file = dir + "/gt.tum";
  options.estimate_dir = dir + "/est.txt";
  options.alignment = kind;
  const Result<Evaluation> r = Evaluate(options);
  ASSERT_TRUE(r.ok()) << r.status().message();
  const json& a = r.value().metrics["alignment"];

  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const StampedPose& p : drive) mean += p.p_world_body;
  mean /= static_cast<double>(drive.size());
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
  double spread = 0.0;
  for (const StampedPose& p : drive) {
    const Eigen::Vector3d c = p.p_world_body - mean;
    information += (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose()) / (sigma * sigma);
    spread += c.squaredNorm();
  }
  const double sigma_rotation = std::sqrt(information.inverse().eigenvalues().real().maxCoeff());
  const Eigen::Quaterniond q(a["q_ref_est_wxyz"][0].get<double>(), a["q_ref_est_wxyz"][1].get<double>(),
                             a["q_ref_est_wxyz"][2].get<double>(), a["q_ref_est_wxyz"][3].get<double>());
  EXPECT_LT(q.angularDistance(truth.q_ref_est), 5.0 * sigma_rotation);
  EXPECT_NEAR(a["scale"].get<double>() / scale, 1.0,
              kind == AlignmentKind::kSim3 ? 5.0 * sigma / std::sqrt(spread) : 0);
  // Where the estimate's centroid lands.
  RigidTransform found;
  found.q_ref_est = q;
  found.scale = a["scale"].get<double>();
  found.p_ref_est = Eigen::Vector3d(a["p_ref_est_m"][0].get<double>(), a["p_ref_est_m"][1].get<double>(),
                                    a["p_ref_est_m"][2].get<double>());
  const Eigen::Vector3d centroid_est = truth.q_ref_est.conjugate() * (mean - truth.p_ref_est) / scale;
  EXPECT_LT((found.Apply(centroid_est) - mean).norm(), 5.0 * std::sqrt(3.0) * sigma / std::sqrt(drive.size()));
  // The ATE is the noise: its mean square 3 sigma^2, within five standard deviations of a mean of 3N squares.
  const double ate = r.value().metrics["ate_m"].get<double>();
  EXPECT_NEAR(ate * ate / (3.0 * sigma * sigma), 1.0, 5.0 * std::sqrt(2.0 / (3.0 * drive.size())));
  // Orientations were not perturbed: the rotation ATE is the alignment's rotation error alone.
  EXPECT_LT(r.value().metrics["ate_rot_deg"].get<double>(), 5.0 * sigma_rotation * 180.0 / M_PI);
}

TEST_F(EvaluateFilesTest, Se3AlignmentRecoversAKnownTransformUnderNoise) {
  ExpectRecovered(AlignmentKind::kSe3, 1.0, 11, dir_.path());
}

TEST_F(EvaluateFilesTest, Sim3AlignmentRecoversAKnownScaleUnderNoise) {
  ExpectRecovered(AlignmentKind::kSim3, 0.4, 12, dir_.path());
}

TEST_F(EvaluateFilesTest, TimeOffsetIsAddedToTheEstimate) {
  Trajectory estimate = Drive();
  // 0.55 s late: between two reference stamps, 0.05 s from each.
  for (StampedPose& p : estimate) p.t = Time::FromNanoseconds(p.t.nanoseconds() + 550'000'000);
  ASSERT_TRUE(WriteTum(Drive(), File("gt.tum")).ok());
  ASSERT_TRUE(WriteTum(estimate, File("est.tum")).ok());
  EXPECT_THAT(Error(Options("gt.tum", "est.tum")),
              StartsWith(File("est.tum") + ": no pose within 0.01 s (time offset 0 s) of a pose of " + File("gt.tum")));
  EvaluateOptions shifted = Options("gt.tum", "est.tum");
  shifted.time_offset_s = -0.55;
  const Evaluation e = MustEvaluate(shifted);
  EXPECT_EQ(e.metrics["association"]["matched"], 601);
  EXPECT_EQ(e.metrics["association"]["time_offset_s"], -0.55);
  EXPECT_LT(e.metrics["ate_m"].get<double>(), 1e-9);
}

TEST_F(EvaluateFilesTest, AlignmentOnTheFirstPosesOrAWindow) {
  // The estimate is exact for 20 s, then drifts away 0.5 m/s along x; it also lives in a shifted frame.
  const Trajectory drive = Drive();
  Trajectory estimate = drive;
  for (StampedPose& p : estimate) {
    const double t = SecondsBetween(drive.front().t, p.t);
    p.p_world_body += Eigen::Vector3d(5.0 + (t > 20.0 ? 0.5 * (t - 20.0) : 0.0), 1.0, 0.0);
  }
  ASSERT_TRUE(WriteTum(drive, File("gt.tum")).ok());
  ASSERT_TRUE(WriteTum(estimate, File("est.tum")).ok());
  EvaluateOptions first = Options("gt.tum", "est.tum");
  first.alignment = AlignmentKind::kSe3;
  first.align_first_n = 150;  // 15 s
  const Evaluation e = MustEvaluate(first);
  EXPECT_EQ(e.metrics["alignment"]["poses"], 150);
  EXPECT_LT(e.error_world[100].norm(), 1e-9);               // before the drift
  EXPECT_NEAR(e.error_world.back().x(), 0.5 * 40.0, 1e-6);  // the whole drift at the end
  EvaluateOptions window = first;
  window.align_first_n = 0;
  window.align_window_s = std::make_pair(2.0, 18.0);
  const Evaluation w = MustEvaluate(window);
  EXPECT_EQ(w.metrics["alignment"]["poses"], 161);
  EXPECT_NEAR(w.error_world.back().x(), 20.0, 1e-6);
  // All poses: the drift is spread over the whole run, so the early poses are off.
  EvaluateOptions all = first;
  all.align_first_n = 0;
  EXPECT_GT(MustEvaluate(all).error_world[100].norm(), 1.0);
  window.align_window_s = std::make_pair(500.0, 600.0);
  EXPECT_THAT(Error(window), HasSubstr("no matched pose in the alignment window"));
  // Origin alignment: the first poses made equal, the 5 m shift removed.
  EvaluateOptions origin = Options("gt.tum", "est.tum");
  origin.alignment = AlignmentKind::kOrigin;
  EXPECT_LT(MustEvaluate(origin).error_world[100].norm(), 1e-9);
}

TEST_F(EvaluateFilesTest, KittiFilesArePairedByIndex) {
  const Trajectory drive = Drive();
  std::string reference, estimate;
  for (std::size_t i = 0; i < drive.size(); ++i) {
    const Eigen::Matrix3d r = drive[i].q_world_body.toRotationMatrix();
    const Eigen::Vector3d p = drive[i].p_world_body;
    std::string row;
    for (int k = 0; k < 3; ++k)
      row += std::to_string(r(k, 0)) + " " + std::to_string(r(k, 1)) + " " + std::to_string(r(k, 2)) + " " +
             std::to_string(p[k]) + (k < 2 ? " " : "\n");
    reference += row;
    if (i < 500) estimate += row;
  }
  WriteFile(File("gt_poses.txt"), reference);
  WriteFile(File("est_poses.txt"), estimate);
  const Evaluation e = MustEvaluate(Options("gt_poses.txt", "est_poses.txt"));
  EXPECT_EQ(e.metrics["association"]["by"], "index");
  EXPECT_EQ(e.metrics["association"]["matched"], 500);
  EXPECT_EQ(e.metrics["reference"]["format"], "kitti");
  EXPECT_EQ(e.metrics["estimate_format"], "kitti");
  EXPECT_LT(e.metrics["ate_m"].get<double>(), 1e-5);
}

// A plain TUM estimate with its covariances in a file of their own: every pose 0.1 m off in x with a variance of
// 0.01 m^2 in x gives a NEES of exactly 1 per pose; without the file there is no NEES; an untimed (KITTI) estimate
// cannot pair covariance rows by stamp.
TEST_F(EvaluateFilesTest, CovarianceFileGivesAPlainEstimateItsNees) {
  const Trajectory drive = Drive();
  Trajectory estimate = drive;
  std::string rows = "t,xx,xy,xz,yx,yy,yz,zx,zy,zz\n";
  for (StampedPose& p : estimate) {
    p.p_world_body.x() += 0.1;
    rows += FormatSeconds(p.t) + ",0.01,0,0,0,1,0,0,0,1\n";
  }
  ASSERT_TRUE(WriteTum(drive, File("gt.tum")).ok());
  ASSERT_TRUE(WriteTum(estimate, File("est.tum")).ok());
  WriteFile(File("est_covariance.csv"), rows);
  EvaluateOptions options = Options("gt.tum", "est.tum");
  EXPECT_FALSE(MustEvaluate(options).metrics.contains("nees"));
  options.covariance_file = File("est_covariance.csv");
  const Evaluation e = MustEvaluate(options);
  ASSERT_TRUE(e.metrics.contains("nees")) << e.metrics.dump(2);
  EXPECT_NEAR(e.metrics["nees_mean"].get<double>(), 1.0, 1e-9);
  EXPECT_EQ(e.metrics["nees"]["poses"], drive.size());

  options.covariance_file = File("absent.csv");
  EXPECT_THAT(Error(options), StartsWith(File("absent.csv") + ": cannot open"));
  WriteFile(File("est.kitti"), "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1 0 1 0 0 0 0 1 0\n");
  options.estimate_dir = File("est.kitti");
  options.covariance_file = File("est_covariance.csv");
  EXPECT_THAT(Error(options), HasSubstr("has no time stamps"));
}

TEST_F(EvaluateFilesTest, EurocReferenceAgainstATumEstimate) {
  const Trajectory drive = Drive();
  std::string csv = "#timestamp [ns],p_RS_R_x [m],p_RS_R_y [m],p_RS_R_z [m],q_RS_w [],q_RS_x [],q_RS_y [],q_RS_z []\n";
  for (const StampedPose& p : drive) {
    char row[256];
    std::snprintf(row, sizeof row, "%lld,%.12f,%.12f,%.12f,%.12f,%.12f,%.12f,%.12f\n",
                  static_cast<long long>(p.t.nanoseconds()), p.p_world_body.x(), p.p_world_body.y(), p.p_world_body.z(),
                  p.q_world_body.w(), p.q_world_body.x(), p.q_world_body.y(), p.q_world_body.z());
    csv += row;
  }
  WriteFile(File("data.csv"), csv);
  Trajectory estimate = drive;
  for (StampedPose& p : estimate) p.p_world_body.y() += 0.25;
  ASSERT_TRUE(WriteTum(estimate, File("est.tum")).ok());
  const Evaluation e = MustEvaluate(Options("data.csv", "est.tum"));
  EXPECT_EQ(e.metrics["reference"]["format"], "euroc");
  EXPECT_EQ(e.metrics["association"]["matched"], 601);
  EXPECT_NEAR(e.metrics["ate_m"].get<double>(), 0.25, 1e-9);
  EXPECT_NEAR(e.metrics["ate_axes"]["y"]["mean_m"].get<double>(), 0.25, 1e-9);
  EXPECT_LT(e.metrics["ate_rot_deg"].get<double>(), 1e-6);
}

TEST_F(EvaluateFilesTest, SeveralEstimatesGiveOneTableAndOverlaidFigures) {
  const Trajectory drive = Drive();
  Trajectory good = drive, bad = drive;
  for (StampedPose& p : good) p.p_world_body.z() += 0.1;
  for (StampedPose& p : bad) p.p_world_body.x() += 1.0;
  ASSERT_TRUE(WriteTum(drive, File("gt.tum")).ok());
  fs::create_directories(File("good"));
  ASSERT_TRUE(WriteTum(good, File("good/trajectory.tum")).ok());
  ASSERT_TRUE(WriteTum(bad, File("bad.tum")).ok());
  std::vector<Evaluation> evaluations = {MustEvaluate(Options("gt.tum", "good")),
                                         MustEvaluate(Options("gt.tum", "bad.tum"))};
  EXPECT_NEAR(evaluations[0].metrics["ate_axes"]["vertical"]["rmse_m"].get<double>(), 0.1, 1e-9);
  EXPECT_NEAR(evaluations[1].metrics["ate_axes"]["horizontal"]["rmse_m"].get<double>(), 1.0, 1e-9);
  const Result<WrittenEvaluation> w = WriteComparison(evaluations, File("out"));
  ASSERT_TRUE(w.ok()) << w.status().message();
  const json m = json::parse(ReadFile(File("out/metrics.json")));
  ASSERT_EQ(m["table"].size(), 2u);
  EXPECT_EQ(m["table"][0]["name"], "good");
  EXPECT_EQ(m["table"][1]["name"], "bad.tum");
  EXPECT_NEAR(m["table"][1]["ate_m"].get<double>(), 1.0, 1e-9);
  EXPECT_EQ(m["estimates"]["good"], evaluations[0].metrics);
  const std::string trajectory = ReadFile(File("out/trajectory.gp"));
  EXPECT_THAT(trajectory, HasSubstr("trajectory_estimate.dat"));
  EXPECT_THAT(trajectory, HasSubstr("trajectory_estimate_2.dat"));
  const std::string errors = ReadFile(File("out/ate_over_time.gp"));
  EXPECT_THAT(errors, HasSubstr("ate_over_time_2.dat"));
  EXPECT_THAT(errors, HasSubstr("rotation error [deg]"));
  EXPECT_TRUE(fs::exists(File("out/good/metrics.json")));
  EXPECT_TRUE(fs::exists(File("out/bad.tum/metrics.json")));
  if (GnuplotAvailable()) {
    EXPECT_TRUE(w.value().note.empty());
    EXPECT_EQ(w.value().images.size(), 2u);
    for (const std::string& image : w.value().images) EXPECT_GT(fs::file_size(image), 1000u) << image;
  }
  // One page: the comparison table first, then each estimate's tables; the overlaid figures and each estimate's own
  // (trajectory and position error: no covariance) embedded.
  const std::string page = ReadFile(w.value().report_path);
  const testing::HtmlSummary html = testing::CheckHtml(page);
  ASSERT_EQ(html.error, "");
  ASSERT_FALSE(html.table_headers.empty());
  EXPECT_THAT(html.table_headers[0], ::testing::ElementsAre("estimate", "matched", "ATE [m]", "ATE [deg]", "RPE [m]",
                                                            "RPE [deg]", "NEES mean", "alignment"));
  EXPECT_LT(page.find("<h2>Estimate good</h2>"), page.find("<h2>Estimate bad.tum</h2>"));
  EXPECT_THAT(page, HasSubstr("<td>bad.tum</td><td>"));
  if (GnuplotAvailable()) {
    EXPECT_EQ(html.image_sources.size(), 2u + 2u + 2u);
  }
  for (const std::string& src : html.image_sources)
    EXPECT_TRUE(testing::DecodeBase64(src.substr(src.find(',') + 1)).has_value());
}

TEST_F(EvaluateFilesTest, BadInputsNameTheFile) {
  ASSERT_TRUE(WriteTum(Drive(), File("gt.tum")).ok());
  EXPECT_THAT(Error(Options("gt.tum", "none.tum")), StartsWith(File("none.tum") + ": missing"));
  EXPECT_THAT(Error(Options("none.tum", "gt.tum")), StartsWith(File("none.tum") + ": cannot open"));
  WriteFile(File("short.tum"), "0 1 2 3\n");
  EXPECT_THAT(Error(Options("gt.tum", "short.tum")), StartsWith(File("short.tum") + ":1: expected 8 fields"));
  EvaluateOptions neither;
  neither.estimate_dir = File("gt.tum");
  EXPECT_THAT(Error(neither), HasSubstr("no reference"));
}

}  // namespace
}  // namespace roamlab::eval
