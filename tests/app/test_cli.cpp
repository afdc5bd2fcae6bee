// The skinmesh command: exit codes and messages a user sees.
#include "cgal_reference.hpp"
#include "cli_run.hpp"
#include "test_support.hpp"

#include "skinmesh/core/interpolation.hpp"
#include "skinmesh/core/molecule.hpp"
#include "skinmesh/mesh_io/mesh_read.hpp"
#include "skinmesh/mesh_io/mesh_write.hpp"
#include "skinmesh/core/skin_oracle.hpp"
#include "skinmesh/core/skin_topology.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <map>
#include <numeric>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <csignal>
#include <fcntl.h>
#include <cstdio>
#include <filesystem>
#include <sys/wait.h>
#include <unistd.h>

using skinmesh::test::Run;
using skinmesh::test::run;
using skinmesh::test::run_within;

TEST_CASE("skinmesh info reports atoms, radii and the complex", "[cli]") {
  const Run r = run("info " + skinmesh::test::data_file("pept.pdb"));
  INFO(r.output);
  CHECK(r.code == 0);
  CHECK(r.output.find("atoms read:     107") != std::string::npos);
  CHECK(r.output.find("tetrahedra") != std::string::npos);
  CHECK(r.output.find("hidden balls:   0") != std::string::npos);
}

TEST_CASE("skinmesh info --json is machine-readable", "[cli]") {
  const Run r = run("info --json " + skinmesh::test::data_file("2k39_3models.pdb") + " --all-models");
  INFO(r.output);
  CHECK(r.code == 0);
  CHECK(r.output.front() == '[');
  CHECK(r.output.find("\"models_in_file\": 3") != std::string::npos);
  CHECK(r.output.find("\"tetrahedron\":") != std::string::npos);
}

TEST_CASE("skinmesh info on bad input: message names the file, non-zero exit", "[cli][bad]") {
  const Run missing = run("info /nonexistent/file.pdb");
  CHECK(missing.code == 2);
  CHECK(missing.output.find("/nonexistent/file.pdb") != std::string::npos);
  skinmesh::test::TempFile nan("nan.xyzr", "0 0 0 1.5\n1 nan 0 1.5\n");
  const Run bad = run("info " + nan.path());
  CHECK(bad.code == 2);
  CHECK(bad.output.find(nan.path() + ":2:") != std::string::npos);
  const Run usage = run("info");
  CHECK(usage.code != 0);
}

TEST_CASE("skinmesh info runs on every PDB entry in data", "[cli]") {
  for (const char* name : {"pept.pdb", "3al1.pdb", "1ubi.pdb", "1ejg.pdb", "1hpv.pdb", "3mht.pdb",
                           "2k39_3models.pdb"}) {
    const Run r = run("--quiet info " + skinmesh::test::data_file(name));
    INFO(name << "\n" << r.output);
    CHECK(r.code == 0);
    CHECK(r.output.find("mixed cells:") != std::string::npos);
  }
}

TEST_CASE("skinmesh quality grades a mesh file, writes an SVG, measures on-surface error", "[cli][quality]") {
  // A regular tetrahedron with circumradius 1.7 about the origin, and one atom of
  // radius 1.7 there: with w = r^2/s the atom's skin is that circumsphere.
  const double h = 1.7 / std::sqrt(3.0);
  char off[512];
  std::snprintf(off, sizeof off,
                "OFF\n4 4 0\n%.17g %.17g %.17g\n%.17g %.17g %.17g\n%.17g %.17g %.17g\n%.17g %.17g %.17g\n"
                "3 0 1 2\n3 0 3 1\n3 0 2 3\n3 1 3 2\n",
                h, h, h, h, -h, -h, -h, h, -h, -h, -h, h);
  skinmesh::test::TempFile mesh("tet.off", off);
  skinmesh::test::TempFile atom("atom.xyzr", "0 0 0 1.7\n");
  const std::string svg = mesh.path() + ".svg";
  const Run r = run("quality " + mesh.path() + " --molecule " + atom.path() + " --svg " + svg + " --json");
  INFO(r.output);
  CHECK(r.code == 0);
  CHECK(r.output.find("\"euler_characteristic\": 2") != std::string::npos);
  CHECK(r.output.find("\"self_intersecting_pairs\": 0") != std::string::npos);
  const size_t at = r.output.find("\"max\":", r.output.find("\"on_surface_error\""));
  REQUIRE(at != std::string::npos);
  CHECK(std::stod(r.output.substr(at + 6)) < 1e-12);
  std::ifstream in(svg);
  std::string first;
  std::getline(in, first);
  CHECK(first.rfind("<svg", 0) == 0);
  std::remove(svg.c_str());

  const Run missing = run("quality /nonexistent/mesh.off");
  CHECK(missing.code == 2);
  CHECK(missing.output.find("/nonexistent/mesh.off") != std::string::npos);
}

TEST_CASE("skinmesh quality grades CGAL's skin mesh and ours side by side", "[cli][quality]") {
  using skinmesh::test::TempFile;
  const std::string molecule = skinmesh::test::data_file("pept.pdb");
  const auto balls = skinmesh::balls_from_molecule(skinmesh::read_molecule(molecule), 0.5);
  TempFile cgal("cgal.off");
  {
    std::ofstream out(cgal.path());
    skinmesh::write_mesh(out, skinmesh::test::cgal_skin_mesh(balls, 0.5), skinmesh::MeshFormat::off, nullptr);
  }
  TempFile ours("ours.off");
  REQUIRE(run("--quiet mesh " + molecule + " -o " + ours.path()).code == 0);
  auto grade = [&](const std::string& path) {
    const Run r = run("--json quality " + path + " --molecule " + molecule);
    INFO(r.output);
    REQUIRE(r.code == 0);
    return nlohmann::json::parse(r.output);
  };
  const nlohmann::json c = grade(cgal.path()), o = grade(ours.path());
  INFO("CGAL: " << c.dump() << "\nskinmesh: " << o.dump());
  // Both are closed manifolds without self-intersections, with the skin's topology.
  for (const nlohmann::json* q : {&c, &o}) {
    CHECK((*q)["closed"] == true);
    CHECK((*q)["manifold"] == true);
    CHECK((*q)["self_intersecting_pairs"] == 0);
  }
  CHECK(o["components"] == c["components"]);
  CHECK(o["genus"] == c["genus"]);
  // What the grader tells apart: only ours keeps the angle bound and has its
  // vertices on the skin.
  CHECK(o["min_angle_deg"].get<double>() >= 30.0 - 1e-9);
  CHECK(c["min_angle_deg"].get<double>() < 30.0);
  CHECK(o["on_surface_error"]["max"].get<double>() <= 1e-9);
  CHECK(c["on_surface_error"]["max"].get<double>() > 1e-9);
}

TEST_CASE("skinmesh mesh writes a mesh, a report and MSMS files, and failures leave nothing behind", "[cli][mesh]") {
  skinmesh::test::TempFile out("pept.ply");
  const std::string report = out.path() + ".json";
  const Run r = run("mesh " + skinmesh::test::data_file("pept.pdb") + " -o " + out.path() + " --report " + report +
                    " --quiet");
  INFO(r.output);
  CHECK(r.code == 0);
  std::ifstream ply(out.path(), std::ios::binary);
  std::string line;
  std::getline(ply, line);
  CHECK(line == "ply");
  std::getline(ply, line);
  CHECK(line == "format binary_little_endian 1.0");
  std::getline(ply, line);
  std::getline(ply, line);
  std::getline(ply, line);
  CHECK(line == "property double x");  // full precision by default
  std::ifstream rep(report);
  const std::string json((std::istreambuf_iterator<char>(rep)), std::istreambuf_iterator<char>());
  CHECK(json.find("\"closed_oriented_manifold\": true") != std::string::npos);
  CHECK(json.find("\"min_angle_at_least_bound\": true") != std::string::npos);
  std::remove(report.c_str());

  // The same mesh, graded by `quality` from the written file.
  const Run q = run("quality " + out.path() + " --molecule " + skinmesh::test::data_file("pept.pdb") + " --json");
  CHECK(q.code == 0);
  CHECK(q.output.find("\"components\": 3") != std::string::npos);

  skinmesh::test::TempFile vert("pept.vert");
  const std::string face = vert.path().substr(0, vert.path().size() - 5) + ".face";
  CHECK(run("mesh " + skinmesh::test::data_file("pept.pdb") + " -o " + vert.path() + " --quiet").code == 0);
  CHECK(std::ifstream(face).good());
  std::remove(face.c_str());

  // Over budget: an error naming the molecule, exit 3, no file.
  skinmesh::test::TempFile none("none.off");
  std::remove(none.path().c_str());
  const Run budget = run("mesh " + skinmesh::test::data_file("pept.pdb") + " -o " + none.path() + " --max-triangles 500");
  CHECK(budget.code == 3);
  CHECK(budget.output.find("pept.pdb") != std::string::npos);
  CHECK(budget.output.find("budget") != std::string::npos);
  CHECK_FALSE(std::ifstream(none.path()).good());

  const Run format = run("mesh " + skinmesh::test::data_file("pept.pdb") + " -o " + none.path() + ".xyz");
  CHECK(format.code != 0);
  CHECK(format.output.find(".xyz") != std::string::npos);
  const Run missing = run("mesh /nonexistent/x.pdb -o " + none.path());
  CHECK(missing.code == 2);
  CHECK_FALSE(std::ifstream(none.path()).good());
}

