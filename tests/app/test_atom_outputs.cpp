// What the output files say about atoms: the atom tables beside every mesh
// and frame directory, the per-vertex atom columns that index them (never
// negative: viewers read them as unsigned), and PLY as text for PyMOL.
#include "cli_run.hpp"
#include "test_support.hpp"

#include "skinmesh/core/error.hpp"
#include "skinmesh/core/molecule.hpp"
#include "skinmesh/mesh_io/mesh_read.hpp"
#include "skinmesh/mesh_io/mesh_write.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

using namespace skinmesh;
using skinmesh::test::run;

namespace {

namespace fs = std::filesystem;

std::vector<std::string> split(const std::string& line, char by) {
  std::vector<std::string> fields;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, by)) fields.push_back(field);
  if (!line.empty() && line.back() == by) fields.emplace_back();
  return fields;
}

// An atom table's rows (header checked), each split into its 8 fields.
std::vector<std::vector<std::string>> read_table(const std::string& path) {
  std::ifstream in(path);
  REQUIRE(in.good());
  std::string line;
  std::getline(in, line);
  CHECK(line == "index\tchain\tresidue_number\tinsertion_code\tresidue_name\tatom_name\telement\tradius");
  std::vector<std::vector<std::string>> rows;
  while (std::getline(in, line)) {
    rows.push_back(split(line, '\t'));
    REQUIRE(rows.back().size() == 8);
    CHECK(rows.back()[0] == std::to_string(rows.size() - 1));  // 0-based, in order
  }
  return rows;
}

// The vertex rows of a text PLY, by property name.
std::vector<std::map<std::string, double>> ply_vertices(const std::string& path) {
  std::ifstream in(path);
  REQUIRE(in.good());
  std::string line;
  std::vector<std::string> names;
  long count = -1;
  bool in_vertex = false;
  while (std::getline(in, line) && line != "end_header") {
    const auto f = split(line, ' ');
    if (f[0] == "format") REQUIRE(f[1] == "ascii");
    if (f[0] == "element") {
      in_vertex = f[1] == "vertex";
      if (in_vertex) count = std::stol(f[2]);
    }
    if (f[0] == "property" && in_vertex) names.push_back(f.back());
  }
  std::vector<std::map<std::string, double>> rows;
  for (long v = 0; v < count && std::getline(in, line); ++v) {
    std::istringstream values(line);
    std::map<std::string, double> row;
    for (const std::string& name : names) values >> row[name];
    REQUIRE(values);
    rows.push_back(row);
  }
  REQUIRE(static_cast<long>(rows.size()) == count);
  return rows;
}

std::string temp_dir() {
  char pattern[] = "/tmp/skinmesh-atoms-XXXXXX";
  REQUIRE(mkdtemp(pattern) != nullptr);
  return pattern;
}

// Meshes MOLECULE with ARGS as a text PLY; every vertex's atom must be a row
// of the table that names the molecule's atoms after the same filters, and
// lie within that atom's ball (radius r sqrt(2): the weight r^2 / s, s = 1/2,
// whose union holds the skin): an index off by a filtered atom fails.
void check_mesh_atoms(const std::string& molecule, const std::string& args, const ReadOptions& read) {
  const std::string dir = temp_dir();
  const auto r = run("--quiet mesh " + molecule + " " + args + " --ascii -o " + dir + "/m.ply");
  INFO(r.output);
  REQUIRE(r.code == 0);
  const auto table = read_table(dir + "/m.atoms.tsv");
  const Molecule m = read_molecule(molecule, read);
  REQUIRE(table.size() == m.atoms.size());
  for (size_t i = 0; i < table.size(); ++i) {
    CHECK(table[i][1] == m.atoms[i].chain);
    CHECK(table[i][2] == std::to_string(m.atoms[i].residue_number));
    CHECK(table[i][5] == m.atoms[i].name);
    CHECK(std::stod(table[i][7]) == Approx(m.atoms[i].radius).epsilon(1e-5));
  }
  const auto vertices = ply_vertices(dir + "/m.ply");
  double worst = 0;  // distance beyond the atom's ball, A
  for (const auto& v : vertices) {
    REQUIRE(v.at("atom") == v.at("atomid"));
    REQUIRE(v.at("atom") >= 0);
    REQUIRE(v.at("atom") < static_cast<double>(table.size()));
    const Atom& a = m.atoms[static_cast<size_t>(v.at("atom"))];
    const Eigen::Vector3d x(v.at("x"), v.at("y"), v.at("z"));
    worst = std::max(worst, (x - a.position).norm() - a.radius * std::sqrt(2.0));
  }
  CHECK(worst <= 1e-9);
  fs::remove_all(dir);
}

}  // namespace

TEST_CASE("mesh writes the atom table beside the mesh and its vertices name its rows, filters and outer-only kept",
          "[cli][atoms][large]") {
  SECTION("hydrogens kept, cavities dropped") {
    ReadOptions read;
    read.keep_hydrogens = true;
    check_mesh_atoms(test::data_file("2k39_3models.pdb"), "--keep-hydrogens --outer-only", read);
  }
  SECTION("one chain of two: chain B's atoms come after chain A's in the file") {
    ReadOptions read;
    read.chains = {"B"};
    check_mesh_atoms(test::data_file("1hpv.pdb"), "--chain B --outer-only", read);
  }
}

