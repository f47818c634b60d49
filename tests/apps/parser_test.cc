// The command line as a newcomer meets it, checked against the parser itself (apps/parser.h): every command's --help
// and docs/commands.md name every option it accepts, --version, "did you mean" for a mistyped command or option, and
// the recording named alike in every command.
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <functional>
#include <map>
#include <regex>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "apps/parser.h"
#include "apps/suggest.h"
#include "tests/recording/temp_dir.h"
#include "tests/support/paths.h"

namespace roamlab::apps {
namespace {

namespace fs = std::filesystem;

testing::CommandRun Roamlab(const std::string& args, const testing::TempDir& dir) {
  return testing::RunCommand(std::string(ROAMLAB_BINARY) + " " + args, dir.path());
}

// A command of the parser: its path below `roamlab` ("odometry learn") and its app.
struct Node {
  std::string path;
  const CLI::App* app;
};

// Every command and group below `app`, depth first.
void Walk(const CLI::App& app, const std::string& path, std::vector<Node>* nodes) {
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
    const std::string sub_path = path.empty() ? sub->get_name() : path + " " + sub->get_name();
    nodes->push_back({sub_path, sub});
    Walk(*sub, sub_path, nodes);
  }
}

// Every spelling a user types for `app`'s options: "--out", "-h", and the positionals' names.
std::vector<std::string> Spellings(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::Option* option : app.get_options()) {
    for (const std::string& l : option->get_lnames()) names.push_back("--" + l);
    for (const std::string& s : option->get_snames()) names.push_back("-" + s);
    if (option->get_positional()) names.push_back(option->get_name(true));
  }
  return names;
}

class ParserTest : public ::testing::Test {
 protected:
  void SetUp() override {
    commands_ = AddCommands(&app_);
    Walk(app_, "", &nodes_);
  }
  CLI::App app_;
  Commands commands_;
  std::vector<Node> nodes_;
  testing::TempDir dir_;
};

TEST_F(ParserTest, TheParserHasEveryCommand) {
  // A sanity check on the walk itself: the groups and their commands are found.
  std::vector<std::string> paths;
  for (const Node& n : nodes_) paths.push_back(n.path);
  for (const char* path : {"simulate", "calibrate", "track", "evaluate", "montecarlo", "diagnose", "odometry learn",
                           "import rosbag", "batch status", "regress", "sweep"})
    EXPECT_NE(std::find(paths.begin(), paths.end(), path), paths.end()) << path;
}

TEST_F(ParserTest, EveryHelpNamesEveryOption) {
  const std::vector<std::string> top = Spellings(app_);
  EXPECT_NE(std::find(top.begin(), top.end(), "--version"), top.end());
  std::vector<Node> all = nodes_;
  all.push_back({"", &app_});
  for (const Node& n : all) {
    const testing::CommandRun help = Roamlab(n.path + " --help", dir_);
    EXPECT_EQ(help.exit_code, 0) << n.path << ": " << help.err;
    for (const std::string& name : Spellings(*n.app))
      EXPECT_NE(help.out.find(name), std::string::npos) << "roamlab " << n.path << " --help lacks " << name;
    for (const CLI::Option* option : n.app->get_options())
      EXPECT_FALSE(option->get_description().empty()) << "roamlab " << n.path << " " << option->get_name(true, true);
    for (const CLI::App* sub : n.app->get_subcommands([](const CLI::App*) { return true; }))
      EXPECT_NE(help.out.find(sub->get_name()), std::string::npos) << n.path << " --help lacks " << sub->get_name();
  }
}

// docs/commands.md split at its "## " headings: heading -> text (the text before the first heading under "").
std::map<std::string, std::string> Sections(const std::string& text) {
  std::map<std::string, std::string> sections;
  std::string heading;
  std::size_t start = 0;
  for (std::size_t at = 0; at != std::string::npos; at = text.find("\n## ", at + 1)) {
    if (at > 0) {
      sections[heading] = text.substr(start, at - start);
      const std::size_t end = text.find('\n', at + 1);
      heading = text.substr(at + 4, end - at - 4);
      start = end;
    }
  }
  sections[heading] = text.substr(start);
  return sections;
}

