// "Did you mean": the nearest of the command's subcommands or of a
// subcommand's options to a word the command line got wrong.
#pragma once

#include <CLI/CLI.hpp>

#include <string>
#include <vector>

namespace skinmesh::app {

// The name in `names` nearest to `word` by edit distance, when near enough
// to be a slip (at most a third of the word's letters, and at least 2
// allowed), else "".
std::string nearest_name(const std::string& word, const std::vector<std::string>& names);

// A line suggesting what the user meant by the first word of `args` (the
// command line without the program) that names no subcommand where one is
// expected, or no option of the subcommand given; "" when there is none.
std::string suggestion(const CLI::App& app, const std::vector<std::string>& args);

}  // namespace skinmesh::app