TEST_CASE("an XYZR molecule's atom table leaves residues and elements empty", "[cli][atoms]") {
  test::TempFile xyzr("three.xyzr", "0 0 0 1.5\n2 0 0 1.25\n1 1.5 0 1.7\n");
  const std::string dir = temp_dir();
  const auto r = run("--quiet mesh " + xyzr.path() + " -o " + dir + "/three.off");
  INFO(r.output);
  REQUIRE(r.code == 0);
  const auto table = read_table(dir + "/three.atoms.tsv");
  REQUIRE(table.size() == 3);
  CHECK(table[1] == std::vector<std::string>{"1", "", "", "", "", "", "", "1.25"});
  fs::remove_all(dir);
}

TEST_CASE("a text PLY is PLY's alone: --ascii with another format is refused and nothing is written",
          "[cli][atoms][bad]") {
  const std::string dir = temp_dir();
  const auto r = run("mesh " + test::data_file("pept.pdb") + " --ascii -o " + dir + "/pept.off");
  CHECK(r.code == 2);
  CHECK(r.output.find("--ascii") != std::string::npos);
  CHECK(fs::is_empty(dir));
  fs::remove_all(dir);
}

TEST_CASE("morph frames hold no negative atom value: a side's missing atom is a flag", "[cli][atoms][morph]") {
  const std::string dir = temp_dir() + "/m";
  const std::string file = test::data_file("2k39_3models.pdb");
  // The m x n blend: at t = 0 and t = 1 the frame is one side's own mesh.
  const auto r = run("--quiet morph " + file + " " + file +
                     " --source-model 1 --target-model 3 --pairs all --frames 3 --format ply --ascii -o " + dir);
  INFO(r.output);
  REQUIRE(r.code == 0);
  const auto source = read_table(dir + "/source_atoms.tsv"), target = read_table(dir + "/target_atoms.tsv");
  CHECK(source.size() == 78);
  CHECK(target.size() == 78);
  for (int k = 0; k < 3; ++k) {
    INFO("frame " << k);
    long with_source = 0, with_target = 0;
    const auto vertices = ply_vertices(dir + "/frame_000" + std::to_string(k) + ".ply");
    for (const auto& v : vertices) {
      for (const char* column : {"atom", "atomid", "source_atom", "target_atom", "has_source_atom", "has_target_atom"})
        REQUIRE(v.at(column) >= 0);
      REQUIRE(v.at("source_atom") < static_cast<double>(source.size()));
      REQUIRE(v.at("target_atom") < static_cast<double>(target.size()));
      const bool has_source = v.at("has_source_atom") == 1, has_target = v.at("has_target_atom") == 1;
      REQUIRE((has_source || has_target));
      REQUIRE(v.at("atomid") == (has_source ? v.at("source_atom") : v.at("target_atom")));
      REQUIRE(v.at("atom") == v.at("atomid"));
      if (!has_source) REQUIRE(v.at("source_atom") == 0);
      if (!has_target) REQUIRE(v.at("target_atom") == 0);
      REQUIRE(v.count("red") == 1);  // coloured by patch unless --colour none
      with_source += has_source;
      with_target += has_target;
    }
    const long n = static_cast<long>(vertices.size());
    CHECK(with_source == (k == 2 ? 0 : n));
    CHECK(with_target == (k == 0 ? 0 : n));
  }
  fs::remove_all(fs::path(dir).parent_path());
}

TEST_CASE("a trajectory's frames name the first model's atoms on both sides", "[cli][atoms][morph]") {
  const std::string dir = temp_dir() + "/t";
  const auto r = run("--quiet trajectory " + test::data_file("2k39_3models.pdb") +
                     " --models 1-2 --frames-per-step 1 --format ply --ascii --colour none -o " + dir);
  INFO(r.output);
  REQUIRE(r.code == 0);
  const auto source = read_table(dir + "/source_atoms.tsv");
  CHECK(source == read_table(dir + "/target_atoms.tsv"));
  CHECK(source.size() == 78);
  for (const auto& v : ply_vertices(dir + "/frame_0001.ply")) {
    REQUIRE(v.at("has_source_atom") == 1);
    REQUIRE(v.at("has_target_atom") == 1);
    REQUIRE(v.at("source_atom") == v.at("target_atom"));
    REQUIRE(v.at("atomid") == v.at("source_atom"));
    REQUIRE(v.at("atomid") < static_cast<double>(source.size()));
    REQUIRE(v.count("red") == 0);  // --colour none
  }
  fs::remove_all(fs::path(dir).parent_path());
}

TEST_CASE("a text PLY reads back to the same doubles, and an unsigned column refuses a negative value", "[io][atoms]") {
  SurfaceMesh m;
  m.vertices = {{1.0 / 3.0, 0, 0}, {0, 2.0 / 3.0, 0}, {0, 0, 1e-17 + 0.1}};
  m.triangles = {{0, 1, 2}};
  VertexAttributes a;
  a.patch = {0, 1, 2};
  a.atom = {4, 5, 6};
  a.more = {{"atomid", PropertyType::uint32, {4, 5, 6}}};
  a.colours = {{{255, 0, 0}}, {{0, 255, 0}}, {{0, 0, 255}}};
  test::TempFile file("t.ply");
  {
    MeshWriteOptions text;
    text.ascii = true;
    std::ofstream out(file.path());
    write_mesh(out, m, MeshFormat::ply, &a, text);
  }
  const SurfaceMesh back = read_surface_mesh(file.path());
  REQUIRE(back.vertices.size() == 3);
  for (size_t v = 0; v < 3; ++v) CHECK(back.vertices[v] == m.vertices[v]);
  const auto rows = ply_vertices(file.path());
  CHECK(rows[2].at("atomid") == 6);
  CHECK(rows[2].at("blue") == 255);
  a.more[0].values[1] = -1;
  std::ostringstream sink;
  CHECK_THROWS_AS(write_mesh(sink, m, MeshFormat::ply, &a), ContractError);
}