TEST_CASE("skinmesh volume writes VTU, Gmsh and TetGen files with a report", "[cli][volume]") {
  skinmesh::test::TempFile report("volume.json");
  const std::string stem = report.path() + ".mesh";
  const Run r = run("--quiet volume " + skinmesh::test::data_file("pept.pdb") + " -o " + stem +
                    " --domain both --box-margin 4 --report " + report.path());
  INFO(r.output);
  REQUIRE(r.code == 0);
  // quality grades the written volume mesh: its boundary is exactly its marked faces.
  const Run graded = run("--json quality " + stem + ".msh");
  INFO(graded.output);
  REQUIRE(graded.code == 0);
  const nlohmann::json g = nlohmann::json::parse(graded.output);
  CHECK(g["boundary_faces_not_marked"] == 0);
  CHECK(g["marked_faces_not_on_boundary"] == 0);
  CHECK(g["inverted"] == 0);
  for (const char* ext : {".vtu", ".msh", ".node", ".ele", ".face"}) {
    std::ifstream in(stem + ext);
    CHECK(in.good());
    std::remove((stem + ext).c_str());
  }
  const nlohmann::json j = nlohmann::json::parse(std::ifstream(report.path()));
  CHECK(j["inverted"] == 0);
  CHECK(j["regions"].contains("interior"));
  CHECK(j["regions"].contains("solvent"));
  CHECK(j["regions"].contains("cavity"));
  CHECK(j["interior_volume_relative_difference"].get<double>() <= 1e-9);
  // What a solver needs to hear: a closed, oriented, manifold skin without
  // self-intersections (both checks), and elements within the bounds asked.
  CHECK(j["surface"]["closed"] == true);
  CHECK(j["surface"]["manifold"] == true);
  CHECK(j["surface_self_intersections"]["cgal_exact"] == 0);
  CHECK(j["surface_self_intersections"]["tetgen_triangles"] == 0);
  CHECK(j["bounds_met"] == true);
  CHECK(j["max_radius_edge_ratio"].get<double>() <= 2.0);
  CHECK(j["min_dihedral_deg"].get<double>() >= 5.0);
  CHECK(j["smoothing"]["out_of_bounds_after"] == 0);

  const Run bad = run("volume " + skinmesh::test::data_file("pept.pdb") + " -o " + stem + " --domain inside");
  CHECK(bad.code != 0);
  std::ifstream none(stem + ".vtu");
  CHECK(!none.good());

  // A volume bound past the tetrahedron budget (1,335 A^3 / 1e-4 A^3 is
  // 13 million) is refused before TetGen runs, naming what would fit.
  const std::string tiny_stem = stem + "-tiny";
  const Run tiny = run("volume " + skinmesh::test::data_file("pept.pdb") + " -o " + tiny_stem + " --max-volume 0.0001");
  INFO(tiny.output);
  CHECK(tiny.code == 3);
  CHECK(tiny.output.find("--max-volume of at least") != std::string::npos);
  for (const char* ext : {".vtu", ".msh", ".node", ".ele", ".face"}) CHECK(!std::ifstream(tiny_stem + ext).good());
}

TEST_CASE("skinmesh interpolate writes the live pairs of B(t) as weighted points", "[cli][interpolation]") {
  skinmesh::test::TempFile out("mid.wpts");
  std::remove(out.path().c_str());
  const std::string pept = skinmesh::test::data_file("pept.pdb"), al1 = skinmesh::test::data_file("3al1.pdb");
  const Run r = run("--json interpolate " + pept + " " + al1 + " --t 0.25 --centre -o " + out.path());
  INFO(r.output);
  REQUIRE(r.code == 0);
  const nlohmann::json j = nlohmann::json::parse(r.output);
  // Read back as a molecule: one ball per live pair, weights as written.
  const skinmesh::Molecule m = skinmesh::read_molecule(out.path());
  CHECK(static_cast<long>(m.atoms.size()) == j["balls"].get<long>());
  CHECK(j["balls"].get<long>() < j["all_pairs"].get<long>());
  long negative = 0;
  for (const auto& a : m.atoms) negative += *a.weight < 0;
  CHECK(negative == j["negative_weights"].get<long>());
  CHECK(negative > 0);  // weights dip in the middle of a morph
  // --all-pairs keeps m * n.
  const Run all = run("--json interpolate " + pept + " " + al1 + " --all-pairs -o " + out.path());
  REQUIRE(all.code == 0);
  CHECK(skinmesh::read_molecule(out.path()).atoms.size() == nlohmann::json::parse(all.output)["all_pairs"].get<size_t>());
  // XYZR cannot hold a negative weight: refused, nothing written.
  skinmesh::test::TempFile xyzr("mid.xyzr");
  std::remove(xyzr.path().c_str());
  const Run refused = run("interpolate " + pept + " " + al1 + " -o " + xyzr.path());
  CHECK(refused.code != 0);
  CHECK(refused.output.find(".wpts") != std::string::npos);
  CHECK(!std::ifstream(xyzr.path()).good());
}

TEST_CASE("numeric options refuse NaN and infinities when parsed", "[cli][bad]") {
  const std::string pept = skinmesh::test::data_file("pept.pdb");
  skinmesh::test::TempFile out("never.ply");
  for (const char* bad : {"--epsilon nan", "--tolerance inf", "--min-angle nan", "--edge-length -inf", "--shrink nan"}) {
    INFO(bad);
    const Run r = run("--quiet mesh " + pept + " -o " + out.path() + " " + std::string(bad));
    CHECK(r.code != 0);
    CHECK(r.output.find("finite") != std::string::npos);
  }
  const Run t = run("interpolate " + pept + " " + pept + " --t nan -o " + out.path() + ".wpts");
  CHECK(t.code != 0);
  CHECK(t.output.find("finite") != std::string::npos);
  std::ifstream none(out.path() + ".wpts");
  CHECK_FALSE(none.good());
}

TEST_CASE("outputs that cannot be written are refused before the work", "[cli][bad]") {
  const std::string pept = skinmesh::test::data_file("pept.pdb");
  skinmesh::test::TempFile dir_holder("x");
  const std::string folder = dir_holder.path().substr(0, dir_holder.path().rfind('/'));
  // The report is a directory: refused before meshing, and no mesh is left.
  skinmesh::test::TempFile mesh("m.ply");
  std::remove(mesh.path().c_str());
  const Run r = run("--quiet mesh " + pept + " -o " + mesh.path() + " --report " + folder);
  CHECK(r.code == 2);  // a bad option (docs/commands.md, exit codes)
  CHECK(r.output.find("is a directory") != std::string::npos);
  CHECK_FALSE(std::ifstream(mesh.path()).good());
  // A folder that does not exist, for the mesh and for a volume stem.
  const Run nowhere = run("--quiet mesh " + pept + " -o /nonexistent-skinmesh/m.ply");
  CHECK(nowhere.code == 2);
  CHECK(nowhere.output.find("/nonexistent-skinmesh/m.ply") != std::string::npos);
  const Run volume = run("--quiet volume " + pept + " -o /nonexistent-skinmesh/v");
  CHECK(volume.code == 2);
  CHECK(volume.output.find("cannot write") != std::string::npos);
}