// A heading's anchor as GitHub makes it: lower case, spaces to '-', punctuation other than '-' and '_' dropped.
std::string Anchor(const std::string& heading) {
  std::string anchor;
  for (char c : heading) {
    if (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_')
      anchor += static_cast<char>(std::tolower(c));
    if (c == ' ') anchor += '-';
  }
  return anchor;
}

// What documents `roamlab PATH`: its section and the sections it links to, or without a section of its own the
// paragraphs that name it.
std::string Documentation(const std::map<std::string, std::string>& sections, const std::string& path) {
  const auto own = sections.find("roamlab " + path);
  if (own == sections.end()) {
    std::string paragraphs;
    for (const auto& [heading, text] : sections)
      for (std::size_t at = text.find("roamlab " + path + " "); at != std::string::npos;
           at = text.find("roamlab " + path + " ", at + 1)) {
        const std::size_t begin = text.rfind("\n\n", at), end = text.find("\n\n", at);
        paragraphs += text.substr(begin == std::string::npos ? 0 : begin, end - begin);
      }
    return paragraphs;
  }
  std::string text = own->second;
  for (const auto& [heading, section] : sections)
    if (own->second.find("(#" + Anchor(heading) + ")") != std::string::npos) text += section;
  return text;
}

TEST_F(ParserTest, CommandsMdDocumentsEveryOption) {
  const std::string doc = testing::ReadFile(roamlab::testing::SourceDir() + "/docs/commands.md");
  ASSERT_FALSE(doc.empty());
  const std::map<std::string, std::string> sections = Sections(doc);
  EXPECT_NE(sections.at("").find("--version"), std::string::npos) << "the introduction lacks roamlab --version";
  for (const Command& command : commands_) {
    std::string path = command.app->get_name();
    for (const CLI::App* p = command.app->get_parent(); p && p->get_parent(); p = p->get_parent())
      path = p->get_name() + " " + path;
    const std::string text = Documentation(sections, path);
    EXPECT_FALSE(text.empty()) << "docs/commands.md does not document roamlab " << path;
    for (const CLI::Option* option : command.app->get_options()) {
      for (const std::string& l : option->get_lnames()) {
        if (l == "help") continue;
        EXPECT_NE(text.find("--" + l), std::string::npos) << "docs/commands.md: roamlab " << path << " --" << l;
      }
    }
  }
}

TEST_F(ParserTest, VersionNamesTheProjectVersion) {
  const testing::CommandRun run = Roamlab("--version", dir_);
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(std::regex_search(run.out, std::regex("^roamlab [0-9]+\\.[0-9]+\\.[0-9]+"))) << run.out;
}

// One line on stderr, exit 2, naming the command and the close name.
void ExpectSuggestion(const testing::CommandRun& run, const std::string& expected) {
  EXPECT_EQ(run.exit_code, 2) << run.err;
  EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
  EXPECT_NE(run.err.find(expected), std::string::npos) << run.err;
}

TEST_F(ParserTest, MistypedCommandsAndOptionsGetASuggestion) {
  ExpectSuggestion(Roamlab("calibrat rec --config c.yaml --out o", dir_),
                   "roamlab: unknown command 'calibrat'; did you mean 'calibrate'?");
  ExpectSuggestion(Roamlab("odometry lern --recording r --out m.json", dir_),
                   "roamlab odometry: unknown command 'lern'; did you mean 'learn'?");
  ExpectSuggestion(Roamlab("calibrate rec --config c.yaml --outt o", dir_),
                   "roamlab calibrate: unknown option '--outt'; did you mean '--out'?");
  ExpectSuggestion(Roamlab("evaluate --estimate e --recording r --out o --algin se3", dir_),
                   "roamlab evaluate: unknown option '--algin'; did you mean '--align'?");
  // Nothing close: the commands are listed instead.
  ExpectSuggestion(Roamlab("fly", dir_), "roamlab: unknown command 'fly' (commands: simulate, replay,");
  ExpectSuggestion(Roamlab("", dir_), "roamlab: a command is required (commands: simulate,");
}

TEST(ClosestName, ByEditDistanceOrUniqueStart) {
  EXPECT_EQ(EditDistance("kitten", "sitting"), 3);
  EXPECT_EQ(EditDistance("", "abc"), 3);
  EXPECT_EQ(EditDistance("abc", "abc"), 0);
  const std::vector<std::string> commands = {"simulate", "calibrate", "track", "evaluate", "gap-benchmark"};
  EXPECT_EQ(ClosestName("calbirate", commands), "calibrate");
  EXPECT_EQ(ClosestName("trak", commands), "track");
  EXPECT_EQ(ClosestName("gap", commands), "gap-benchmark");  // the only name it starts
  EXPECT_EQ(ClosestName("xyz", commands), "");
  EXPECT_EQ(ClosestName("evalu", {"evaluate", "eval-all"}), "evaluate");
}

TEST_F(ParserTest, TheRecordingIsNamedAlikeInEveryCommand) {
  // Each spelling reaches the command, which then reports the missing recording by its path.
  const std::string missing = (fs::path(dir_.path()) / "norec").string();
  const std::string config = roamlab::testing::SourceDir() + "/configs/atv_calibration.yaml";
  const std::string out = " --out " + (fs::path(dir_.path()) / "o").string();
  for (const std::string& args :
       {"calibrate " + missing + " --config " + config + out,
        "calibrate --recording " + missing + " --config " + config + out,
        "track --recording " + missing + " --config " + config + out, "init --recording " + missing + out + "/e.yaml",
        "diagnose --recording " + missing + " --config " + config + " --no-baseline" + out,
        "diagnose " + missing + " --config " + config + " --no-baseline" + out,
        "diagnose --real " + missing + " --config " + config + " --no-baseline" + out}) {
    const testing::CommandRun run = Roamlab(args, dir_);
    EXPECT_EQ(run.exit_code, 2) << args << "\n" << run.err;
    EXPECT_NE(run.err.find(missing), std::string::npos) << args << "\n" << run.err;
  }
  // Every command that reads a recording takes --recording; those that read one take it as REC too.
  std::vector<std::string> with_option, with_positional;
  for (const Node& n : nodes_) {
    for (const CLI::Option* option : n.app->get_options()) {
      const std::vector<std::string>& l = option->get_lnames();
      if (std::find(l.begin(), l.end(), "recording") != l.end()) with_option.push_back(n.path);
      if (option->get_positional() && option->get_name(true) == "recording") {
        with_positional.push_back(n.path);
        EXPECT_NE(std::find(l.begin(), l.end(), "recording"), l.end()) << n.path << ": REC without --recording";
      }
    }
  }
  EXPECT_EQ(with_option, (std::vector<std::string>{"replay", "calibrate", "track", "evaluate", "init", "diagnose",
                                                   "odometry learn", "odometry evaluate", "frontend"}));
  EXPECT_EQ(with_positional,
            (std::vector<std::string>{"replay", "calibrate", "track", "init", "diagnose", "frontend"}));
}

}  // namespace
}  // namespace roamlab::apps
