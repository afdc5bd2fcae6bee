#include "suggest.hpp"

#include <algorithm>
#include <numeric>

namespace skinmesh::app {
namespace {

size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  std::iota(row.begin(), row.end(), size_t{0});
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// Every long and short option name of `app`, with its dashes.
std::vector<std::string> option_names(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::Option* option : app.get_options()) {
    for (const std::string& n : option->get_lnames()) names.push_back("--" + n);
    for (const std::string& n : option->get_snames()) names.push_back("-" + n);
  }
  return names;
}

}  // namespace

std::string nearest_name(const std::string& word, const std::vector<std::string>& names) {
  std::string best;
  size_t best_distance = std::max<size_t>(2, word.size() / 3) + 1;
  for (const std::string& name : names) {
    const size_t d = edit_distance(word, name);
    if (d < best_distance) {
      best = name;
      best_distance = d;
    }
  }
  return best;
}

std::string suggestion(const CLI::App& app, const std::vector<std::string>& args) {
  std::vector<std::string> commands;
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) commands.push_back(sub->get_name());
  const std::vector<std::string> global = option_names(app);
  const CLI::App* command = nullptr;
  for (const std::string& arg : args) {
    const std::string word = arg.substr(0, arg.find('='));
    if (!command) {
      if (word.empty() || word[0] == '-') continue;  // a global option before the subcommand
      const auto found = std::find(commands.begin(), commands.end(), word);
      if (found == commands.end()) {
        const std::string near = nearest_name(word, commands);
        return "'" + word + "' is not a command" + (near.empty() ? "" : "; did you mean '" + near + "'?");
      }
      command = app.get_subcommand(word);
      continue;
    }
    if (word.size() < 2 || word[0] != '-' || (word[1] >= '0' && word[1] <= '9') || word[1] == '.') continue;
    std::vector<std::string> known = option_names(*command);
    known.insert(known.end(), global.begin(), global.end());
    if (std::find(known.begin(), known.end(), word) != known.end()) continue;
    std::string near = nearest_name(word, known);
    if (near.empty()) {  // no slip of the keys: the options that hold the word (--model: --source-model, --target-model)
      const std::string bare = word.substr(word.find_first_not_of('-'));
      for (const std::string& name : known)
        if (bare.size() >= 3 && name.find(bare) != std::string::npos) near += (near.empty() ? "" : "' or '") + name;
    }
    return "'" + word + "' is not an option of '" + command->get_name() + "'" +
           (near.empty() ? "" : "; did you mean '" + near + "'?");
  }
  return "";
}

}  // namespace skinmesh::app