TEST_CASE("every usage error exits 2, and a mistyped command or option is told the nearest name", "[cli][bad]") {
  const std::string pept = skinmesh::test::data_file("pept.pdb");
  skinmesh::test::TempFile out("never.off");
  std::remove(out.path().c_str());
  struct Case {
    std::string args, says;
  };
  const std::vector<Case> cases{
      {"msh " + pept, "did you mean 'mesh'?"},                                        // no such command
      {"mesh " + pept + " -o " + out.path() + " --edge-lenght 1", "did you mean '--edge-length'?"},  // no such option
      {"morph " + pept + " --frame 3 -o " + out.path(), "did you mean '--frames'?"},   // and a required one missing
      {"mesh " + pept + " -o " + out.path() + " --min-angle abc", "min-angle"},     // not a number
      {"mesh " + pept + " -o " + out.path() + " --min-angle", "min-angle"},          // an option without its value
      {"mesh " + pept + " -o " + out.path() + " --tolerance 0", "must be greater than 0, not 0"},  // out of range
      {"mesh " + pept + " -o " + out.path() + " --edge-length -1", "must be 0 or more, not -1"},
      {"morph " + pept + " " + pept + " --model 2 -o " + out.path(), "'--source-model' or '--target-model'"},
      {"mesh", "required"},                                                          // the input missing
      {"", "subcommand"},                                                            // no command
  };
  for (const Case& c : cases) {
    INFO(c.args);
    const Run r = run(c.args);
    CHECK(r.code == 2);
    CHECK(r.output.find(c.says) != std::string::npos);
  }
  CHECK_FALSE(std::ifstream(out.path()).good());
  for (const Case& c : cases) CHECK(run(c.args).output.size() < 400);  // no range written with 300 digits
  // --edge-length 0 means the same in every command: no cap, curvature only.
  CHECK(run("--quiet mesh " + pept + " -o " + out.path() + " --edge-length 0").code == 0);
  std::remove(out.path().c_str());
  CHECK(run("mesh --help").code == 0);
  CHECK(run("--version").code == 0);
}

TEST_CASE("morph refuses a directory holding an earlier run's frames, before any work", "[cli][bad][morph]") {
  const std::string pept = skinmesh::test::data_file("pept.pdb");
  skinmesh::test::TempFile holder("x");
  const std::string dir = holder.path() + "-earlier-run";
  std::filesystem::create_directory(dir);
  { std::ofstream(dir + "/frame_0007.ply") << "an earlier run's frame"; }
  const Run r = run("--quiet morph " + pept + " " + pept + " --frames 3 -o " + dir);
  CHECK(r.code == 2);
  CHECK(r.output.find("frame_0007.ply") != std::string::npos);
  size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) files += entry.is_regular_file();
  CHECK(files == 1);  // nothing written beside it
  const Run t = run("--quiet trajectory " + skinmesh::test::data_file("2k39_3models.pdb") + " -o " + dir);
  CHECK(t.code == 2);
  std::filesystem::remove_all(dir);
}

TEST_CASE("interpolate --all-pairs refuses a set that would not fit, at once", "[cli][bad]") {
  // 4,500 x 4,500 atoms: 20.25 million pairs, over the 20 million written.
  std::string atoms;
  for (int i = 0; i < 4500; ++i)
    atoms += std::to_string(3.0 * (i % 30)) + " " + std::to_string(3.0 * ((i / 30) % 30)) + " " +
             std::to_string(3.0 * (i / 900)) + " 1.5\n";
  skinmesh::test::TempFile big("big.xyzr", atoms);
  skinmesh::test::TempFile out("all.wpts");
  std::remove(out.path().c_str());
  const Run r = run("interpolate " + big.path() + " " + big.path() + " --all-pairs --t 0.5 -o " + out.path());
  CHECK(r.code == 2);
  CHECK(r.output.find("4500 x 4500") != std::string::npos);
  CHECK_FALSE(std::ifstream(out.path()).good());
}

TEST_CASE("extreme but legal inputs are refused at once, naming the sizes that would fit", "[cli][bad][estimate]") {
  // Each ran minutes to the triangle budget before the estimate (issue 14).
  skinmesh::test::TempFile ball("big_ball.xyzr", "0 0 0 1000\n");
  skinmesh::test::TempFile out("refused.ply");
  std::remove(out.path().c_str());
  const std::string pept = skinmesh::test::data_file("pept.pdb");
  // Exit 3, the file named, `says` in the message, no output of the command.
  auto refused = [&](const std::string& args, const std::string& input, const std::string& says) {
    const Run r = run(args + " -o " + out.path());
    INFO(r.output);
    CHECK(r.code == 3);
    CHECK(r.output.find(input) != std::string::npos);
    CHECK(r.output.find(says) != std::string::npos);
    CHECK_FALSE(std::ifstream(out.path()).good());
    CHECK_FALSE(std::ifstream(out.path() + ".vtu").good());
    return r.output;
  };
  refused("mesh " + ball.path(), "big_ball.xyzr", "this would fit: --max-size ");
  refused("mesh " + pept + " --tolerance 1e-300", "pept.pdb", "this would fit: --tolerance ");
  refused("mesh " + pept + " --max-memory 0.001", "pept.pdb", "more than the memory allows");
  // A weight of 1e8 (a skin sphere of radius 7,071 A) and a 0.001 A edge
  // length: the estimate, not only the lower bound, so that the sizes are named.
  skinmesh::test::TempFile heavy("heavy.wpts", "0 0 0 100000000\n");
  refused("mesh " + heavy.path(), "heavy.wpts", "this would fit: --max-size ");
  refused("mesh " + pept + " --edge-length 0.001", "pept.pdb", "this would fit: --edge-length ");
  // Necks sharper than any size: only a smaller shrink factor helps.
  refused("mesh " + pept + " --shrink 0.999999", "pept.pdb", "this would fit: --shrink 0.99");
  // volume sets the surface sizes by --epsilon and --edge-length only, and names only those.
  const std::string volume = refused("volume " + pept + " --edge-length 0.01", "pept.pdb", "this would fit: --edge-length ");
  CHECK(volume.find("--tolerance") == std::string::npos);
}

TEST_CASE("an empty skin is said to be empty, and non-UTF-8 names do not break --json", "[cli][bad]") {
  // Every weight negative: no surface. The error says so and names the file.
  skinmesh::test::TempFile negative("negative.wpts", "0 0 0 -1\n3 0 0 -2\n");
  skinmesh::test::TempFile out("empty.ply");
  std::remove(out.path().c_str());
  const Run empty = run("--quiet mesh " + negative.path() + " -o " + out.path());
  CHECK(empty.code == 2);
  CHECK(empty.output.find(negative.path()) != std::string::npos);
  CHECK(empty.output.find("skin of this ball set is empty") != std::string::npos);
  CHECK_FALSE(std::ifstream(out.path()).good());
  // A molecule file whose name is not UTF-8: the JSON report replaces the
  // bytes instead of failing after the mesh is written.
  std::ifstream pept(skinmesh::test::data_file("pept.pdb"));
  std::stringstream text;
  text << pept.rdbuf();
  skinmesh::test::TempFile odd("pept-\xff\xfe.pdb", text.str());
  const Run r = run("--json mesh " + odd.path() + " -o " + out.path());
  CHECK(r.code == 0);
  const size_t start = r.output.find('{');
  REQUIRE(start != std::string::npos);
  const nlohmann::json j = nlohmann::json::parse(r.output.substr(start));
  CHECK(j["molecule"].get<std::string>().find("\xef\xbf\xbd") != std::string::npos);  // U+FFFD
}

// B(1e-5) of pept -> 3al1 holds clusters of balls 1e-5 to 1e-3 A apart
// (pair (i, j) lies t |z_i - z_j| from z_i). The frame took minutes, walks
// along segments creeping through their sliver cells 1e-9 at a time; it
// takes about 2 s of CPU. A stall is killed at 60.
TEST_CASE("morph a step of 1e-5 in t from pept to 3al1 in bounded time", "[cli][morph][bad]") {
  char pattern[] = "/tmp/skinmesh-near-XXXXXX";
  REQUIRE(mkdtemp(pattern) != nullptr);
  const std::string dir = std::string(pattern) + "/out";
  const Run r = run_within(60, "morph " + skinmesh::test::data_file("pept.pdb") + " " +
                                   skinmesh::test::data_file("3al1.pdb") + " --t 0,0.00001 --format ply -o " + dir);
  INFO(r.output);
  REQUIRE(r.code == 0);
  std::ifstream jsonl(dir + "/frames.jsonl");
  std::string line;
  int frames = 0;
  while (std::getline(jsonl, line)) {
    const nlohmann::json f = nlohmann::json::parse(line);
    CHECK(f["min_angle"].get<double>() >= 20.0);
    CHECK(f["max_onsurf_error"].get<double>() <= 1e-9);
    ++frames;
  }
  CHECK(frames == 2);
  std::filesystem::remove_all(pattern);
}

