// The atomic writer (common/atomic_file.h) and the interruption flag and marker (common/interrupt.h).
#include "common/atomic_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <csignal>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/interrupt.h"
#include "tests/recording/temp_dir.h"

namespace roamlab {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::vector<std::string> Names(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename().string());
  return names;
}

TEST(AtomicFileTest, WritesAndReplacesLeavingNoTemporaryFile) {
  testing::TempDir dir;
  const std::string path = dir.File("out.json");
  ASSERT_TRUE(WriteFileAtomic(path, std::string("first\0bytes", 11)).ok());
  EXPECT_EQ(testing::ReadFile(path), std::string("first\0bytes", 11));
  ASSERT_TRUE(WriteFileAtomic(path, "second").ok());
  EXPECT_EQ(testing::ReadFile(path), "second");
  EXPECT_THAT(Names(dir.path()), ::testing::ElementsAre("out.json"));
}

TEST(AtomicFileTest, FailureNamesTheFileAndLeavesNothing) {
  testing::TempDir dir;
  const std::string missing = dir.File("no_such_dir/out.json");
  const Status s = WriteFileAtomic(missing, "x");
  ASSERT_FALSE(s.ok());
  EXPECT_THAT(s.message(), HasSubstr(missing + ": cannot write"));
  EXPECT_TRUE(Names(dir.path()).empty());

  // A directory without write permission: the temporary file cannot be made, the old file stays as it was.
  if (::geteuid() == 0) GTEST_SKIP() << "root writes into a read-only directory";
  const std::string locked = dir.File("locked");
  fs::create_directory(locked);
  testing::WriteFile(locked + "/out.json", "old");
  fs::permissions(locked, fs::perms::owner_read | fs::perms::owner_exec);
  const Status denied = WriteFileAtomic(locked + "/out.json", "new");
  fs::permissions(locked, fs::perms::owner_all);
  ASSERT_FALSE(denied.ok());
  EXPECT_THAT(denied.message(), HasSubstr(locked + "/out.json: cannot write"));
  EXPECT_EQ(testing::ReadFile(locked + "/out.json"), "old");
  EXPECT_THAT(Names(locked), ::testing::ElementsAre("out.json"));
}

TEST(AtomicFileTest, RemoveStaleFileIgnoresAMissingFile) {
  testing::TempDir dir;
  testing::WriteFile(dir.File("a.csv"), "t\n");
  EXPECT_TRUE(RemoveStaleFile(dir.File("a.csv")).ok());
  EXPECT_FALSE(fs::exists(dir.File("a.csv")));
  EXPECT_TRUE(RemoveStaleFile(dir.File("a.csv")).ok());
}

class InterruptTest : public ::testing::Test {
 protected:
  void TearDown() override { ClearInterrupt(); }
};

TEST_F(InterruptTest, ExitCodesFollowTheSignal) {
  EXPECT_FALSE(InterruptRequested());
  EXPECT_EQ(InterruptExitCode(), 0);
  RequestInterrupt(SIGINT);
  EXPECT_TRUE(InterruptRequested());
  EXPECT_EQ(InterruptExitCode(), 130);
  EXPECT_EQ(InterruptedError().message(), "interrupted by SIGINT");
  ClearInterrupt();
  RequestInterrupt(SIGTERM);
  EXPECT_EQ(InterruptExitCode(), 143);
  EXPECT_EQ(InterruptedError().message(), "interrupted by SIGTERM");
}

TEST_F(InterruptTest, HandlerSetsTheFlag) {
  InstallInterruptHandlers();
  ASSERT_EQ(std::raise(SIGTERM), 0);
  EXPECT_TRUE(InterruptRequested());
  EXPECT_EQ(InterruptSignal(), SIGTERM);
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
}

TEST_F(InterruptTest, MarkerSaysRunningThenInterruptedWithWhatWasDone) {
  testing::TempDir dir;
  const char* argv[] = {"roamlab", "regress", "suite.yaml"};
  SetCommandLine(3, argv);
  {
    IncompleteMarker marker(dir.path());
    ASSERT_TRUE(marker.Start().ok());
    nlohmann::json j = nlohmann::json::parse(testing::ReadFile(dir.File(kIncompleteFile)));
    EXPECT_EQ(j["state"], "running");
    EXPECT_EQ(j["command"], "roamlab regress suite.yaml");
    ASSERT_TRUE(marker.AddDone("case a").ok());
    j = nlohmann::json::parse(testing::ReadFile(dir.File(kIncompleteFile)));
    EXPECT_EQ(j["done"], nlohmann::json::array({"case a"}));
    marker.SetMessage("stopped after case a");
    RequestInterrupt(SIGINT);
  }
  const nlohmann::json j = nlohmann::json::parse(testing::ReadFile(dir.File(kIncompleteFile)));
  EXPECT_EQ(j["state"], "interrupted");
  EXPECT_EQ(j["signal"], "SIGINT");
  EXPECT_EQ(j["message"], "stopped after case a");
  EXPECT_EQ(j["done"], nlohmann::json::array({"case a"}));
  EXPECT_THAT(Names(dir.path()), ::testing::ElementsAre(kIncompleteFile));
}

TEST_F(InterruptTest, MarkerRemovedOnCompletionAndSaysFailedOtherwise) {
  testing::TempDir dir;
  {
    IncompleteMarker marker(dir.path());
    ASSERT_TRUE(marker.Start().ok());
    ASSERT_TRUE(marker.Complete().ok());
  }
  EXPECT_FALSE(fs::exists(dir.File(kIncompleteFile)));
  { IncompleteMarker(dir.path()).Start(); }
  EXPECT_EQ(nlohmann::json::parse(testing::ReadFile(dir.File(kIncompleteFile)))["state"], "failed");
}

}  // namespace
}  // namespace roamlab
