// Volume meshes by TetGen: quality bounds, exact volume, the surface kept as
// the boundary, region markers, and the written files read back.
#include "test_support.hpp"

#include "skinmesh/core/molecule.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/mesh_io/mesh_read.hpp"
#include "skinmesh/mesh_io/tet_write.hpp"
#include "skinmesh/mesher/skin_mesher.hpp"
#include "skinmesh/quality/mesh_quality.hpp"
#include "skinmesh/quality/tet_quality.hpp"
#include "skinmesh/volume/tet_estimate.hpp"
#include "skinmesh/volume/volume_mesh.hpp"
#include "tetgen_run.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <functional>
#include <map>
#include <set>
#include <cstdio>
#include <fstream>
#include <sstream>

using namespace skinmesh;

namespace {

SurfaceMesh skin_mesh(const std::string& path) {
  const auto balls = balls_from_molecule(read_molecule(path), 0.5);
  const SkinMeshResult r = mesh_skin(build_skin_complex(balls, {0.5}));
  REQUIRE(r.status == MeshingStatus::ok);
  return r.mesh;
}

// The tetrahedra of a volume mesh that must succeed.
TetMesh tetrahedralize_ok(const SurfaceMesh& surface, const VolumeOptions& options = {}) {
  const VolumeMeshResult r = tetrahedralize(surface, options);
  INFO(r.message);
  REQUIRE(r.status == VolumeStatus::ok);
  return r.mesh;
}

// Enclosed volume per connected component (union-find over vertices).
std::map<int, double> component_volumes(const SurfaceMesh& m) {
  std::vector<int> parent(m.vertices.size());
  for (size_t i = 0; i < parent.size(); ++i) parent[i] = static_cast<int>(i);
  std::function<int(int)> find = [&](int x) { return parent[x] == x ? x : parent[x] = find(parent[x]); };
  for (const auto& t : m.triangles) parent[find(t[1])] = parent[find(t[2])] = find(t[0]);
  std::map<int, double> per;
  for (const auto& t : m.triangles)
    per[find(t[0])] += m.vertices[t[0]].dot(m.vertices[t[1]].cross(m.vertices[t[2]])) / 6.0;
  return per;
}

double enclosed_volume(const SurfaceMesh& m, bool outer_only = false) {
  // Per component when outer_only: cavities (negative) are left out.
  const std::map<int, double> per = component_volumes(m);
  double v = 0;
  for (const auto& [c, w] : per)
    if (!outer_only || w > 0) v += w;
  return v;
}

using Key = std::array<std::array<double, 3>, 3>;
Key key_of(const std::vector<Eigen::Vector3d>& points, std::array<int, 3> t) {
  Key k;
  for (int i = 0; i < 3; ++i) k[i] = {points[t[i]][0], points[t[i]][1], points[t[i]][2]};
  std::sort(k.begin(), k.end());
  return k;
}

// Checks the interior mesh of a molecule against the requirements.
void check_interior(const std::string& path) {
  INFO(path);
  const SurfaceMesh surface = skin_mesh(path);
  const TetMesh tets = tetrahedralize_ok(surface);
  const TetQuality q = grade_tet_mesh(tets);
  CHECK(q.inverted == 0);
  // The default bounds hold everywhere, against the surface too (TetGen's
  // result passed through improve_tet_mesh).
  CHECK(q.max_radius_edge <= 2.0);
  CHECK(q.min_dihedral >= 5.0);
  const double enclosed = enclosed_volume(surface);
  CHECK(std::abs(region_volume(tets, kRegionInterior) - enclosed) <= 1e-9 * enclosed);
  CHECK(std::abs(q.volume - enclosed) <= 1e-9 * enclosed);
  // The boundary is the surface: the same triangles on the same points.
  std::multiset<Key> boundary, expected;
  for (const auto& f : tets.faces) boundary.insert(key_of(tets.points, f));
  for (const auto& t : surface.triangles) expected.insert(key_of(surface.vertices, t));
  CHECK(boundary == expected);
}

// Runs improve_tet_mesh with the default bounds on a mesh with a tetrahedron
// below 5 degrees, and checks what every improvement must give: nothing left
// outside the bounds, nothing inverted, the same volume.
TetImprovement improve_and_check(TetMesh& mesh) {
  const TetQuality before = grade_tet_mesh(mesh);
  REQUIRE(before.inverted == 0);
  REQUIRE(before.min_dihedral < 5.0);
  const TetImprovement r = improve_tet_mesh(mesh, TetBounds{2.0, 5.0});
  const TetQuality after = grade_tet_mesh(mesh);
  CHECK(r.bad_after == 0);
  CHECK(after.inverted == 0);
  CHECK(after.min_dihedral >= 5.0);
  CHECK(after.max_radius_edge <= 2.0);
  CHECK(std::abs(after.volume - before.volume) <= 1e-12);
  return r;
}

}  // namespace