TEST_CASE("skinmesh morph writes a self-describing directory of checked frames", "[cli][morph]") {
  char pattern[] = "/tmp/skinmesh-morph-XXXXXX";
  REQUIRE(mkdtemp(pattern) != nullptr);
  const std::string dir = std::string(pattern) + "/out";
  const std::string file = skinmesh::test::data_file("2k39_3models.pdb");
  const Run r = run("morph " + file + " " + file + " --source-model 1 --target-model 3 --pairs all --frames 4 -o " + dir);
  INFO(r.output);
  REQUIRE(r.code == 0);
  // stderr is a pipe here, as in a log: plain lines, the preparation shown,
  // the last frame's line always there.
  CHECK(r.output.find('\r') == std::string::npos);
  CHECK(r.output.find("skinmesh: preparing the morph") != std::string::npos);
  CHECK(r.output.find("skinmesh: frame 4/4") != std::string::npos);
  for (int k = 0; k < 4; ++k)
    for (const char* ext : {"ply", "vtp"}) {
      std::ifstream frame(dir + "/frame_000" + std::to_string(k) + "." + ext);
      CHECK(frame.good());
    }
  std::ifstream ply(dir + "/frame_0002.ply");
  std::string header, line;
  while (std::getline(ply, line) && line != "end_header") header += line + "\n";
  for (const char* property : {"property int id", "property uint atomid", "property uint source_atom",
                               "property uchar has_source_atom", "property uint target_atom", "property uchar has_target_atom"})
    CHECK(header.find(property) != std::string::npos);
  // frames.jsonl: one object per frame with the fields a user plots.
  std::ifstream jsonl(dir + "/frames.jsonl");
  int frames = 0;
  long from_scratch = 0, repaired = 0, remeshed = 0;
  while (std::getline(jsonl, line)) {
    const auto j = nlohmann::json::parse(line);
    from_scratch += j.value("full_rebuild", false);
    repaired += j.value("repaired", false);
    // A frame remeshed whole says why; one that was not has no reason.
    REQUIRE(j.contains("remeshed"));
    REQUIRE(j.contains("remeshed_because"));
    if (j["remeshed"].get<bool>()) {
      ++remeshed;
      CHECK(!j["remeshed_because"].get<std::string>().empty());
    } else {
      CHECK(j["remeshed_because"].is_null());
    }
    for (const char* key : {"t", "file", "vertices", "triangles", "min_angle", "share_below_bound", "moved",
                            "relocated", "inserted", "removed", "repairs", "full_rebuild", "max_onsurf_error",
                            "oracle_uncertified", "components", "euler", "seconds"})
      CHECK(j.contains(key));
    // Where the frame's time went: stages that do not overlap, within the frame's seconds.
    double stages = 0;
    for (const char* key : {"seconds_complex", "seconds_transport", "seconds_relax", "seconds_judge", "seconds_repair"}) {
      REQUIRE(j.contains(key));
      CHECK(j[key].get<double>() >= 0);
      stages += j[key].get<double>();
    }
    CHECK(stages <= j["seconds"].get<double>());
    // The edits and the patches are parts of the repair.
    REQUIRE(j.contains("seconds_edits"));
    REQUIRE(j.contains("seconds_patch"));
    CHECK(j["seconds_edits"].get<double>() >= 0);
    CHECK(j["seconds_patch"].get<double>() >= 0);
    CHECK(j["seconds_edits"].get<double>() + j["seconds_patch"].get<double>() <= j["seconds_repair"].get<double>());
    CHECK((j["patch_attempts"].get<long>() > 0) == (j["seconds_patch"].get<double>() > 0));
    CHECK(j["min_angle"].get<double>() >= 20.0);
    CHECK(j["max_onsurf_error"].get<double>() <= 1e-8);
    ++frames;
  }
  CHECK(frames == 4);
  CHECK(remeshed >= 1);  // t = 1, on the target's own complex
  std::ifstream pvd(dir + "/frames.pvd");
  std::stringstream pvd_text;
  pvd_text << pvd.rdbuf();
  CHECK(pvd_text.str().find("frame_0003.vtp") != std::string::npos);
  std::ifstream morph_json(dir + "/morph.json");
  const auto m = nlohmann::json::parse(morph_json);
  CHECK(m["alignment"]["method"] == "kabsch");
  CHECK(m["alignment"]["matched_atoms"] == 78);
  // The terminal's summary, morph.json and frames.jsonl count the frames alike.
  CHECK(from_scratch >= 1);  // the first frame
  CHECK(m["full_rebuilds"] == from_scratch);
  CHECK(m["repaired_frames"] == repaired);
  CHECK(m["remeshed_frames"] == remeshed);
  CHECK(r.output.find("4 frames (" + std::to_string(from_scratch) + " meshed from scratch, " + std::to_string(repaired) +
                      " repaired, " + std::to_string(remeshed) + " remeshed whole)") != std::string::npos);
  CHECK(m["frame_times"].size() == 4);
  // The source's balls read back bit for bit from source.xyzr.
  skinmesh::ReadOptions model1;
  const auto original = skinmesh::balls_from_molecule(skinmesh::read_molecule(file, model1), 0.5);
  const auto written = skinmesh::balls_from_molecule(skinmesh::read_molecule(dir + "/source.xyzr"), 0.5);
  REQUIRE(written.size() == original.size());
  for (size_t i = 0; i < written.size(); ++i) {
    CHECK(written[i].center == original[i].center);
    CHECK(written[i].weight == original[i].weight);
  }
  // A molecule onto itself: the Kabsch fit leaves every atom within
  // rounding of itself; they are put exactly on their source atoms, and
  // every frame is the molecule's own skin.
  const std::string itself = std::string(pattern) + "/itself";
  const Run same = run("--quiet morph " + file + " " + file + " --frames 3 -o " + itself);
  INFO(same.output);
  REQUIRE(same.code == 0);
  std::ifstream itself_json(itself + "/morph.json");
  CHECK(nlohmann::json::parse(itself_json)["alignment"]["unmoved_atoms"] == 78);
  // Bad requests: nothing written, non-zero exit.
  const std::string second = std::string(pattern) + "/second";
  const Run backwards = run("morph " + file + " " + file + " --t 0.5,0.2 -o " + second);
  CHECK(backwards.code != 0);
  CHECK(backwards.output.find("increase") != std::string::npos);
  std::ifstream none(second + "/morph.json");
  CHECK_FALSE(none.good());
  std::system(("rm -rf " + std::string(pattern)).c_str());
}

// A PDB file's atoms moved by `shift` (columns 31-54 rewritten; the rest kept).
std::string shifted_pdb(const std::string& path, const Eigen::Vector3d& shift) {
  std::ifstream in(path);
  std::ostringstream out;
  std::string line;
  while (std::getline(in, line)) {
    if ((line.rfind("ATOM", 0) == 0 || line.rfind("HETATM", 0) == 0) && line.size() >= 54) {
      char xyz[32];
      std::snprintf(xyz, sizeof xyz, "%8.3f%8.3f%8.3f", std::stod(line.substr(30, 8)) + shift[0],
                    std::stod(line.substr(38, 8)) + shift[1], std::stod(line.substr(46, 8)) + shift[2]);
      line.replace(30, 24, xyz);
    }
    out << line << "\n";
  }
  return out.str();
}

