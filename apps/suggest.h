// "Did you mean" for a command line the parser refused: the word it could not place (a mistyped command or option)
// and the parser's own name closest to it.
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace roamlab::apps {

// The Levenshtein distance between `a` and `b` (insertions, deletions, substitutions).
int EditDistance(const std::string& a, const std::string& b);

// The name in `names` closest to `word`: the one that `word` is the start of (when just one is, and `word` has at
// least three characters), else the nearest by EditDistance when it is at most a third of the name's length (and
// at least 1, at most 3); "" when none is.
std::string ClosestName(const std::string& word, const std::vector<std::string>& names);

// After `app.parse` threw `error`: one line for the user naming the command, the word that was not understood and,
// when one is close, the command or option it probably meant ("roamlab calibrate: unknown option '--outt'; did you
// mean '--out'? (see roamlab calibrate --help)"); CLI11's own message, with the command named, otherwise.
std::string ParseErrorLine(const CLI::App& app, const CLI::ParseError& error);

}  // namespace roamlab::apps