TEST_CASE("interior volume meshes: bounds, exact volume, the surface as boundary", "[volume][large]") {
  check_interior(test::data_file("pept.pdb"));
  check_interior(test::data_file("1ubi.pdb"));
  check_interior(test::data_file("1ejg.pdb"));
  check_interior(test::data_file("2k39_3models.pdb"));
  check_interior(test::data_file("3al1.pdb"));
}

TEST_CASE("interior volume meshes of the large molecules", "[volume][slow]") {
  check_interior(test::data_file("1hpv.pdb"));
  check_interior(test::data_file("3mht.pdb"));
}

TEST_CASE("moving TetGen's points brings a flat tetrahedron within bounds", "[volume]") {
  // A regular tetrahedron as the marked boundary, split into four from one
  // free point placed almost on a face: one sliver, three skinny ones.
  TetMesh mesh;
  mesh.points = {{0, 0, 0}, {1, 0, 0}, {0.5, std::sqrt(3.0) / 2, 0}, {0.5, std::sqrt(3.0) / 6, std::sqrt(2.0 / 3.0)}};
  const Eigen::Vector3d centroid = (mesh.points[0] + mesh.points[1] + mesh.points[2]) / 3.0;
  mesh.points.push_back(centroid + Eigen::Vector3d(0.05, -0.02, 0.01));
  mesh.faces = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  mesh.face_marker = {kFaceSkin, kFaceSkin, kFaceSkin, kFaceSkin};
  for (const auto& f : mesh.faces) {
    std::array<int, 4> t{f[0], f[2], f[1], 4};  // the free point behind each outward face
    mesh.tets.push_back(t);
    mesh.tet_region.push_back(kRegionInterior);
  }
  const TetMesh original = mesh;
  const TetImprovement r = improve_and_check(mesh);
  CHECK(r.bad_before >= 1);
  CHECK(r.moved == 1);
  for (int v = 0; v < 4; ++v) CHECK(mesh.points[static_cast<size_t>(v)] == original.points[static_cast<size_t>(v)]);
  CHECK(mesh.tets == original.tets);
  CHECK(mesh.faces == original.faces);
}