TEST_CASE("skinmesh morph --pairs matched: a translated molecule travels rigidly, ids kept, each frame's balls written",
          "[cli][morph][moving]") {
  char pattern[] = "/tmp/skinmesh-matched-XXXXXX";
  REQUIRE(mkdtemp(pattern) != nullptr);
  const std::string source = skinmesh::test::data_file("pept.pdb");
  const std::string target = std::string(pattern) + "/pept-moved.pdb";
  std::ofstream(target) << shifted_pdb(source, Eigen::Vector3d(20, 0, 0));
  const std::string dir = std::string(pattern) + "/out";
  const Run r = run("--quiet morph " + source + " " + target + " --align none --frames 5 -o " + dir);
  INFO(r.output);
  REQUIRE(r.code == 0);
  std::ifstream morph_json(dir + "/morph.json");
  const auto m = nlohmann::json::parse(morph_json);
  CHECK(m["pairs"] == "matched");  // the default for one molecule
  CHECK(m["matched_atoms"] == 107);
  const skinmesh::SurfaceMesh first = skinmesh::read_surface_mesh(dir + "/frame_0000.ply");
  for (int k = 1; k < 5; ++k) {
    const double t = k / 4.0;
    const skinmesh::SurfaceMesh frame = skinmesh::read_surface_mesh(dir + "/frame_000" + std::to_string(k) + ".ply");
    REQUIRE(frame.vertices.size() == first.vertices.size());
    CHECK(frame.triangles == first.triangles);
    double worst = 0;
    for (size_t v = 0; v < frame.vertices.size(); ++v)
      worst = std::max(worst, (frame.vertices[v] - first.vertices[v] - Eigen::Vector3d(20 * t, 0, 0)).norm());
    CHECK(worst < 1e-9);
    // The frame's balls, read back from its .wpts, carry it: every vertex on their skin.
    const auto balls = skinmesh::balls_from_molecule(
        skinmesh::read_molecule(dir + "/frame_000" + std::to_string(k) + ".wpts"), 0.5);
    const skinmesh::SkinOracle oracle(balls, 0.5);
    double off = 0;
    for (const auto& x : frame.vertices) off = std::max(off, oracle.evaluate(x).distance());
    CHECK(off < 1e-8);
  }
  std::ifstream jsonl(dir + "/frames.jsonl");
  std::string line;
  int frames = 0;
  while (std::getline(jsonl, line)) {
    const auto j = nlohmann::json::parse(line);
    if (frames++ == 0) continue;
    CHECK(j["ids_kept"].get<double>() == 1.0);
    CHECK(j["repaired"] == false);
    CHECK(j["components"] == j["skin_topology"]["components"]);
    CHECK(j["euler"] == j["skin_topology"]["euler"]);
  }
  CHECK(frames == 5);
  // --pairs all: the m x n blend, said so (on this pair it would vanish: at
  // t = 1/2 every weight falls by 100 A^2, so the molecule onto itself).
  const Run all = run("--quiet morph " + source + " " + source + " --pairs all --t 0.5 -o " + dir + "-all");
  INFO(all.output);
  REQUIRE(all.code == 0);
  std::ifstream all_json(dir + "-all/morph.json");
  CHECK(nlohmann::json::parse(all_json)["pairs"] == "all");
  std::system(("rm -rf " + std::string(pattern)).c_str());
}

TEST_CASE("skinmesh --version, and reports that say which version wrote them and how it was called", "[cli]") {
  const Run v = run("--version");
  CHECK(v.code == 0);
  CHECK(v.output.rfind("skinmesh 0.", 0) == 0);
  char pattern[] = "/tmp/skinmesh-version-XXXXXX";
  REQUIRE(mkdtemp(pattern) != nullptr);
  const std::string report = std::string(pattern) + "/r.json";
  const Run r = run("--quiet mesh " + skinmesh::test::data_file("pept.pdb") + " -o " + pattern + "/p.ply --report " + report);
  REQUIRE(r.code == 0);
  std::ifstream in(report);
  const auto j = nlohmann::json::parse(in);
  CHECK(j["skinmesh_version"].get<std::string>().rfind(v.output.substr(9, 5), 0) == 0);
  CHECK(j["command_line"].get<std::string>().find("mesh " + skinmesh::test::data_file("pept.pdb")) != std::string::npos);
  std::system(("rm -rf " + std::string(pattern)).c_str());
}

TEST_CASE("skinmesh morph --spacing change: frames at equal shares of the largest ball move", "[cli][morph][large]") {
  char pattern[] = "/tmp/skinmesh-spacing-XXXXXX";
  REQUIRE(mkdtemp(pattern) != nullptr);
  const std::string dir = std::string(pattern) + "/out";
  const std::string pept = skinmesh::test::data_file("pept.pdb"), al1 = skinmesh::test::data_file("3al1.pdb");
  const Run r = run("--quiet morph " + pept + " " + al1 + " --frames 6 --spacing change --no-self-intersections -o " + dir);
  INFO(r.output);
  REQUIRE(r.code == 0);
  std::ifstream morph_json(dir + "/morph.json");
  const auto m = nlohmann::json::parse(morph_json);
  CHECK(m["spacing"] == "change");
  const std::vector<double> t = m["frame_times"].get<std::vector<double>>();
  REQUIRE(t.size() == 6);
  CHECK(t.front() == 0.0);
  CHECK(t.back() == 1.0);
  // The change between frames, recomputed here from B(t) on a grid of its
  // own: each step's share within 20% of the mean, where uniform steps of t
  // differ by more than a factor of 2 on this pair.
  std::vector<skinmesh::Ball> a = skinmesh::balls_from_molecule(skinmesh::read_molecule(pept), 0.5);
  std::vector<skinmesh::Ball> b = skinmesh::balls_from_molecule(skinmesh::read_molecule(al1), 0.5);
  const std::string moved_target = dir + "/target.xyzr";  // the target after alignment, as the morph used it
  b = skinmesh::balls_from_molecule(skinmesh::read_molecule(moved_target), 0.5);
  const auto live = skinmesh::live_pairs(a, b);
  const auto change = [&](double from, double to) {
    double sum = 0;
    const int grid = 1600;
    std::vector<skinmesh::Ball> before = skinmesh::interpolated_balls(a, b, live, from);
    for (int g = 1; g <= grid; ++g) {
      const auto now = skinmesh::interpolated_balls(a, b, live, from + (to - from) * g / grid);
      double largest = 0;
      for (size_t i = 0; i < now.size(); ++i)
        largest = std::max(largest, (now[i].center - before[i].center).norm() +
                                        std::abs(std::sqrt(0.5 * std::max(now[i].weight, 0.0)) -
                                                 std::sqrt(0.5 * std::max(before[i].weight, 0.0))));
      sum += largest;
      before = now;
    }
    return sum;
  };
  std::vector<double> steps, uniform;
  for (size_t k = 1; k < t.size(); ++k) {
    steps.push_back(change(t[k - 1], t[k]));
    uniform.push_back(change((k - 1) / 5.0, k / 5.0));
  }
  const double mean = std::accumulate(steps.begin(), steps.end(), 0.0) / steps.size();
  for (double c : steps) CHECK(std::abs(c - mean) <= 0.1 * mean);
  CHECK(*std::max_element(uniform.begin(), uniform.end()) > 2 * *std::min_element(uniform.begin(), uniform.end()));
  const Run with_t = run("--quiet morph " + pept + " " + al1 + " --t 0.5 --spacing change -o " + dir + "-t");
  CHECK(with_t.code == 2);
  std::system(("rm -rf " + std::string(pattern)).c_str());
}

TEST_CASE("skinmesh trajectory: one morph through every model, each keyframe the model's own skin",
          "[cli][morph][moving]") {
  char pattern[] = "/tmp/skinmesh-trajectory-XXXXXX";
  REQUIRE(mkdtemp(pattern) != nullptr);
  const std::string dir = std::string(pattern) + "/out";
  const std::string file = skinmesh::test::data_file("2k39_3models.pdb");
  const Run r = run("--quiet trajectory " + file + " --frames-per-step 3 -o " + dir);
  INFO(r.output);
  REQUIRE(r.code == 0);
  std::ifstream report(dir + "/trajectory.json");
  const auto j = nlohmann::json::parse(report);
  CHECK(j["keyframes"] == nlohmann::json({0, 3, 6}));
  CHECK(j["frames"] == 7);
  // Keyframe 2 (frame 6) is model 3 fitted onto model 1: its balls as written
  // equal the model's after the fit, and the frame lies on their skin with
  // the skin's topology.
  const auto balls = skinmesh::balls_from_molecule(skinmesh::read_molecule(dir + "/frame_0006.wpts"), 0.5);
  skinmesh::ReadOptions third;
  third.model = 3;
  CHECK(balls.size() == skinmesh::read_molecule(file, third).atoms.size());
  const skinmesh::SurfaceMesh frame = skinmesh::read_surface_mesh(dir + "/frame_0006.ply");
  const skinmesh::SkinOracle oracle(balls, 0.5);
  double off = 0;
  for (const auto& x : frame.vertices) off = std::max(off, oracle.evaluate(x).distance());
  CHECK(off < 1e-8);
  std::ifstream jsonl(dir + "/frames.jsonl");
  std::string line;
  while (std::getline(jsonl, line)) {
    const auto f = nlohmann::json::parse(line);
    CHECK(f["components"] == f["skin_topology"]["components"]);
    CHECK(f["euler"] == f["skin_topology"]["euler"]);
    CHECK(f["min_angle"].get<double>() >= 20.0);
  }
  // A model whose atoms differ is refused, naming the file and the model.
  const Run one = run("--quiet trajectory " + file + " --models 2-2 -o " + dir + "-one");
  CHECK(one.code == 2);
  CHECK(one.output.find("at least two models") != std::string::npos);
  std::system(("rm -rf " + std::string(pattern)).c_str());
}

