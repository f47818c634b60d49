// report.html in a real browser: Debian's chromium, headless, takes a screenshot of an evaluation's report. Skipped
// when chromium is not installed (it is not part of the CI set-up).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "eval/evaluate.h"
#include "tests/recording/temp_dir.h"

namespace roamlab::eval {
namespace {

namespace fs = std::filesystem;

// Width and height from a PNG's IHDR chunk; {0, 0} when the file is not a PNG.
std::pair<unsigned, unsigned> PngSize(const std::string& path) {
  const std::string bytes = testing::ReadFile(path);
  if (bytes.size() < 24 || bytes.compare(0, 8, std::string("\x89PNG\r\n\x1a\n", 8)) != 0) return {0, 0};
  const auto be32 = [&](std::size_t at) {
    unsigned v = 0;
    for (std::size_t k = 0; k < 4; ++k) v = (v << 8) | static_cast<unsigned char>(bytes[at + k]);
    return v;
  };
  return {be32(16), be32(20)};
}

TEST(ReportBrowserTest, ChromiumRendersTheReport) {
  if (std::system("command -v chromium >/dev/null 2>&1") != 0) GTEST_SKIP() << "chromium is not installed";
  if (!GnuplotAvailable()) GTEST_SKIP() << "gnuplot is not installed: the report would have no figures";
  testing::TempDir dir;
  Trajectory reference(200), estimate(200);
  for (int i = 0; i < 200; ++i) {
    const double t = 0.1 * i;
    reference[i].t = estimate[i].t = Time::FromSeconds(t);
    reference[i].p_world_body = Eigen::Vector3d(10.0 * std::sin(0.2 * t), 10.0 * std::cos(0.2 * t), 0.0);
    estimate[i].p_world_body = reference[i].p_world_body + Eigen::Vector3d(0.1 * std::sin(t), 0.05, 0.0);
  }
  ASSERT_TRUE(WriteTum(reference, dir.File("reference.tum")).ok());
  ASSERT_TRUE(WriteTum(estimate, dir.File("estimate.tum")).ok());
  EvaluateOptions options;
  options.reference_file = dir.File("reference.tum");
  options.estimate_dir = dir.File("estimate.tum");
  const Result<Evaluation> evaluation = Evaluate(options);
  ASSERT_TRUE(evaluation.ok()) << evaluation.status().message();
  const Result<WrittenEvaluation> written = WriteEvaluation(evaluation.value(), dir.File("out"));
  ASSERT_TRUE(written.ok()) << written.status().message();

  const std::string screenshot = dir.File("screenshot.png");
  const std::string command =
      "chromium --headless --no-sandbox --disable-gpu --hide-scrollbars --screenshot=" + screenshot +
      " --window-size=1200,2000 file://" + written.value().report_path + " >" + dir.File("chromium.log") + " 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << testing::ReadFile(dir.File("chromium.log"));
  ASSERT_TRUE(fs::exists(screenshot)) << testing::ReadFile(dir.File("chromium.log"));
  EXPECT_EQ(PngSize(screenshot), std::make_pair(1200u, 2000u));
  // A blank page compresses to a few kB; text, tables and two embedded figures do not.
  EXPECT_GT(fs::file_size(screenshot), 30000u);
}

}  // namespace
}  // namespace roamlab::eval