TEST_CASE("removing an edge undoes a flat tetrahedron of four surface points", "[volume]") {
  // The convex hull of a nearly flat quad c-a-d-b (folded along c-d) and an
  // apex e, as three tetrahedra around a-b; all points lie on marked faces,
  // so nothing can move: only removing a-b (a 3-2 flip) mends a-b-c-d.
  TetMesh mesh;
  mesh.points = {{0, -1, 0.05}, {0, 1, 0.05}, {-1, 0, 0}, {1, 0, 0}, {0, 0, 1}};  // a b c d e
  mesh.faces = {{0, 2, 3}, {1, 3, 2}, {2, 0, 4}, {0, 3, 4}, {3, 1, 4}, {1, 2, 4}};
  mesh.face_marker.assign(mesh.faces.size(), kFaceSkin);
  mesh.tets = {{0, 1, 2, 3}, {0, 1, 2, 4}, {0, 1, 3, 4}};
  for (auto& t : mesh.tets) {
    const Eigen::Vector3d &p = mesh.points[t[0]], &q = mesh.points[t[1]], &r = mesh.points[t[2]],
                          &s = mesh.points[t[3]];
    if ((q - p).dot((r - p).cross(s - p)) < 0) std::swap(t[2], t[3]);
  }
  mesh.tet_region.assign(3, kRegionInterior);
  const TetMesh original = mesh;
  const TetImprovement r = improve_and_check(mesh);
  CHECK(r.flips == 1);
  CHECK(r.moved == 0);
  CHECK(mesh.tets.size() == 2);
  CHECK(mesh.points == original.points);
  CHECK(mesh.faces == original.faces);
  // Each marked face is still a face of exactly one tetrahedron.
  for (auto f : mesh.faces) {
    std::sort(f.begin(), f.end());
    int owners = 0;
    for (const auto& t : mesh.tets) {
      int shared = 0;
      for (int v : t) shared += std::binary_search(f.begin(), f.end(), v);
      owners += shared == 3;
    }
    CHECK(owners == 1);
  }
}