namespace {

std::string bytes_of(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Ubiquitin as two models, the second with the atoms of residues 1-8 moved
// 0.4 A along x: the rest of the surface stays where it was.
void write_two_ubiquitin_models(const std::string& path) {
  std::ifstream in(skinmesh::test::data_file("1ubi.pdb"));
  std::vector<std::string> atoms;
  for (std::string line; std::getline(in, line);)
    if (line.rfind("ATOM", 0) == 0) atoms.push_back(line);
  std::ofstream out(path);
  for (int model = 1; model <= 2; ++model) {
    out << "MODEL     " << model << "\n";
    for (std::string line : atoms) {
      if (model == 2 && std::stoi(line.substr(22, 4)) <= 8) {
        char x[9];
        std::snprintf(x, sizeof x, "%8.3f", std::stod(line.substr(30, 8)) + 0.4);
        line.replace(30, 8, x);
      }
      out << line << "\n";
    }
    out << "ENDMDL\n";
  }
  out << "END\n";
}

// The triangles of frame k of `dir` (PLY, with ids) that frame k - 1 does
// not have: by their corners' ids, each corner where it was.
long changed_triangles(const std::string& dir, size_t k) {
  const auto read = [&](size_t frame) {
    char name[32];
    std::snprintf(name, sizeof name, "/frame_%04zu.ply", frame);
    return skinmesh::read_ply_with_properties(dir + name);
  };
  const skinmesh::PlyMesh before = read(k - 1), now = read(k);
  const std::vector<double>& ids_before = before.vertex_properties.at("id");
  const std::vector<double>& ids_now = now.vertex_properties.at("id");
  std::map<long, Eigen::Vector3d> place;
  for (size_t v = 0; v < ids_before.size(); ++v) place[static_cast<long>(ids_before[v])] = before.mesh.vertices[v];
  const auto key = [](const std::array<int, 3>& t, const std::vector<double>& ids) {
    std::array<long, 3> k3{static_cast<long>(ids[static_cast<size_t>(t[0])]), static_cast<long>(ids[static_cast<size_t>(t[1])]),
                           static_cast<long>(ids[static_cast<size_t>(t[2])])};
    std::sort(k3.begin(), k3.end());
    return k3;
  };
  std::set<std::array<long, 3>> had;
  for (const auto& t : before.mesh.triangles) had.insert(key(t, ids_before));
  long changed = 0;
  for (const auto& t : now.mesh.triangles) {
    bool same = had.count(key(t, ids_now)) > 0;
    for (int v : t) {
      const auto it = place.find(static_cast<long>(ids_now[static_cast<size_t>(v)]));
      same = same && it != place.end() && it->second == now.mesh.vertices[static_cast<size_t>(v)];
    }
    changed += !same;
  }
  return changed;
}

}  // namespace

TEST_CASE("skinmesh trajectory: a later frame's self-intersection test takes the pairs with a changed triangle",
          "[cli][morph][moving]") {
  // The frames are the same with every pair tested; the first frame tests
  // every triangle, each later one those it does not share with the frame
  // before (by the ids and places its PLY file gives), at least one of them
  // fewer than all, and no frame has a crossing pair. Asking to skip the test and to
  // test every pair at once is refused.
  char pattern[] = "/tmp/skinmesh-crossings-XXXXXX";
  REQUIRE(mkdtemp(pattern) != nullptr);
  const std::string base = pattern, models = base + "/two.pdb";
  write_two_ubiquitin_models(models);
  const std::string common = "--quiet trajectory " + models + " --align none --frames-per-step 3 --format ply -o ";
  const Run changed = run(common + base + "/changed");
  INFO(changed.output);
  REQUIRE(changed.code == 0);
  const Run all = run(common + base + "/all --self-intersections all");
  INFO(all.output);
  REQUIRE(all.code == 0);
  const std::vector<nlohmann::json> some = skinmesh::test::frame_lines(base + "/changed");
  const std::vector<nlohmann::json> every = skinmesh::test::frame_lines(base + "/all");
  REQUIRE(some.size() == 4);
  REQUIRE(every.size() == some.size());
  int fewer = 0;  // later frames that tested fewer triangles than they have
  for (size_t k = 0; k < some.size(); ++k) {
    INFO("frame " << k);
    const std::string name = some[k]["file"].get<std::string>();
    CHECK(bytes_of(base + "/changed/" + name) == bytes_of(base + "/all/" + name));
    CHECK(some[k]["self_intersecting_pairs"] == 0);
    CHECK(every[k]["self_intersecting_pairs"] == 0);
    CHECK(every[k]["self_intersection_triangles_tested"] == every[k]["triangles"]);
    const long tested = some[k]["self_intersection_triangles_tested"].get<long>();
    CHECK(tested == (k == 0 ? some[k]["triangles"].get<long>() : changed_triangles(base + "/changed", k)));
    fewer += k > 0 && tested < some[k]["triangles"].get<long>();
  }
  CHECK(fewer > 0);
  const Run both = run(common + base + "/both --self-intersections all --no-self-intersections");
  CHECK(both.code == 2);
  CHECK_FALSE(std::filesystem::exists(base + "/both"));
  std::system(("rm -rf " + base).c_str());
}

// At t = 0.9999 on 2k39 model 1 -> 3 (centroid, no Kabsch fit) the morph
// oracle leaves a vertex or two uncertified (a KKT gap of 3e-6, its distance
// 4.3e-6 A), and the command refused a frame that is on the skin. Those
// vertices are measured on B(t)'s own complex instead (cmd_morph.cpp,
// check_frame), and counted.
// Near t = 1 the pair balls of one target atom nearly coincide: the morph
// oracle's solve over pairs left two vertices of this frame uncertified (a
// KKT gap of 3e-6), which were then measured on B(t)'s own complex. Solving
// again in the split unknowns certifies them.
TEST_CASE("skinmesh morph near t = 1: the morph oracle certifies every vertex", "[cli][morph]") {
  char pattern[] = "/tmp/skinmesh-morph-end-XXXXXX";
  REQUIRE(mkdtemp(pattern) != nullptr);
  const std::string dir = std::string(pattern) + "/out";
  const std::string file = skinmesh::test::data_file("2k39_3models.pdb");
  const Run r = run("--quiet morph " + file + " " + file +
                    " --source-model 1 --target-model 3 --align centroid --pairs all --t 0.9999 -o " + dir);
  INFO(r.output);
  REQUIRE(r.code == 0);
  const std::vector<nlohmann::json> frames = skinmesh::test::frame_lines(dir);
  REQUIRE(frames.size() == 1);
  CHECK(frames[0]["oracle_uncertified"].get<long>() == 0);
  CHECK(frames[0]["max_onsurf_error"].get<double>() <= 1e-8);
  std::system(("rm -rf " + std::string(pattern)).c_str());
}

// The blend's check counts the skin's topology afresh only where it may
// have changed since the last count (blend_topology.hpp): every frame's
// count, carried or not, is that of its own balls, read back from the
// balls the command wrote and counted here from scratch.
TEST_CASE("skinmesh morph --pairs all: a frame's skin topology, carried or counted, is its own balls'",
          "[cli][morph]") {
  char pattern[] = "/tmp/skinmesh-morph-carried-XXXXXX";
  REQUIRE(mkdtemp(pattern) != nullptr);
  const std::string dir = std::string(pattern) + "/out";
  const std::string file = skinmesh::test::data_file("2k39_3models.pdb");
  const Run r = run("--quiet morph " + file + " " + file + " --source-model 1 --target-model 3 --pairs all" +
                    " --t 0.3,0.31,0.32,0.33,0.34,0.35,0.36,0.37 -o " + dir);
  INFO(r.output);
  REQUIRE(r.code == 0);
  const auto source = skinmesh::balls_from_molecule(skinmesh::read_molecule(dir + "/source.xyzr"), 0.5);
  const auto target = skinmesh::balls_from_molecule(skinmesh::read_molecule(dir + "/target.xyzr"), 0.5);
  const auto pairs = skinmesh::live_pairs(source, target);
  long carried = 0;
  for (const nlohmann::json& f : skinmesh::test::frame_lines(dir)) {
    const double t = f["t"].get<double>(), counted_at = f["skin_topology"]["counted_at_t"].get<double>();
    INFO("t = " << t << ", counted at " << counted_at);
    const skinmesh::SkinTopology own = skinmesh::skin_topology(skinmesh::interpolated_balls(source, target, pairs, t));
    CHECK(f["skin_topology"]["components"] == own.components);
    CHECK(f["skin_topology"]["voids"] == own.voids);
    CHECK(f["skin_topology"]["euler"] == own.euler);
    CHECK(counted_at <= t);
    carried += counted_at < t;
  }
  CHECK(carried >= 4);
  std::system(("rm -rf " + std::string(pattern)).c_str());
}

// An interrupted morph leaves nothing: the frames staged so far, their
// temporaries and the directory it made are removed, and the process ends
// by the signal. The signal is sent once a frame's temporary exists.
TEST_CASE("an interrupted command leaves no output behind", "[cli][bad][interrupt]") {
  const std::string file = skinmesh::test::data_file("2k39_3models.pdb");
  for (int signal : {SIGTERM, SIGINT}) {
    INFO("signal " << signal);
    char pattern[] = "/tmp/skinmesh-interrupt-XXXXXX";
    REQUIRE(mkdtemp(pattern) != nullptr);
    const std::string dir = std::string(pattern) + "/out";
    const pid_t pid = fork();
    REQUIRE(pid >= 0);
    if (pid == 0) {
      const int quiet = open("/dev/null", O_WRONLY);  // only async-signal-safe calls after fork
      dup2(quiet, 1);
      dup2(quiet, 2);
      execl(SKINMESH_BINARY, SKINMESH_BINARY, "morph", file.c_str(), file.c_str(), "--source-model", "1",
            "--target-model", "3", "--frames", "200", "-o", dir.c_str(), static_cast<char*>(nullptr));
      std::_Exit(127);
    }
    auto staged = [&] {
      std::error_code error;
      for (const auto& entry : std::filesystem::directory_iterator(dir, error))
        if (entry.path().filename().string().rfind(".skinmesh-", 0) == 0) return true;
      return false;
    };
    bool seen = false;
    for (int wait = 0; wait < 1200 && !seen; ++wait) {  // at most 60 s
      usleep(50000);
      seen = staged();
    }
    CHECK(seen);
    kill(pid, signal);
    int status = 0;
    REQUIRE(waitpid(pid, &status, 0) == pid);
    CHECK(WIFSIGNALED(status));
    if (WIFSIGNALED(status)) CHECK(WTERMSIG(status) == signal);
    CHECK_FALSE(std::filesystem::exists(dir));
    CHECK(std::filesystem::is_empty(pattern));
    std::filesystem::remove_all(pattern);
  }
}

TEST_CASE("the example at the end of every command's help runs as written", "[cli][large]") {
  const std::string data = skinmesh::test::data_file("pept.pdb").substr(0, skinmesh::test::data_file("pept.pdb").rfind('/') + 1);
  skinmesh::test::TempFile holder("x");
  const std::string dir = holder.path() + "-examples";
  std::filesystem::create_directory(dir);
  // In the order that makes what a later example reads (quality reads mesh's output).
  for (const char* command : {"info", "mesh", "quality", "volume", "interpolate", "morph", "trajectory", "render", "view"}) {
    INFO(command);
    const Run help = run(std::string(command) + " --help");
    const size_t at = help.output.find("Example:\n  ");
    REQUIRE(at != std::string::npos);
    std::string example = help.output.substr(at + 11);
    example = example.substr(0, example.find('\n'));
    REQUIRE(example.rfind("skinmesh ", 0) == 0);
    for (size_t p = example.find("data/"); p != std::string::npos; p = example.find("data/", p + data.size()))
      example.replace(p, 5, data);
    const std::string line = "cd " + dir + " && " + SKINMESH_BINARY + " --quiet " + example.substr(9) + " > /dev/null 2>&1";
    INFO(line);
    CHECK(std::system(line.c_str()) == 0);
  }
  std::filesystem::remove_all(dir);
}

TEST_CASE("mesh --outer-only keeps the outer surface, and the report gives the skin's own area", "[cli][mesh][large]") {
  skinmesh::test::TempFile out("outer.ply");
  skinmesh::test::TempFile report("outer.json");
  const Run r = run("--quiet mesh " + skinmesh::test::data_file("1ubi.pdb") + " -o " + out.path() + " --outer-only --report " +
                    report.path());
  REQUIRE(r.code == 0);
  std::ifstream in(report.path());
  const auto j = nlohmann::json::parse(in);
  CHECK(j["outer_only"] == true);
  CHECK(j["quality"]["components"] == 1);  // 1ubi: one outer surface and ten cavities
  CHECK(j["quality"]["cavities"] == 0);
  CHECK(j["components_dropped"] == 10);
  CHECK(j["guarantees"]["min_angle_at_least_bound"] == true);
  const auto& area = j["skin_area"];
  CHECK(area["converged"] == true);
  CHECK(area["mesh"].get<double>() == j["quality"]["area"].get<double>());
  CHECK(area["skin"].get<double>() > area["mesh"].get<double>());  // chords cut the convex skin short
  CHECK(area["uncertainty"].get<double>() < 1e-3 * area["skin"].get<double>());
}

TEST_CASE("render draws a molecule's skin or a mesh file into a PNG", "[cli][render]") {
  skinmesh::test::TempFile png("pept.png");
  skinmesh::test::TempFile ply("pept-render.ply");
  const std::string pept = skinmesh::test::data_file("pept.pdb");
  const Run drawn = run("--json render " + pept + " -o " + png.path() + " --colour element --width 200 --height 150");
  REQUIRE(drawn.code == 0);
  const auto j = nlohmann::json::parse(drawn.output.substr(drawn.output.find('{')));
  CHECK(j["covered_pixels"].get<long>() > 200 * 150 / 10);  // the skin fills a good part of the picture
  CHECK(j["covered_pixels"].get<long>() < 200 * 150);       // and leaves background
  std::ifstream in(png.path(), std::ios::binary);
  std::string signature(8, '\0');
  in.read(&signature[0], 8);
  CHECK(signature == std::string("\x89PNG\r\n\x1a\n", 8));
  REQUIRE(run("--quiet mesh " + pept + " -o " + ply.path()).code == 0);
  const Run mesh = run("--json render " + ply.path() + " -o " + png.path());
  REQUIRE(mesh.code == 0);
  CHECK(mesh.output.find("\"colour\": \"uniform\"") != std::string::npos);
  const Run missing = run("render /nonexistent/x.pdb -o " + png.path());
  CHECK(missing.code == 2);
}

TEST_CASE("a morph whose frame the mesher refuses exits as mesh does, naming the inputs, writing nothing", "[cli][bad][morph]") {
  skinmesh::test::TempFile negative("negative.wpts", "0 0 0 -1\n5 0 0 -2\n");
  skinmesh::test::TempFile here("here.xyzr", "0 0 0 1.5\n");
  skinmesh::test::TempFile far("far.xyzr", "100 0 0 1.5\n");
  const std::string pept = skinmesh::test::data_file("pept.pdb");
  const std::string dir = negative.path() + "-morph";
  struct Case {
    std::string args;
    int code;
    std::vector<std::string> says;
  };
  const std::vector<Case> cases{
      {"morph " + negative.path() + " " + pept, 2, {negative.path(), "empty"}},  // an empty side: bad input
      {"morph " + pept + " " + negative.path(), 2, {negative.path(), "empty"}},
      {"morph " + here.path() + " " + far.path() + " --align none --pairs all", 2,  // B(1/2) empty
       {here.path(), far.path(), "empty"}},
      {"morph " + pept + " " + skinmesh::test::data_file("3al1.pdb") + " --max-triangles 100", 3,  // over budget
       {"budget", "--max-triangles"}},
  };
  for (const Case& c : cases) {
    INFO(c.args);
    const Run r = run(c.args + " --frames 3 -o " + dir);
    CHECK(r.code == c.code);
    for (const std::string& s : c.says) CHECK(r.output.find(s) != std::string::npos);
    CHECK_FALSE(std::filesystem::exists(dir));
  }
}

TEST_CASE("outputs named alike are refused before any work, naming both", "[cli][bad]") {
  const std::string pept = skinmesh::test::data_file("pept.pdb");
  skinmesh::test::TempFile holder("x");
  const std::string base = holder.path() + "-alike";
  struct Case {
    std::string args, says;
    std::vector<std::string> never;  // files that must not exist afterwards
  };
  const std::vector<Case> cases{
      {"mesh " + pept + " -o " + base + ".ply --report " + base + ".ply", base + ".ply", {base + ".ply"}},
      {"mesh " + pept + " -o " + base + ".ply --svg " + base + "/../" + base.substr(base.rfind('/') + 1) + ".ply",
       "two outputs", {base + ".ply"}},
      {"volume " + pept + " -o " + base + " --report " + base + ".msh", base + ".msh",
       {base + ".msh", base + ".vtu"}},
      {"morph " + pept + " " + pept + " --frames 3 --format ply,ply -o " + base + "-dir", "ply twice", {base + "-dir"}},
  };
  for (const Case& c : cases) {
    INFO(c.args);
    const Run r = run("--quiet " + c.args);
    CHECK(r.code == 2);
    CHECK(r.output.find(c.says) != std::string::npos);
    for (const std::string& f : c.never) CHECK_FALSE(std::filesystem::exists(f));
  }
}

TEST_CASE("out of memory is an error naming the job, exit 3, nothing written", "[cli][bad][oom]") {
  // Under an address-space limit that the morph's first frame exceeds.
  skinmesh::test::TempFile holder("x");
  const std::string dir = holder.path() + "-oom";
  const std::string command = "ulimit -v 150000; " + std::string(SKINMESH_BINARY) + " --quiet morph " +
                              skinmesh::test::data_file("3al1.pdb") + " " + skinmesh::test::data_file("1ubi.pdb") +
                              " --frames 3 -o " + dir + " > " + holder.path() + " 2>&1";
  const int status = std::system(("bash -c '" + command + "'").c_str());
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 3);
  std::ifstream said(holder.path());
  std::stringstream text;
  text << said.rdbuf();
  CHECK(text.str().find("out of memory running") != std::string::npos);
  CHECK(text.str().find("3al1.pdb") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(dir));
  // The estimate before meshing counts the limit as memory: a mesh that
  // cannot fit under it is refused at once with the sizes that would.
  const std::string mesh = "ulimit -v 400000; " + std::string(SKINMESH_BINARY) + " --quiet mesh " +
                           skinmesh::test::data_file("3mht.pdb") + " --epsilon 0.3 -o " + dir + ".ply > " +
                           holder.path() + " 2>&1";
  const int refused = std::system(("bash -c '" + mesh + "'").c_str());
  REQUIRE(WIFEXITED(refused));
  CHECK(WEXITSTATUS(refused) == 3);
  std::ifstream said_mesh(holder.path());
  std::stringstream mesh_text;
  mesh_text << said_mesh.rdbuf();
  CHECK(mesh_text.str().find("more than the memory allows") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(dir + ".ply"));
}

