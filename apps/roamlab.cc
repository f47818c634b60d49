// roamlab: the command line. `roamlab --help` and `roamlab <command> --help` describe every command.
#include <iostream>
#include <set>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "apps/cli.h"
#include "apps/output_check.h"
#include "apps/parser.h"
#include "apps/suggest.h"
#include "common/interrupt.h"

namespace roamlab::apps {
namespace {

// The options that name what a command reads (positional or long names): its --out must not be or lie inside them.
const std::set<std::string> kInputOptions = {"recording", "scenario", "config", "calibration", "estimate", "reference",
                                             "suite",     "baseline", "bag",    "run",         "metadata", "files",
                                             "map",       "model",    "atv",    "diffdrive",   "mecanum"};

// The commands that stop cleanly on SIGINT and SIGTERM (common/interrupt.h); the others end at once, as by default.
const std::set<std::string> kInterruptible = {"simulate",   "replay",   "calibrate",     "track",
                                              "montecarlo", "diagnose", "gap-benchmark", "regress"};

// The name a command's error lines carry: the group's ("import", "odometry") for a subcommand of a group.
std::string CommandName(const CLI::App& app) {
  const CLI::App* parent = app.get_parent();
  return parent && parent->get_parent() ? parent->get_name() : app.get_name();
}

// The problem with the command's --out against its inputs (apps/output_check.h), "" when there is none.
std::string CheckOutput(const CLI::App& app) {
  std::string out;
  std::vector<std::string> inputs;
  for (const CLI::Option* option : app.get_options()) {
    const std::string name = !option->nonpositional()        ? option->get_name(true)
                             : !option->get_lnames().empty() ? option->get_lnames().front()
                                                             : "";
    if (name == "out" && option->count() > 0) out = option->results().front();
    if (kInputOptions.count(name))
      for (const std::string& value : option->results()) inputs.push_back(value);
  }
  if (out.empty()) return "";
  const CLI::App* parent = app.get_parent();
  return OutputOverlapsInput(out, inputs, parent && parent->get_name() == "import");
}

// Runs the parsed command: --out checked first, the interrupt handlers for the long commands; after an interruption
// the exit code is 128 + the signal (130 for SIGINT, 143 for SIGTERM) unless the command finished its work.
int RunParsed(const Command& command) {
  const std::string name = CommandName(*command.app);
  if (const std::string problem = CheckOutput(*command.app); !problem.empty()) return BadInput(nullptr, name, problem);
  if (kInterruptible.count(command.app->get_name())) InstallInterruptHandlers();
  const int code = command.run();
  return code != 0 && InterruptRequested() ? InterruptExitCode() : code;
}

// Registers every command, parses the command line and runs the command it names; the process exit code.
int RunCommandLine(int argc, char** argv) {
  SetCommandLine(argc, argv);
  CLI::App app;
  const Commands commands = AddCommands(&app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << ParseErrorLine(app, e) << "\n";
    return kBadInputExit;
  }
  for (const Command& command : commands)
    if (*command.app) return RunParsed(command);
  return kBadInputExit;
}

}  // namespace
}  // namespace roamlab::apps

int main(int argc, char** argv) { return roamlab::apps::RunCommandLine(argc, argv); }
