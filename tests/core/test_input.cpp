// Molecule input: every format, gzip, models, alternate locations, chains,
// radii and every kind of bad input of the foundation issue.
#include "test_support.hpp"

#include "skinmesh/core/error.hpp"
#include "skinmesh/core/molecule.hpp"
#include "skinmesh/core/radii.hpp"
#include "skinmesh/core/skin_complex.hpp"

#include <catch2/catch.hpp>
#include <zlib.h>

#include <fstream>
#include <set>
#include <sstream>

using namespace skinmesh;
using test::TempFile;

namespace {

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// A PDB ATOM record with the columns where the format puts them.
std::string pdb_atom(int serial, const std::string& name, const std::string& res, char chain, int resnum, double x,
                     double y, double z, const std::string& element, char altloc = ' ', double occ = 1.0) {
  char line[100];
  std::snprintf(line, sizeof line, "ATOM  %5d %-4s%c%3s %c%4d    %8.3f%8.3f%8.3f%6.2f%6.2f          %2s\n", serial,
                name.c_str(), altloc, res.c_str(), chain, resnum, x, y, z, occ, 10.0, element.c_str());
  return line;
}

// Expects read_molecule to throw an InputError naming the file and, when
// line > 0, that line; and a message containing `words`.
void expect_input_error(const std::string& path, long line, const std::string& words, const ReadOptions& o = {}) {
  try {
    read_molecule(path, o);
    FAIL("no error for " << path);
  } catch (const InputError& e) {
    INFO(e.what());
    CHECK(e.file() == path);
    CHECK(std::string(e.what()).find(path) != std::string::npos);
    if (line > 0) CHECK(e.line() == line);
    CHECK(std::string(e.what()).find(words) != std::string::npos);
  }
}

}  // namespace

TEST_CASE("PDB: heavy atoms with Bondi radii, waters and hydrogens dropped", "[input]") {
  const Molecule m = read_molecule(test::data_file("1ubi.pdb"));
  CHECK(m.format == MoleculeFormat::Pdb);
  CHECK(m.atoms.size() == 602);
  CHECK(m.skipped.at("water") == 81);
  for (const Atom& a : m.atoms) {
    REQUIRE(bondi_radius(a.element));
    CHECK(a.radius == *bondi_radius(a.element));
    CHECK(a.element != "H");
    CHECK(a.line > 0);
  }
  const Molecule with_waters = read_molecule(test::data_file("1ubi.pdb"), [] {
    ReadOptions o;
    o.keep_waters = true;
    return o;
  }());
  CHECK(with_waters.atoms.size() == 683);
}

TEST_CASE("PDB with old-style identification in columns 73-80 (1hpv)", "[input]") {
  const Molecule m = read_molecule(test::data_file("1hpv.pdb"));
  CHECK(m.atoms.size() == 1551);
  std::set<std::string> elements;
  for (const Atom& a : m.atoms) elements.insert(a.element);
  CHECK(elements == std::set<std::string>{"C", "N", "O", "S"});
  CHECK(m.unknown_elements.empty());
  REQUIRE_FALSE(m.warnings.empty());
  CHECK(m.warnings.front().find("columns 73-80") != std::string::npos);
}

TEST_CASE("hydrogens kept on request (1ejg)", "[input]") {
  ReadOptions o;
  o.keep_hydrogens = true;
  const Molecule with_h = read_molecule(test::data_file("1ejg.pdb"), o);
  const Molecule without = read_molecule(test::data_file("1ejg.pdb"));
  long hydrogens = 0;
  for (const Atom& a : with_h.atoms) hydrogens += a.element == "H";
  CHECK(hydrogens > 0);
  CHECK(with_h.atoms.size() == without.atoms.size() + static_cast<size_t>(hydrogens));
  CHECK(without.skipped.at("hydrogen") > 0);
}