TEST_CASE("morph and interpolate say what the readers warn of, as mesh does", "[cli][bad]") {
  const std::string crambin = skinmesh::test::data_file("1ejg.pdb");  // two microheterogeneous residues
  skinmesh::test::TempFile out("crambin.wpts");
  const Run interpolate = run("interpolate " + crambin + " " + crambin + " --t 0.5 -o " + out.path());
  CHECK(interpolate.code == 0);
  CHECK(interpolate.output.find("warning: " + crambin + ": chain A residue 22 is microheterogeneous") != std::string::npos);
  const std::string dir = out.path() + "-morph";
  const Run morph = run("morph " + crambin + " " + crambin + " --frames 2 -o " + dir);
  CHECK(morph.code == 0);
  CHECK(morph.output.find("residue 25 is microheterogeneous") != std::string::npos);
  std::filesystem::remove_all(dir);
  CHECK(run("--quiet interpolate " + crambin + " " + crambin + " --t 0.5 -o " + out.path()).output.find("warning") ==
        std::string::npos);
}

TEST_CASE("a write the system refuses names the file and the reason, and leaves nothing", "[cli][bad]") {
  skinmesh::test::TempFile holder("x");
  const std::string mesh = holder.path() + "-limited.ply";
  // A file size limit of 20 blocks (SIGXFSZ ignored, so write fails with EFBIG), as a full disk would.
  const std::string command = "ulimit -f 20; trap \"\" XFSZ; " + std::string(SKINMESH_BINARY) + " --quiet mesh " +
                              skinmesh::test::data_file("pept.pdb") + " -o " + mesh + " > " + holder.path() + " 2>&1";
  const int status = std::system(("bash -c '" + command + "'").c_str());
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 1);  // the system refused (docs/commands.md)
  std::ifstream said(holder.path());
  std::stringstream text;
  text << said.rdbuf();
  CHECK(text.str().find(mesh + ": writing the mesh failed (File too large)") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(mesh));
}

