// README.md's tutorial, run as a newcomer types it: its commands are read from the tutorial section, not copied here.
// They run in a scratch directory that links the repository's scenarios/ and configs/, with two changes that keep the
// test short: the Monte-Carlo step runs 2 runs instead of the tutorial's count, and DATA is the OptiOdom data of the
// test data directory (the real-data steps are left out, with a note, when it is absent).
#include <filesystem>
#include <iostream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/recording/temp_dir.h"
#include "tests/support/paths.h"
#include "tests/support/real_data.h"

namespace roamlab {
namespace {

namespace fs = std::filesystem;

// The tutorial's commands: the indented lines of README.md's "A ten-minute tutorial" section, comments removed and
// lines ending in a backslash joined with the next.
std::vector<std::string> TutorialCommands() {
  const std::string readme = testing::ReadFile(roamlab::testing::SourceDir() + "/README.md");
  const std::size_t begin = readme.find("\n## A ten-minute tutorial\n");
  const std::size_t end = readme.find("\n## ", begin + 1);
  std::istringstream section(readme.substr(begin, end - begin));
  std::vector<std::string> commands;
  for (std::string line; std::getline(section, line);) {
    if (line.rfind("    ", 0) != 0) continue;
    line = std::regex_replace(line.substr(4), std::regex("\\s*#.*$"), "");
    // A line ending in a backslash continues on the next.
    if (!commands.empty() && !commands.back().empty() && commands.back().back() == '\\') {
      commands.back().pop_back();
      commands.back() += std::regex_replace(line, std::regex("^\\s+"), "");
    } else if (!line.empty()) {
      commands.push_back(line);
    }
  }
  return commands;
}

TEST(Tutorial, EveryCommandRuns) {
  const std::vector<std::string> commands = TutorialCommands();
  ASSERT_GE(commands.size(), 10u) << "README.md's tutorial section was not found";
  testing::TempDir dir;
  for (const char* linked : {"scenarios", "configs", "models"})
    fs::create_directory_symlink(fs::path(roamlab::testing::SourceDir()) / linked, fs::path(dir.path()) / linked);
  const std::string data = testing::RealData("optiodom/data");
  const bool have_data = fs::is_directory(data);
  const std::string bin = fs::path(ROAMLAB_BINARY).parent_path().string();
  int ran = 0;
  std::vector<std::string> not_written;  // the outputs of the steps left out
  const auto reads_missing = [&not_written](const std::string& command) {
    for (const std::string& out : not_written)
      if (command.find(out + " ") != std::string::npos || command.find(out + "/") != std::string::npos) return true;
    return false;
  };
  for (std::string command : commands) {
    // The environment the tutorial sets up: roamlab on PATH (the built one), DATA at the test data.
    if (command.rfind("export PATH=", 0) == 0 || command.rfind("xdg-open ", 0) == 0) continue;
    if (command.rfind("DATA=", 0) == 0) continue;
    if ((command.find("$DATA") != std::string::npos && !have_data) || reads_missing(command)) {
      std::cout << "[ NOTE ] real data absent (" << data << "): not run: " << command << "\n";
      std::smatch out;
      if (std::regex_search(command, out, std::regex("--out (\\S+)"))) not_written.push_back(out[1]);
      continue;
    }
    command = std::regex_replace(command, std::regex("--runs [0-9]+"), "--runs 2");
    const testing::CommandRun run = testing::RunCommand(
        "cd " + dir.path() + " && export PATH=" + bin + ":$PATH DATA=" + data + " && " + command, dir.path());
    EXPECT_EQ(run.exit_code, 0) << command << "\n" << run.err;
    if (run.exit_code != 0) break;
    ++ran;
  }
  EXPECT_GE(ran, 8);
  // What the tutorial says the steps leave behind.
  for (const char* file : {"tut/rec/truth.yaml", "tut/cal/calibration.json", "tut/trk/trajectory.tum",
                           "tut/report_trk/report.html", "tut/report_trk/metrics.json", "tut/mc/nees.json"})
    EXPECT_TRUE(fs::exists(fs::path(dir.path()) / file)) << file;
  if (!have_data) return;
  for (const char* file :
       {"tut/odo/table.json", "tut/gap/report.md", "tut/twin/twin.json", "tut/twin/scenario_patch.yaml"})
    EXPECT_TRUE(fs::exists(fs::path(dir.path()) / file)) << file;
}

}  // namespace
}  // namespace roamlab