TEST_CASE("alternate locations: one conformer per residue, highest occupancy, ties to the first", "[input]") {
  std::string pdb;
  // Residue 1: label B has the higher mean occupancy (0.60 against 0.40), so
  // both CA and CB come from B, never a mixture of the two conformers.
  pdb += pdb_atom(1, " N", "SER", 'A', 1, 0, 0, 0, "N");
  pdb += pdb_atom(2, " CA", "SER", 'A', 1, 1.5, 0, 0, "C", 'A', 0.30);
  pdb += pdb_atom(3, " CA", "SER", 'A', 1, 1.6, 0, 0, "C", 'B', 0.70);
  pdb += pdb_atom(4, " CB", "SER", 'A', 1, 2.0, 1, 0, "C", 'A', 0.50);
  pdb += pdb_atom(5, " CB", "SER", 'A', 1, 2.1, 1, 0, "C", 'B', 0.50);
  // Residue 2: a tie goes to the label met first.
  pdb += pdb_atom(6, " CA", "GLY", 'A', 2, 5.0, 0, 0, "C", 'B', 0.50);
  pdb += pdb_atom(7, " CA", "GLY", 'A', 2, 5.1, 0, 0, "C", 'A', 0.50);
  TempFile f("alt.pdb", pdb + "END\n");
  const Molecule m = read_molecule(f.path());
  REQUIRE(m.atoms.size() == 4);
  CHECK(m.skipped.at("alternate location") == 3);
  for (const Atom& a : m.atoms) {
    if (a.residue_number == 1 && a.name != "N") CHECK(a.altloc == 'B');
    if (a.residue_number == 2) CHECK(a.altloc == 'B');
  }
}

TEST_CASE("alternate locations of a real entry: 1ejg's microheterogeneous residues", "[input]") {
  // Residue 22 of crambin is Pro (A) or Ser (B, C), residue 25 Leu (A) or Ile
  // (B, C): one residue type each, never a proline carrying serine's OG.
  const Molecule crambin = read_molecule(test::data_file("1ejg.pdb"));
  CHECK(crambin.atoms.size() == 327);
  std::set<std::tuple<std::string, int, std::string>> ids;
  std::set<std::string> at22, at25;
  for (const Atom& a : crambin.atoms) {
    ids.insert({a.chain, a.residue_number, a.name});
    if (a.residue_number == 22) at22.insert(a.residue);
    if (a.residue_number == 25) at25.insert(a.residue);
  }
  CHECK(ids.size() == crambin.atoms.size());
  CHECK(at22 == std::set<std::string>{"PRO"});
  CHECK(at25 == std::set<std::string>{"LEU"});
  long named = 0;
  for (const std::string& w : crambin.warnings)
    named += w.find("residue 22 is microheterogeneous") != std::string::npos ||
             w.find("residue 25 is microheterogeneous") != std::string::npos;
  CHECK(named == 2);
}

TEST_CASE("models: first by default, --model N, or all of them", "[input]") {
  const std::string path = test::data_file("2k39_3models.pdb");
  const Molecule first = read_molecule(path);
  CHECK(first.model == 1);
  CHECK(first.models_in_file == 3);
  ReadOptions o;
  o.model = 2;
  const Molecule second = read_molecule(path, o);
  CHECK(second.model == 2);
  REQUIRE(second.atoms.size() == first.atoms.size());
  CHECK((second.atoms[0].position - first.atoms[0].position).norm() > 1e-3);
  CHECK(second.atoms[0].line > first.atoms.back().line);
  const auto all = read_all_models(path);
  REQUIRE(all.size() == 3);
  CHECK(all[1].atoms[5].position == second.atoms[5].position);
  o.model = 4;
  expect_input_error(path, 0, "model 4 requested, but the file has 3 model(s)", o);
}

TEST_CASE("chain selection", "[input]") {
  ReadOptions o;
  o.chains = {"A"};
  const Molecule a = read_molecule(test::data_file("1hpv.pdb"), o);
  const Molecule all = read_molecule(test::data_file("1hpv.pdb"));
  CHECK(a.atoms.size() < all.atoms.size());
  CHECK(a.skipped.at("chain not selected") > 0);
  for (const Atom& atom : a.atoms) CHECK(atom.chain == "A");
  o.chains = {"Z"};
  expect_input_error(test::data_file("1hpv.pdb"), 0, "no atoms left after filtering", o);
}

TEST_CASE("gzipped PDB reads like the plain file", "[input]") {
  const std::string text = slurp(test::data_file("pept.pdb"));
  TempFile gz("pept.pdb.gz");
  gzFile out = gzopen(gz.path().c_str(), "wb");
  gzwrite(out, text.data(), static_cast<unsigned>(text.size()));
  gzclose(out);
  const Molecule plain = read_molecule(test::data_file("pept.pdb"));
  const Molecule zipped = read_molecule(gz.path());
  REQUIRE(zipped.atoms.size() == plain.atoms.size());
  for (size_t i = 0; i < plain.atoms.size(); ++i) CHECK(zipped.atoms[i].position == plain.atoms[i].position);
}