TEST_CASE("solvent and cavity regions get their markers", "[volume]") {
  // pept's skin has a cavity: a component with negative enclosed volume.
  const SurfaceMesh surface = skin_mesh(test::data_file("pept.pdb"));
  const double outer = enclosed_volume(surface, true), net = enclosed_volume(surface);
  REQUIRE(outer - net > 1.0);  // the cavities hold more than 1 A^3
  long negative = 0;
  for (const auto& [c, v] : component_volumes(surface)) negative += v < 0;
  CHECK(grade_mesh(surface, GradeOptions{SelfIntersectionCheck::skip}).cavities == negative);
  CHECK(negative >= 1);
  VolumeOptions both;
  both.domain = VolumeDomain::both;
  both.box_margin = 5.0;
  const TetMesh tets = tetrahedralize_ok(surface, both);
  const TetQuality q = grade_tet_mesh(tets);
  CHECK(q.inverted == 0);
  CHECK(q.min_dihedral >= 5.0);
  CHECK(q.max_radius_edge <= 2.0);
  CHECK(std::abs(region_volume(tets, kRegionInterior) - net) <= 1e-9 * net);
  CHECK(std::abs(region_volume(tets, kRegionCavity) - (outer - net)) <= 1e-9 * outer);
  // All regions together fill the box.
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (const auto& p : tets.points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const double box = (hi - lo).prod();
  CHECK(std::abs(q.volume - box) <= 1e-9 * box);
  CHECK(std::abs(region_volume(tets, kRegionSolvent) - (box - outer)) <= 1e-9 * box);
  std::map<int, long> faces;
  for (int m : tets.face_marker) ++faces[m];
  CHECK(faces[kFaceSkin] + faces[kFaceCavity] == static_cast<long>(surface.triangles.size()));
  CHECK(faces[kFaceCavity] > 0);
  CHECK(faces[kFaceBox] > 0);

  // The exterior only: no interior tetrahedra; dropping cavities fills them.
  VolumeOptions exterior = both;
  exterior.domain = VolumeDomain::exterior;
  const TetMesh outside = tetrahedralize_ok(surface, exterior);
  CHECK(region_volume(outside, kRegionInterior) == 0.0);
  CHECK(std::abs(region_volume(outside, kRegionSolvent) - (box - outer)) <= 1e-9 * box);
  VolumeOptions filled;
  filled.cavities = Cavities::fill;
  const TetMesh full = tetrahedralize_ok(surface, filled);
  CHECK(std::abs(region_volume(full, kRegionInterior) - outer) <= 1e-9 * outer);
}

TEST_CASE("volume mesh files read back, and open surfaces are refused", "[volume]") {
  const SurfaceMesh surface = skin_mesh(test::data_file("pept.pdb"));
  VolumeOptions both;
  both.domain = VolumeDomain::both;
  const TetMesh tets = tetrahedralize_ok(surface, both);

  // TetGen's .node: coordinates round-trip bit-exactly.
  std::stringstream node, ele, gmsh, vtu;
  write_tetgen_node(node, tets);
  long n = 0, dim = 0, attributes = 0, markers = 0;
  node >> n >> dim >> attributes >> markers;
  REQUIRE(n == static_cast<long>(tets.points.size()));
  for (long i = 0; i < n; ++i) {
    long index;
    Eigen::Vector3d p;
    node >> index >> p[0] >> p[1] >> p[2];
    REQUIRE(p == tets.points[static_cast<size_t>(index)]);
  }
  write_tetgen_ele(ele, tets);
  long m = 0, corners = 0, attrs = 0;
  ele >> m >> corners >> attrs;
  CHECK(m == static_cast<long>(tets.tets.size()));
  CHECK(corners == 4);

  // Gmsh 4.1: node and element counts, one tetrahedron block per region.
  write_gmsh(gmsh, tets);
  const std::string text = gmsh.str();
  CHECK(text.rfind("$MeshFormat\n4.1 0 8\n", 0) == 0);
  const size_t nodes_at = text.find("$Nodes\n");
  REQUIRE(nodes_at != std::string::npos);
  std::istringstream nodes(text.substr(nodes_at + 7));
  long blocks = 0, count = 0;
  nodes >> blocks >> count;
  CHECK(count == static_cast<long>(tets.points.size()));
  const size_t elements_at = text.find("$Elements\n");
  REQUIRE(elements_at != std::string::npos);
  std::istringstream elements(text.substr(elements_at + 10));
  elements >> blocks >> count;
  CHECK(count == static_cast<long>(tets.tets.size() + tets.faces.size()));
  CHECK(blocks == 6);  // skin, cavity surface, box; interior, solvent, cavity

  // Both files read back as the same tetrahedral mesh.
  for (const char* ext : {".msh", ".ele"}) {
    INFO(ext);
    test::TempFile file(std::string("v") + ext);
    const std::string stem = file.path().substr(0, file.path().size() - 4);
    {
      std::ofstream out(file.path());
      if (std::string(ext) == ".msh") write_gmsh(out, tets);
      else write_tetgen_ele(out, tets);
    }
    if (std::string(ext) == ".ele") {
      std::ofstream(stem + ".node") << node.str();
      std::ofstream f(stem + ".face");
      write_tetgen_face(f, tets);
    }
    const TetMesh back = read_tet_mesh(file.path());
    std::remove((stem + ".node").c_str());
    std::remove((stem + ".face").c_str());
    CHECK(back.points == tets.points);
    // Gmsh groups elements by region and marker: compare as sets with them.
    std::multiset<std::pair<std::array<int, 4>, int>> ta, tb;
    for (size_t i = 0; i < tets.tets.size(); ++i) ta.insert({tets.tets[i], tets.tet_region[i]});
    for (size_t i = 0; i < back.tets.size(); ++i) tb.insert({back.tets[i], back.tet_region[i]});
    CHECK(ta == tb);
    std::multiset<std::pair<std::array<int, 3>, int>> a, b;
    for (size_t i = 0; i < tets.faces.size(); ++i) a.insert({tets.faces[i], tets.face_marker[i]});
    for (size_t i = 0; i < back.faces.size(); ++i) b.insert({back.faces[i], back.face_marker[i]});
    CHECK(a == b);
  }

  write_vtu(vtu, tets);
  CHECK(vtu.str().find("NumberOfCells=\"" + std::to_string(tets.tets.size()) + "\"") != std::string::npos);

  // An open surface (one triangle dropped) is refused before TetGen runs.
  SurfaceMesh open = surface;
  open.triangles.pop_back();
  const VolumeMeshResult refused = tetrahedralize(open);
  CHECK(refused.status == VolumeStatus::surface_not_closed);
  CHECK(refused.mesh.tets.empty());
  CHECK(refused.message.find("boundary") != std::string::npos);
}

TEST_CASE("self-intersections: CGAL's exact check and TetGen's agree", "[volume][intersections]") {
  const SurfaceMesh two = test::two_interpenetrating_tetrahedra();
  CHECK(count_self_intersections(two) > 0);
  CHECK(tetgen_self_intersections(two) > 0);
  const SurfaceMesh skin = skin_mesh(test::data_file("pept.pdb"));
  CHECK(count_self_intersections(skin) == 0);
  CHECK(tetgen_self_intersections(skin) == 0);
}

TEST_CASE("TetGen runs in memory: its errors and an oversized volume bound are statuses", "[volume][bad]") {
  // Two closed tetrahedra that pass through each other: closed, manifold and
  // oriented, so TetGen gets them and stops (it throws in library builds).
  const VolumeMeshResult crossing = tetrahedralize(test::two_interpenetrating_tetrahedra());
  INFO(crossing.message);
  CHECK(crossing.status == VolumeStatus::tetgen_failed);
  CHECK(crossing.message.find("TetGen") != std::string::npos);
  CHECK(crossing.mesh.tets.empty());
  // TetGen's -d check: the triangles that meet another (one tetrahedron's
  // face and three faces of the other meet, as CGAL's 3 pairs say).
  CHECK(tetgen_self_intersections(test::two_interpenetrating_tetrahedra()) >= 2);

  // A volume bound that asks for more tetrahedra than the budget is refused
  // before TetGen runs, naming the bound that would fit, which then runs.
  // (Without a volume bound the estimate's low end is about 21,000.)
  const SurfaceMesh skin = skin_mesh(test::data_file("pept.pdb"));
  VolumeOptions tiny;
  tiny.max_volume = 0.05;
  tiny.max_tetrahedra = 40'000;
  const VolumeMeshResult refused = tetrahedralize(skin, tiny);
  INFO(refused.message);
  REQUIRE(refused.status == VolumeStatus::over_budget);
  CHECK(refused.mesh.tets.empty());
  const size_t at = refused.message.find("--max-volume of at least ");
  REQUIRE(at != std::string::npos);
  VolumeOptions fits = tiny;
  fits.max_volume = 1.01 * std::stod(refused.message.substr(at + 25));
  const VolumeMeshResult made = tetrahedralize(skin, fits);
  INFO(made.message);
  REQUIRE(made.status == VolumeStatus::ok);
  // The estimate's low end is a lower bound: TetGen made at least that many.
  const double enclosed = grade_mesh(skin).volume;
  CHECK(static_cast<double>(made.mesh.tets.size()) >= enclosed / fits.max_volume);
  CHECK(static_cast<double>(made.mesh.tets.size()) >= estimate_tetrahedra(tet_domain(skin, enclosed), fits).low);
}

TEST_CASE("the estimate of TetGen's tetrahedra: its low end below the count, the count near it", "[volume][estimate]") {
  // pept's interior at the defaults, at the tightest radius-edge bound and
  // at the loosest bounds; its solvent in a box 20 A out; with a volume bound.
  const SurfaceMesh skin = skin_mesh(test::data_file("pept.pdb"));
  const TetDomain domain = tet_domain(skin, grade_mesh(skin).volume);
  std::vector<VolumeOptions> cases(5);
  cases[1].bounds.max_radius_edge = 1.5;
  cases[2].bounds.max_radius_edge = 10, cases[2].bounds.min_dihedral = 0;
  cases[3].domain = VolumeDomain::exterior, cases[3].box_margin = 20;
  cases[4].max_volume = 0.1;
  for (const VolumeOptions& o : cases) {
    const TetEstimate e = estimate_tetrahedra(domain, o);
    const VolumeMeshResult made = tetrahedralize(skin, o);
    REQUIRE(made.status == VolumeStatus::ok);
    const double count = static_cast<double>(made.mesh.tets.size());
    CAPTURE(o.bounds.max_radius_edge, o.bounds.min_dihedral, o.box_margin, o.max_volume, e.tetrahedra, e.low, count);
    CHECK(count >= e.low);
    CHECK(count <= kTetEstimateSpread * e.tetrahedra);
  }
  // The box's triangles as add_box makes them: 4 (nx ny + ny nz + nz nx)
  // for a grid of n cells of at most 3 A a side, whatever the margin.
  CHECK(box_triangles(Eigen::Vector3d(3, 6, 9), 0) == 4 * (1 * 2 + 2 * 3 + 3 * 1));
  CHECK(box_triangles(Eigen::Vector3d(1, 1, 1), 1e12) > 1e23);
}

// Named "out of memory ...": scripts/sanitize.sh leaves it out, since an
// address-space limit does not bind AddressSanitizer's allocator.
TEST_CASE("out of memory in TetGen's child: stopped at its bound, whatever the estimate", "[volume][bad][oom]") {
  // The estimate refuses what it sees coming; the run's own bound is for
  // what it does not. 1ubi's interior at TetGen's tightest bounds is some
  // 2 million tetrahedra, hundreds of MB (more than this process may have
  // freed for the child to reuse); 10 MB are allowed.
  const SurfaceMesh skin = skin_mesh(test::data_file("1ubi.pdb"));
  detail::Plc plc;
  plc.points = skin.vertices;
  plc.facets = skin.triangles;
  plc.markers.assign(skin.triangles.size(), kFaceSkin);
  const detail::TetgenRun bounded = detail::run_tetgen(plc, "pzYQq1.2/18", {10e6, 0});
  CHECK(bounded.error.find("TetGen ran out of the memory allowed (0.010 GB, --max-memory)") != std::string::npos);
  CHECK(bounded.mesh.tets.empty());
}

TEST_CASE("a box or a quality bound past the budget is refused before TetGen, naming what fits", "[volume][bad]") {
  const SurfaceMesh skin = skin_mesh(test::data_file("pept.pdb"));
  VolumeOptions wide;
  wide.domain = VolumeDomain::exterior;
  wide.box_margin = 40;
  wide.max_tetrahedra = 30'000;
  const VolumeMeshResult refused = tetrahedralize(skin, wide);
  INFO(refused.message);
  REQUIRE(refused.status == VolumeStatus::over_budget);
  const size_t at = refused.message.find("this would fit: --box-margin ");
  REQUIRE(at != std::string::npos);
  VolumeOptions fits = wide;
  fits.box_margin = std::stod(refused.message.substr(at + 29));
  CHECK(fits.box_margin < wide.box_margin);
  const VolumeMeshResult made = tetrahedralize(skin, fits);
  INFO(made.message);
  CHECK(made.status == VolumeStatus::ok);
  // The memory bound binds the same way.
  VolumeOptions small = wide;
  small.max_tetrahedra = 10'000'000;
  small.max_memory_bytes = 1e6;
  const VolumeMeshResult no_room = tetrahedralize(skin, small);
  INFO(no_room.message);
  CHECK(no_room.status == VolumeStatus::over_budget);
  CHECK(no_room.message.find("the memory allowed (0.001 GB, --max-memory)") != std::string::npos);
  // An interior with no box and no volume bound: only the quality bounds
  // are left to loosen.
  VolumeOptions tight;
  tight.max_tetrahedra = 1'000;
  const VolumeMeshResult none = tetrahedralize(skin, tight);
  INFO(none.message);
  CHECK(none.status == VolumeStatus::over_budget);
  CHECK(none.message.find("loosen --min-dihedral or --max-radius-edge") != std::string::npos);
}
