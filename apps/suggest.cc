#include "apps/suggest.h"

#include <algorithm>
#include <numeric>

namespace roamlab::apps {
namespace {

// The deepest (sub)command the parser entered.
const CLI::App* DeepestParsed(const CLI::App& app) {
  const CLI::App* current = &app;
  for (std::vector<CLI::App*> parsed = current->get_subcommands(); !parsed.empty(); parsed = current->get_subcommands())
    current = parsed.front();
  return current;
}

// "roamlab odometry learn": the names from the top level down to `app`.
std::string CommandPath(const CLI::App& app) {
  const CLI::App* parent = app.get_parent();
  return parent ? CommandPath(*parent) + " " + app.get_name() : app.get_name();
}

// Every spelling of `app`'s options: "--out", "-h", ...
std::vector<std::string> OptionNames(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::Option* option : app.get_options()) {
    for (const std::string& l : option->get_lnames()) names.push_back("--" + l);
    for (const std::string& s : option->get_snames()) names.push_back("-" + s);
  }
  return names;
}

std::vector<std::string> SubcommandNames(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
    names.push_back(sub->get_name());
  return names;
}

std::string Join(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

// The line for the first word in `words` (what `app` left unparsed) that is an unknown option or command; "" when
// none is.
std::string UnknownWordLine(const CLI::App& app, const std::vector<std::string>& words) {
  const std::vector<std::string> commands = SubcommandNames(app);
  for (const std::string& word : words) {
    const bool option = word.size() > 1 && word[0] == '-';
    if (!option && commands.empty()) continue;  // a stray value: CLI11's message names it
    const std::string name = option ? word.substr(0, word.find('=')) : word;
    const std::string closest = ClosestName(name, option ? OptionNames(app) : commands);
    std::string line = CommandPath(app) + ": unknown " + (option ? "option" : "command") + " '" + name + "'";
    if (!closest.empty()) line += "; did you mean '" + closest + "'?";
    if (closest.empty() && !option) line += " (commands: " + Join(commands) + ")";
    return line + " (see " + CommandPath(app) + " --help)";
  }
  return "";
}

}  // namespace

int EditDistance(const std::string& a, const std::string& b) {
  std::vector<int> row(b.size() + 1);
  std::iota(row.begin(), row.end(), 0);
  for (std::size_t i = 1; i <= a.size(); ++i) {
    int diagonal = row[0];
    row[0] = static_cast<int>(i);
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const int substitute = diagonal + (a[i - 1] == b[j - 1] ? 0 : 1);
      diagonal = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, substitute});
    }
  }
  return row[b.size()];
}

std::string ClosestName(const std::string& word, const std::vector<std::string>& names) {
  std::vector<std::string> starting;
  for (const std::string& n : names)
    if (word.size() >= 3 && n.compare(0, word.size(), word) == 0) starting.push_back(n);
  if (starting.size() == 1) return starting.front();
  std::string best;
  int best_distance = 0;
  for (const std::string& n : names) {
    const int d = EditDistance(word, n);
    const int allowed = std::clamp(static_cast<int>(n.size()) / 3, 1, 3);
    if (d <= allowed && (best.empty() || d < best_distance)) {
      best = n;
      best_distance = d;
    }
  }
  return best;
}

std::string ParseErrorLine(const CLI::App& app, const CLI::ParseError& error) {
  const CLI::App* current = DeepestParsed(app);
  if (std::string line = UnknownWordLine(*current, current->remaining()); !line.empty()) return line;
  std::string what = error.what();
  if (what == "A subcommand is required")
    what = "a command is required (commands: " + Join(SubcommandNames(*current)) + ")";
  return CommandPath(*current) + ": " + what + " (see " + CommandPath(*current) + " --help)";
}

}  // namespace roamlab::apps