TEST_CASE("mmCIF: atoms, models, altlocs, waters", "[input]") {
  const std::string cif =
      "data_test\n"
      "loop_\n_atom_site.group_PDB\n_atom_site.id\n_atom_site.type_symbol\n_atom_site.label_atom_id\n"
      "_atom_site.label_alt_id\n_atom_site.label_comp_id\n_atom_site.label_asym_id\n_atom_site.label_entity_id\n"
      "_atom_site.label_seq_id\n_atom_site.Cartn_x\n_atom_site.Cartn_y\n_atom_site.Cartn_z\n_atom_site.occupancy\n"
      "_atom_site.B_iso_or_equiv\n_atom_site.auth_seq_id\n_atom_site.auth_asym_id\n_atom_site.pdbx_PDB_model_num\n"
      "ATOM 1 N N . GLY A 1 1 0.0 0.0 0.0 1.0 10.0 1 A 1\n"
      "ATOM 2 C CA A GLY A 1 1 1.4 0.0 0.0 0.4 10.0 1 A 1\n"
      "ATOM 3 C CA B GLY A 1 1 1.5 0.1 0.0 0.6 10.0 1 A 1\n"
      "ATOM 4 H H . GLY A 1 1 -0.5 0.8 0.0 1.0 10.0 1 A 1\n"
      "HETATM 5 O O . HOH B 2 . 5.0 5.0 5.0 1.0 10.0 101 A 1\n"
      "ATOM 6 N N . GLY A 1 1 0.2 0.0 0.0 1.0 10.0 1 A 2\n"
      "ATOM 7 C CA . GLY A 1 1 1.6 0.0 0.0 1.0 10.0 1 A 2\n";
  TempFile f("small.cif", cif);
  const Molecule m = read_molecule(f.path());
  CHECK(m.format == MoleculeFormat::Mmcif);
  CHECK(m.models_in_file == 2);
  REQUIRE(m.atoms.size() == 2);
  CHECK(m.atoms[1].position.x() == 1.5);
  CHECK(m.skipped.at("hydrogen") == 1);
  CHECK(m.skipped.at("water") == 1);
  CHECK(m.skipped.at("alternate location") == 1);
  CHECK(read_all_models(f.path()).at(1).atoms.at(0).position.x() == 0.2);
}

TEST_CASE("PQR and XYZR carry their own radii", "[input]") {
  TempFile pqr("m.pqr",
               "REMARK test\n"
               "ATOM      1  N   GLY A   1      0.000   0.000   0.000 -0.30 1.8240\n"
               "ATOM      2  CA  GLY A   1      1.450   0.000   0.000  0.10 1.9080\n"
               "ATOM      3  HA  GLY A   1      1.800   1.000   0.000  0.05 1.3870\n"
               "ATOM      4  O   HOH     2      6.000   0.000   0.000 -0.80 1.6612\n"
               "ATOM      5  CL  CL      3      9.000   0.000   0.000 -1.00 2.4700\n");
  const Molecule m = read_molecule(pqr.path());
  CHECK(m.format == MoleculeFormat::Pqr);
  REQUIRE(m.atoms.size() == 3);
  CHECK(m.atoms[0].radius == 1.8240);
  CHECK(m.atoms[1].chain == "A");
  CHECK(m.atoms[2].element == "CL");
  CHECK(m.atoms[2].radius == 2.47);
  CHECK(m.skipped.at("hydrogen") == 1);
  CHECK(m.skipped.at("water") == 1);

  TempFile xyzr("m.xyzr", "# x y z r\n0 0 0 1.5\n\n2.5 0 0 1.7 1 CA\n");
  const Molecule x = read_molecule(xyzr.path());
  REQUIRE(x.atoms.size() == 2);
  CHECK(x.atoms[1].radius == 1.7);
  CHECK(x.atoms[1].line == 4);
}

TEST_CASE("weight conventions", "[input]") {
  Molecule m;
  Atom a;
  a.radius = 2.0;
  m.atoms.push_back(a);
  CHECK(balls_from_molecule(m, 0.5, WeightConvention::GrowBySkin)[0].weight == 8.0);
  CHECK(balls_from_molecule(m, 0.5, WeightConvention::Raw)[0].weight == 4.0);
  // Grown weights put a lone atom's skin on its van der Waals sphere.
  const auto balls = balls_from_molecule(m, 0.25, WeightConvention::GrowBySkin);
  CHECK(std::abs(build_skin_complex(balls, {0.25}).value({2.0, 0, 0})) < 1e-12);
}