TEST_CASE("a file name as long as the file system allows is written, and a killed run's staging files are cleaned up",
          "[cli][bad]") {
  char pattern[] = "/tmp/skinmesh-names-XXXXXX";
  REQUIRE(mkdtemp(pattern) != nullptr);
  const std::string dir = pattern;
  // The longest output is the atom table beside the mesh: a 255-byte name.
  const std::string longest = dir + "/" + std::string(245, 'm') + ".ply";
  const Run r = run("--quiet mesh " + skinmesh::test::data_file("pept.pdb") + " -o " + longest);
  CHECK(r.code == 0);
  CHECK(std::filesystem::exists(longest));
  CHECK(std::filesystem::exists(dir + "/" + std::string(245, 'm') + ".atoms.tsv"));
  // One byte more is refused before the work, naming the table, and nothing is written.
  const std::string over = dir + "/" + std::string(246, 'n') + ".ply";
  const Run refused = run("--quiet mesh " + skinmesh::test::data_file("pept.pdb") + " -o " + over);
  CHECK(refused.code == 2);
  CHECK(refused.output.find(std::string(246, 'n') + ".atoms.tsv: is a longer name") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(over));
  // Staging files: one of a process that is gone, one of this (living) process.
  const pid_t gone = fork();
  REQUIRE(gone >= 0);
  if (gone == 0) std::_Exit(0);
  REQUIRE(waitpid(gone, nullptr, 0) == gone);
  const std::string stale = dir + "/.skinmesh-" + std::to_string(gone) + "-0.tmp";
  const std::string alive = dir + "/.skinmesh-" + std::to_string(getpid()) + "-0.tmp";
  { std::ofstream(stale) << "left by a killed run"; }
  { std::ofstream(alive) << "another run's, still staging"; }
  CHECK(run("--quiet mesh " + skinmesh::test::data_file("pept.pdb") + " -o " + dir + "/again.ply").code == 0);
  CHECK_FALSE(std::filesystem::exists(stale));
  CHECK(std::filesystem::exists(alive));
  std::filesystem::remove_all(dir);
}

TEST_CASE("volume stops TetGen and its clean-up past --max-seconds", "[cli][bad][volume]") {
  skinmesh::test::TempFile holder("x");
  const std::string stem = holder.path() + "-bounded";
  // Bounds at the ends of their ranges keep the clean-up going for minutes; 2 s are allowed.
  const Run time = run("--quiet volume " + skinmesh::test::data_file("pept.pdb") + " -o " + stem +
                       " --min-dihedral 16 --max-radius-edge 1 --max-seconds 2");
  CHECK(time.code == 3);
  CHECK(time.output.find("past the time allowed (2 s, --max-seconds)") != std::string::npos);
  for (const char* ext : {".vtu", ".msh", ".node", ".ele", ".face"}) CHECK_FALSE(std::filesystem::exists(stem + ext));
}

// TetGen's own run under --max-memory: tests/volume ("out of memory in
// TetGen's child ...").
TEST_CASE("volume past --max-memory is refused before TetGen runs", "[cli][bad][volume]") {
  skinmesh::test::TempFile holder("x");
  const std::string stem = holder.path() + "-bounded";
  // A box 300 A out takes TetGen about 1.2 GB (it ran to that before it
  // was estimated); 0.3 GB are allowed.
  const Run memory = run_within(10, "--quiet volume " + skinmesh::test::data_file("pept.pdb") + " -o " + stem +
                                        " --domain both --box-margin 300 --max-memory 0.3");
  INFO(memory.output);
  CHECK(memory.code == 3);
  CHECK(memory.output.find("more than the memory allowed (0.3 GB, --max-memory)") != std::string::npos);
  CHECK(memory.output.find("needs a --box-margin under ") != std::string::npos);
  for (const char* ext : {".vtu", ".msh", ".node", ".ele", ".face"}) CHECK_FALSE(std::filesystem::exists(stem + ext));
}
