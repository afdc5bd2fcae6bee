#include "view_input.hpp"

#include "skinmesh/core/error.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace skinmesh::app {
namespace fs = std::filesystem;

const char* const kAtomColumns[8] = {"index",       "chain",     "residue_number", "insertion_code",
                                     "residue_name", "atom_name", "element",        "radius"};

std::vector<std::pair<std::string, std::string>> atom_table_names(const std::string& path, bool morph) {
  if (morph) return {{"source", "source_atoms.tsv"}, {"target", "target_atoms.tsv"}};
  fs::path p(path);
  return {{"mesh", p.stem().string() + ".atoms.tsv"}};
}

namespace {

// The header must name every column; the page reads the rest.
void check_atom_table(const std::string& path) {
  std::ifstream in(path);
  std::string header;
  if (!in || !std::getline(in, header)) input_error(path, 1, "cannot read the atom table's header");
  std::vector<std::string> names;
  std::istringstream words(header);
  for (std::string w; std::getline(words, w, '\t');) names.push_back(w.empty() || w.back() != '\r' ? w : w.substr(0, w.size() - 1));
  for (const char* column : kAtomColumns)
    if (std::find(names.begin(), names.end(), column) == names.end())
      input_error(path, 1, std::string("the atom table's header lacks the column '") + column + "'");
}

std::vector<ViewFrame> morph_frames(const fs::path& dir) {
  const fs::path list = dir / "frames.jsonl";
  std::ifstream in(list);
  if (!in) input_error(dir.string(), 0, "not a morph directory: it has no frames.jsonl (skinmesh morph writes one)");
  std::vector<ViewFrame> frames;
  long number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
    if (j.is_discarded() || !j.is_object() || !j.contains("t") || !j["t"].is_number() || !j.contains("file") ||
        !j["file"].is_string())
      input_error(list.string(), number, "a frame's line needs a number t and a string file");
    const fs::path ply = (dir / j["file"].get<std::string>()).replace_extension(".ply");
    if (!fs::is_regular_file(ply))
      input_error(ply.string(), 0, "missing: view and render read the PLY frames (morph --format with ply)");
    if (!frames.empty() && !(j["t"].get<double>() > frames.back().t))
      input_error(list.string(), number, "the frames' t must increase");
    frames.push_back({j["t"].get<double>(), ply.string()});
  }
  if (frames.empty()) input_error(list.string(), 0, "no frames");
  return frames;
}

}  // namespace

long vertex_atom(const std::map<std::string, std::vector<double>>& p, size_t v, const std::string& side) {
  auto column = p.find(side == "mesh" ? "atom" : side + "_atom");
  if (side == "mesh" && column == p.end()) column = p.find("atomid");
  if (column == p.end() || v >= column->second.size()) return -1;
  const double value = column->second[v];
  const auto flag = p.find("has_" + side + "_atom");
  if (value < 0 || value >= 4294967295.0 || (flag != p.end() && flag->second[v] == 0)) return -1;
  return static_cast<long>(value);
}

ViewInput find_view_input(const std::string& path) {
  ViewInput input;
  input.morph = fs::is_directory(path);
  if (input.morph) input.frames = morph_frames(path);
  else if (!fs::is_regular_file(path)) input_error(path, 0, "no such file or directory");
  else input.frames.push_back({0, path});
  const fs::path folder = input.morph ? fs::path(path) : fs::path(path).parent_path();
  for (const auto& [side, name] : atom_table_names(path, input.morph)) {
    const fs::path table = folder / name;
    if (!fs::is_regular_file(table)) continue;
    check_atom_table(table.string());
    input.atoms[side] = table.string();
  }
  return input;
}

}  // namespace skinmesh::app