TEST_CASE("bad input: missing, empty, directory", "[input][bad]") {
  expect_input_error("/nonexistent/dir/x.pdb", 0, "cannot open file");
  TempFile empty("empty.pdb", "");
  expect_input_error(empty.path(), 0, "file is empty");
  TempFile blank("blank.xyzr", "\n  \n");
  expect_input_error(blank.path(), 0, "file is empty");
  expect_input_error(std::string(SKINMESH_DATA_DIR), 0, "is a directory");
  TempFile nothing("header.pdb", "HEADER    NOTHING HERE\nEND\n");
  expect_input_error(nothing.path(), 0, "no atoms");
  TempFile garbage_gz("bad.pdb.gz", std::string("\x1f\x8b\x08\x00garbage", 12));
  CHECK_THROWS_AS(read_molecule(garbage_gz.path()), InputError);
}

TEST_CASE("bad input: no atoms left after filtering", "[input][bad]") {
  TempFile waters("waters.pdb", pdb_atom(1, " O", "HOH", 'A', 1, 0, 0, 0, "O") + "END\n");
  expect_input_error(waters.path(), 0, "no atoms left after filtering (dropped: 1 water");
}

TEST_CASE("bad input: malformed, NaN and infinite coordinates name the line", "[input][bad]") {
  const std::string good = pdb_atom(1, " N", "GLY", 'A', 1, 0, 0, 0, "N");
  std::string bad = pdb_atom(2, " CA", "GLY", 'A', 1, 1.5, 0, 0, "C");
  bad.replace(38, 8, "  12.x45");
  TempFile malformed("malformed.pdb", "REMARK x\n" + good + bad);
  expect_input_error(malformed.path(), 3, "malformed or non-finite y coordinate");

  std::string nan_line = pdb_atom(2, " CA", "GLY", 'A', 1, 1.5, 0, 0, "C");
  nan_line.replace(46, 8, "     nan");
  TempFile nan("nan.pdb", good + nan_line);
  expect_input_error(nan.path(), 2, "non-finite z coordinate");

  // A hex float or an exponent is no PDB coordinate (gemmi would read 0.000).
  for (const char* odd : {"   0x1p3", "   1.0e2"}) {
    std::string odd_line = pdb_atom(2, " CA", "GLY", 'A', 1, 1.5, 0, 0, "C");
    odd_line.replace(30, 8, odd);
    TempFile hex("odd.pdb", good + odd_line);
    expect_input_error(hex.path(), 2, "x coordinate");
  }

  struct BadFile {
    const char* name;
    std::string contents;
    long line;
    const char* message;
  };
  const BadFile bad_files[] = {
      {"short.pdb", good + "ATOM      2  CA  GLY A   1       1.500   0.0\n", 2, "coordinate record too short"},
      {"inf.xyzr", "0 0 0 1.5\n1 inf 0 1.5\n", 2, "non-finite y coordinate"},
      {"nan.xyzr", "0 0 0 1.5\n1 0 0 nan\n", 2, "malformed or non-finite radius"},
      {"short.xyzr", "0 0 0 1.5\n1 0 0\n", 2, "needs 4 numbers"},
      {"neg.xyzr", "0 0 0 -1.5\n", 1, "negative radius"},
      {"short.pqr", "ATOM 1 N GLY 1 0 0 0\n", 1, "PQR atom record needs at least 10 fields"},
  };
  for (const BadFile& b : bad_files) {
    TempFile file(b.name, b.contents);
    expect_input_error(file.path(), b.line, b.message);
  }
  TempFile cif_bad("bad.cif", "data_x\nloop_\n_atom_site.id\n_atom_site.Cartn_x\n1 2 3\n");
  CHECK_THROWS_AS(read_molecule(cif_bad.path()), InputError);
}

TEST_CASE("bad input: an enormous coordinate", "[input][bad]") {
  TempFile huge("huge.xyzr", "0 0 0 1.5\n1e30 0 0 1.5\n");
  expect_input_error(huge.path(), 2, "beyond");
  TempFile big_pdb("big.pdb", pdb_atom(1, " N", "GLY", 'A', 1, 0, 0, 0, "N") +
                                  pdb_atom(2, " C", "GLY", 'A', 1, 0, 0, 0, "C").replace(30, 8, "99999999"));
  expect_input_error(big_pdb.path(), 2, "beyond");
  // An exponent does not fit a PDB coordinate column (F8.3) at all.
  TempFile exp_pdb("exp.pdb", pdb_atom(1, " N", "GLY", 'A', 1, 0, 0, 0, "N") +
                                  pdb_atom(2, " C", "GLY", 'A', 1, 0, 0, 0, "C").replace(30, 8, "9.99e+99"));
  expect_input_error(exp_pdb.path(), 2, "malformed or non-finite x coordinate");
}

