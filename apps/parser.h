// The `roamlab` command line's parser: every command and group with its options, and what runs each once parsed.
// The executable (apps/roamlab.cc) parses with it; the tests walk it to check every command's help and docs.
#pragma once

#include <functional>
#include <vector>

#include <CLI/CLI.hpp>

namespace roamlab::apps {

// A registered (sub)command and what runs it once the command line is parsed.
struct Command {
  CLI::App* app;
  std::function<int()> run;
};
using Commands = std::vector<Command>;

// Registers every command on `app` (the top level: name, description, --version) and returns them.
Commands AddCommands(CLI::App* app);

}  // namespace roamlab::apps