TEST_CASE("bad input: a radius or weight whose square overflows names the file and line", "[input][bad]") {
  TempFile radius("r.xyzr", "0 0 0 1.5\n1 0 0 1e200\n");
  expect_input_error(radius.path(), 2, "radius");
  TempFile pqr("r.pqr", "ATOM      1  N   GLY A   1       0.000   0.000   0.000  0.0 1.5\n"
                        "ATOM      2  CA  GLY A   1       1.000   0.000   0.000  0.0 1e160\n");
  expect_input_error(pqr.path(), 2, "radius");
  TempFile weight("w.wpts", "0 0 0 2\n1 0 0 -1e300\n");
  expect_input_error(weight.path(), 2, "weight");
}

TEST_CASE("bad input: an mmCIF atom table without a coordinate column says which", "[input][bad]") {
  TempFile cif("noz.cif", "data_x\nloop_\n_atom_site.group_PDB\n_atom_site.id\n_atom_site.type_symbol\n"
                          "_atom_site.label_atom_id\n_atom_site.label_comp_id\n_atom_site.label_asym_id\n"
                          "_atom_site.label_seq_id\n_atom_site.Cartn_x\n_atom_site.Cartn_y\n"
                          "ATOM 1 N N GLY A 1 0.0 0.0\n");
  expect_input_error(cif.path(), 0, "_atom_site.Cartn_z");
}

TEST_CASE("unknown elements: fallback radius with a report, or an error when strict", "[input][bad]") {
  TempFile f("fe.pdb", pdb_atom(1, " N", "GLY", 'A', 1, 0, 0, 0, "N") +
                           "HETATM    2 FE   HEM A   2       3.000   0.000   0.000  1.00 10.00          FE\n");
  const Molecule m = read_molecule(f.path());
  REQUIRE(m.atoms.size() == 2);
  CHECK(m.unknown_elements.at("FE") == 1);
  CHECK(m.atoms[1].radius == ReadOptions{}.unknown_radius);
  bool warned = false;
  for (const std::string& w : m.warnings) warned |= w.find("'FE'") != std::string::npos;
  CHECK(warned);
  ReadOptions strict;
  strict.strict_elements = true;
  expect_input_error(f.path(), 2, "unknown element 'FE'", strict);
}

TEST_CASE("several atoms at one position: warned, the twin is hidden", "[input][bad]") {
  TempFile f("dup.pdb", pdb_atom(1, " N", "GLY", 'A', 1, 0, 0, 0, "N") +
                            pdb_atom(2, " CA", "GLY", 'A', 1, 1.5, 0, 0, "C") +
                            pdb_atom(3, " CA", "GLY", 'A', 2, 1.5, 0, 0, "C"));
  const Molecule m = read_molecule(f.path());
  REQUIRE(m.atoms.size() == 3);
  REQUIRE(m.warnings.size() == 1);
  CHECK(m.warnings[0].find("share a position") != std::string::npos);
  CHECK(m.warnings[0].find(":3") != std::string::npos);
  const SkinComplex sc = build_skin_complex(balls_from_molecule(m, 0.5));
  CHECK(sc.hidden_balls().size() == 1);
}

TEST_CASE("one, two, collinear and coplanar atoms build a complex", "[input][degenerate]") {
  TempFile one("one.xyzr", "1 2 3 1.7\n");
  TempFile two("two.xyzr", "0 0 0 1.7\n2.5 0 0 1.5\n");
  TempFile line("line.xyzr", "0 0 0 1.7\n1.5 0 0 1.7\n3 0 0 1.7\n4.5 0 0 1.7\n");
  TempFile plane("plane.xyzr", "0 0 0 1.7\n1.5 0 0 1.7\n0 1.5 0 1.7\n1.5 1.5 0 1.6\n3 1 0 1.5\n");
  const std::pair<const TempFile*, int> cases[] = {{&one, 0}, {&two, 1}, {&line, 1}, {&plane, 2}};
  for (const auto& [file, dim] : cases) {
    const SkinComplex sc = build_skin_complex(balls_from_molecule(read_molecule(file->path()), 0.5));
    CHECK(sc.triangulation_dimension() == dim);
    CHECK(sc.cells().size() >= sc.balls().size());
  }
}

TEST_CASE("weighted points (.wpts): weights as given, negative ones too, and bit-exact round trip", "[input][wpts]") {
  const std::vector<Ball> balls = {{Eigen::Vector3d(0.1, -2.5, 3.0), 4.5},
                                   {Eigen::Vector3d(1.0 / 3.0, 2.0 / 7.0, -1e-3), -0.7321},
                                   {Eigen::Vector3d(5, 5, 5), 0.0}};
  std::ostringstream text;
  write_wpts(text, balls, "two lines\nof comment");
  test::TempFile file("set.wpts", text.str());
  const Molecule m = read_molecule(file.path());
  CHECK(m.format == MoleculeFormat::Wpts);
  REQUIRE(m.atoms.size() == balls.size());  // a zero or negative weight is kept, unlike a zero radius
  // The weights are used as they are, whatever the convention asked for.
  for (const WeightConvention c : {WeightConvention::GrowBySkin, WeightConvention::Raw}) {
    const std::vector<Ball> back = balls_from_molecule(m, 0.5, c);
    for (size_t i = 0; i < balls.size(); ++i) {
      CHECK(back[i].center == balls[i].center);
      CHECK(back[i].weight == balls[i].weight);
    }
  }
  test::TempFile three("three.wpts", "# fine\n0 0 0 1\n1 2 3\n");
  expect_input_error(three.path(), 3, "exactly 4 numbers");
  test::TempFile five("five.wpts", "0 0 0 1 7\n");
  expect_input_error(five.path(), 1, "exactly 4 numbers");
  test::TempFile nan("nan.wpts", "0 0 0 1\n\n0 0 1 nan\n");
  expect_input_error(nan.path(), 3, "weight");
  test::TempFile word("word.wpts", "0 0 x 1\n");
  expect_input_error(word.path(), 1, "z coordinate");
  test::TempFile only_comments("empty.wpts", "# nothing\n\n");
  expect_input_error(only_comments.path(), 0, "no weighted points");
}

TEST_CASE("bounded input: devices refused, size and inflated size limited", "[input][bad][bounded]") {
  // A device is read for ever; it is refused before any byte is read.
  expect_input_error("/dev/zero", 0, "is not a regular file");
  // A file larger than the limit is refused by its size.
  ReadOptions small;
  small.max_bytes = 1000;
  expect_input_error(test::data_file("pept.pdb"), 0, "holds more than 1000 bytes", small);
  // A gzip of 4 MB of zeros is 4 kB: refused once it inflates past the limit,
  // not after inflating all of it.
  test::TempFile bomb("bomb.pdb.gz");
  {
    gzFile out = gzopen(bomb.path().c_str(), "wb9");
    const std::string zeros(1 << 20, '0');
    for (int k = 0; k < 4; ++k) gzwrite(out, zeros.data(), static_cast<unsigned>(zeros.size()));
    gzclose(out);
  }
  ReadOptions mb;
  mb.max_bytes = 1 << 20;
  expect_input_error(bomb.path(), 0, "inflates to more than 1048576 bytes", mb);
}

TEST_CASE("a UTF-8 byte-order mark before the first record is read past, not the first atom dropped", "[input][bad]") {
  std::ifstream in(test::data_file("pept.pdb"), std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  const size_t plain = read_molecule(test::data_file("pept.pdb")).atoms.size();
  for (const char* name : {"pept-bom.pdb", "pept-bom.pqr"}) {
    const std::string body = std::string(name).find(".pqr") != std::string::npos
                                 ? "ATOM      1  N   ALA A   1      11.104   6.134  -6.504  0.0000 1.5500\n"
                                   "ATOM      2  CA  ALA A   1      11.639   6.071  -5.147  0.0000 1.7000\n"
                                 : text.str();
    const test::TempFile with_mark(name, "\xEF\xBB\xBF" + body);
    const test::TempFile without(std::string("plain-") + name, body);
    INFO(name);
    const Molecule m = read_molecule(with_mark.path());
    CHECK(m.atoms.size() == read_molecule(without.path()).atoms.size());
    CHECK(m.atoms.front().position == read_molecule(without.path()).atoms.front().position);
  }
  CHECK(read_molecule(test::TempFile("p.pdb", "\xEF\xBB\xBF" + text.str()).path()).atoms.size() == plain);
}
