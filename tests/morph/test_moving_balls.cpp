// Moving balls (docs/math.md section 6): the topology count from the weighted
// alpha complex against the mesher and shapes whose topology is known; the
// engine on rigid motions, identity, a hinge motion checked by the static
// oracle, atoms that grow and shrink, a three-model trajectory, thermal
// motion; the certificate refusing a wrong mesh.
#include "test_support.hpp"
#include "same_frames.hpp"
#include "four_balls.hpp"

#include "judge.hpp"
#include "mesh_part.hpp"
#include "unchanged_skin.hpp"

#include "skinmesh/core/interpolation.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/skin_oracle.hpp"
#include "skinmesh/core/skin_topology.hpp"
#include "skinmesh/mesher/skin_mesher.hpp"
#include "skinmesh/morph/alignment.hpp"
#include "skinmesh/morph/matched_motion.hpp"
#include "skinmesh/morph/moving_balls.hpp"
#include "skinmesh/quality/guarantees.hpp"
#include "skinmesh/quality/mesh_quality.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <functional>
#include <random>
#include <set>
#include <unordered_map>

using namespace skinmesh;

namespace Catch {
template <>
struct StringMaker<SkinTopology> {
  static std::string convert(const SkinTopology& t) { return t.text(); }
};
}  // namespace Catch

namespace {

std::vector<Ball> molecule_balls(const std::string& name, int model = 1) {
  ReadOptions read;
  read.model = model;
  return balls_from_molecule(read_molecule(test::data_file(name), read), 0.5);
}

SkinTopology meshed_topology(const std::vector<Ball>& balls) {
  const SkinMeshResult made = mesh_skin(build_skin_complex(balls));
  REQUIRE(made.status == MeshingStatus::ok);
  return mesh_topology(made.mesh);
}

// Every check a frame of moving balls must pass, against references that
// do not use the engine: the static oracle on the frame's balls (1e-8 A),
// the angle bound, a closed oriented manifold without self-intersections,
// and the topology of the mesher's mesh of those balls from scratch.
void check_frame(const MovingBalls& moving, const std::vector<Ball>& balls, double min_angle) {
  const MorphFrame& f = moving.frame();
  const SkinOracle oracle(balls, 0.5);
  double worst = 0;
  for (const Eigen::Vector3d& x : f.mesh.vertices) worst = std::max(worst, oracle.evaluate(x).distance());
  CHECK(worst < 1e-8);
  const MeshQuality q = grade_mesh(f.mesh);
  CHECK(q.min_angle >= min_angle - 1e-9);
  CHECK(q.closed);
  CHECK(q.manifold);
  CHECK(q.oriented);
  CHECK(q.self_intersecting_pairs == 0);
  const SkinTopology scratch = meshed_topology(balls);
  CHECK(q.components == scratch.components);
  CHECK(q.euler == scratch.euler);
  CHECK(f.stats.topology_certified);
}

// A copy of `balls` with those of `moving` turned by `degrees` about `axis` through `pivot`.
std::vector<Ball> hinged(std::vector<Ball> balls, const std::vector<char>& moving, const Eigen::Vector3d& pivot,
                         const Eigen::Vector3d& axis, double degrees) {
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(degrees * M_PI / 180, axis.normalized()).toRotationMatrix();
  for (size_t i = 0; i < balls.size(); ++i)
    if (moving[i]) balls[i].center = pivot + turn * (balls[i].center - pivot);
  return balls;
}

// Ubiquitin's residues from `first` on, to be hinged about the CA atom of
// the residue before them.
struct UbiquitinTail {
  std::vector<Ball> start;
  std::vector<char> moving;
  Eigen::Vector3d pivot = Eigen::Vector3d::Zero();
};

UbiquitinTail ubiquitin_tail(int first) {
  const Molecule ubi = read_molecule(test::data_file("1ubi.pdb"));
  UbiquitinTail tail{balls_from_molecule(ubi, 0.5), std::vector<char>(ubi.atoms.size(), 0), Eigen::Vector3d::Zero()};
  for (size_t i = 0; i < ubi.atoms.size(); ++i) {
    tail.moving[i] = ubi.atoms[i].residue_number >= first;
    if (ubi.atoms[i].residue_number == first - 1 && ubi.atoms[i].name == "CA") tail.pivot = ubi.atoms[i].position;
  }
  return tail;
}

// At six points within `reach` of x0 (one at the full reach), the QP
// oracle before the step at x and after it at motion(x): certified, the
// same value (to `relative`) and the same support. Returns the points checked.
long same_skin_around(const SkinOracle& before_oracle, const SkinOracle& after_oracle, const detail::RigidMotion& motion,
                      const Eigen::Vector3d& x0, double reach, double relative, std::mt19937& random) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  long checked = 0;
  for (int k = 0; k < 6; ++k) {
    Eigen::Vector3d d(unit(random), unit(random), unit(random));
    if (!(d.norm() > 1e-3)) continue;
    const Eigen::Vector3d x = x0 + (k == 0 ? 1.0 : 0.5 * (1 + unit(random))) * reach * d.normalized();
    const OracleResult b = before_oracle.evaluate(x), a = after_oracle.evaluate(motion(x));
    REQUIRE(b.certified);
    REQUIRE(a.certified);
    CHECK(std::abs(a.value - b.value) <= relative * (1 + std::abs(b.value)));
    std::vector<int> sb, sa;
    for (const auto& p : b.support) sb.push_back(p.first);
    for (const auto& p : a.support) sa.push_back(p.first);
    std::sort(sb.begin(), sb.end());
    std::sort(sa.begin(), sa.end());
    CHECK(sb == sa);
    ++checked;
  }
  return checked;
}

// The balls of data/2k39_3models.pdb's model 1 and of its model 3 fitted
// onto model 1 by Kabsch (residues 1-10; shrink factor 1/2).
std::pair<std::vector<Ball>, std::vector<Ball>> models_1_and_3_of_2k39() {
  ReadOptions read;
  const Molecule first = read_molecule(test::data_file("2k39_3models.pdb"), read);
  read.model = 3;
  Molecule last = read_molecule(test::data_file("2k39_3models.pdb"), read);
  const RigidMotion fit = align(first, last, AlignmentMethod::kabsch).motion;  // before last is moved from
  last = moved(std::move(last), fit);
  return {balls_from_molecule(first, 0.5), balls_from_molecule(last, 0.5)};
}

}  // namespace

TEST_CASE("skin topology from the alpha complex: shapes of known topology", "[moving][topology]") {
  SECTION("one ball, two apart, two overlapping") {
    CHECK(skin_topology({{Eigen::Vector3d::Zero(), 4.0}}) == SkinTopology{1, 0, 2});
    CHECK(skin_topology({{Eigen::Vector3d::Zero(), 4.0}, {Eigen::Vector3d(10, 0, 0), 4.0}}) == SkinTopology{2, 0, 4});
    CHECK(skin_topology({{Eigen::Vector3d::Zero(), 4.0}, {Eigen::Vector3d(3, 0, 0), 4.0}}) == SkinTopology{1, 0, 2});
    CHECK(skin_topology({{Eigen::Vector3d::Zero(), -1.0}}) == SkinTopology{0, 0, 0});
  }
  SECTION("a ring of balls is a torus") {
    std::vector<Ball> ring;
    for (int k = 0; k < 12; ++k) ring.push_back({Eigen::Vector3d(6 * std::cos(k * M_PI / 6), 6 * std::sin(k * M_PI / 6), 0), 4.0});
    CHECK(skin_topology(ring) == SkinTopology{1, 0, 0});
    CHECK(meshed_topology(ring) == SkinTopology{1, 0, 0});
  }
  SECTION("a closed shell of balls holds a void") {
    std::vector<Ball> shell;  // balls on a Fibonacci sphere of radius 8 A
    const int n = 120;
    for (int i = 0; i < n; ++i) {
      const double z = 1 - (2 * i + 1.0) / n, phi = i * M_PI * (3 - std::sqrt(5.0));
      const double r = std::sqrt(1 - z * z);
      shell.push_back({8.0 * Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), z), 9.0});
    }
    const SkinTopology counted = skin_topology(shell);
    CHECK(counted.voids == 1);
    CHECK(counted.components == 2);
    CHECK(counted == meshed_topology(shell));
  }
}

TEST_CASE("skin topology from the alpha complex equals the mesher's on every molecule of data/", "[moving][topology][large]") {
  for (const char* name : {"pept.pdb", "1ubi.pdb", "3al1.pdb", "2k39_3models.pdb", "1ejg.pdb"}) {
    INFO(name);
    const std::vector<Ball> balls = molecule_balls(name);
    CHECK(skin_topology(balls) == meshed_topology(balls));
  }
}

TEST_CASE("moving balls: a rigid translation moves every vertex rigidly, ids kept, no repair", "[moving]") {
  const std::vector<Ball> start = molecule_balls("pept.pdb");
  MovingBalls moving(start);
  const SurfaceMesh first = moving.frame().mesh;
  const std::vector<long> first_ids = moving.frame().ids;
  const Eigen::Vector3d shift(20, 0, 0);
  for (int k = 1; k <= 10; ++k) {
    const double t = k / 10.0;
    std::vector<Ball> balls = start;
    for (Ball& b : balls) b.center += t * shift;
    const MorphFrame& f = moving.advance_to(balls, t);
    INFO("t = " << t);
    REQUIRE(f.ids == first_ids);
    REQUIRE(f.mesh.triangles == first.triangles);
    double worst = 0;
    for (size_t v = 0; v < first.vertices.size(); ++v)
      worst = std::max(worst, (f.mesh.vertices[v] - (first.vertices[v] + t * shift)).norm());
    CHECK(worst < 1e-9);
    CHECK_FALSE(f.stats.repaired);
    CHECK(f.stats.reidentified == 0);
    CHECK(f.stats.ids_kept == 1.0);
    CHECK(f.stats.topology_certified);
  }
}

TEST_CASE("moving balls: a rigid rotation turns every vertex with the molecule", "[moving]") {
  const std::vector<Ball> start = molecule_balls("pept.pdb");
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Ball& b : start) centre += b.center / static_cast<double>(start.size());
  MovingOptions one_step;  // the frames' motion is a rotation; steps between them would take straight lines
  one_step.max_step = 100;
  MovingBalls moving(start, one_step);
  const SurfaceMesh first = moving.frame().mesh;
  const std::vector<char> all(start.size(), 1);
  for (int k = 1; k <= 4; ++k) {
    const double degrees = 5.0 * k;
    const MorphFrame& f = moving.advance_to(hinged(start, all, centre, Eigen::Vector3d(1, 2, 3), degrees), k);
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(degrees * M_PI / 180, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    REQUIRE(f.mesh.vertices.size() == first.vertices.size());
    double worst = 0;
    for (size_t v = 0; v < first.vertices.size(); ++v)
      worst = std::max(worst, (f.mesh.vertices[v] - (centre + turn * (first.vertices[v] - centre))).norm());
    CHECK(worst < 1e-8);
    CHECK(f.stats.ids_kept == 1.0);
    // Every ball moved with its neighbours as one rigid body: from the
    // second frame on (the first follows a mesh made at other criteria) no
    // triangle is judged on the skin again, and judged again in full, by the
    // same judge against the frame's own complex, every one passes.
    if (k > 1) CHECK(f.stats.carried == f.stats.triangles);
    const std::vector<char> failing =
        detail::failing_triangles(moving.complex(), f.mesh, f.mesh.triangles, one_step.frames);
    CHECK(std::count(failing.begin(), failing.end(), 1) == 0);
  }
}

TEST_CASE("judging: a triangle carried rigidly keeps its skin verdicts and has its angles judged again", "[moving]") {
  const std::vector<Ball> balls = molecule_balls("pept.pdb");
  const SkinComplex complex = build_skin_complex(balls, {0.5});
  const MeshingOptions criteria = MovingOptions{}.frames;
  SkinMeshResult made = mesh_skin(complex, criteria);
  REQUIRE(made.status == MeshingStatus::ok);
  SurfaceMesh mesh = made.mesh;
  RelaxationOptions none;
  none.passes = 0;  // the verdicts as judged, nothing moved
  const long triangles = static_cast<long>(mesh.triangles.size());
  // Squash the triangles around vertex 0: moved most of the way to a neighbour.
  const int a = mesh.triangles[0][0], b = mesh.triangles[0][1];
  const std::vector<Eigen::Vector3d> unsquashed = mesh.vertices;
  mesh.vertices[static_cast<size_t>(a)] += 0.9 * (mesh.vertices[static_cast<size_t>(b)] - mesh.vertices[static_cast<size_t>(a)]);
  long star = 0, bad_shape = 0;
  for (const auto& t : mesh.triangles) {
    star += t[0] == a || t[1] == a || t[2] == a;
    bad_shape += !shape_passes({mesh.vertices[static_cast<size_t>(t[0])], mesh.vertices[static_cast<size_t>(t[1])],
                                mesh.vertices[static_cast<size_t>(t[2])]},
                               criteria.min_angle);
  }
  REQUIRE(bad_shape > 0);
  detail::KnownVerdicts known;
  known.carried.assign(mesh.vertices.size(), 1);
  SECTION("told every edge kept its length, the judge still finds every triangle of bad angles") {
    known.before = mesh.vertices;
    SurfaceMesh judged = mesh;
    const detail::Judged j = detail::judge_and_relax(complex, judged, none, criteria, &known);
    CHECK(j.carried == triangles);
    long caught = 0;
    for (size_t f = 0; f < judged.triangles.size(); ++f) {
      const auto& t = judged.triangles[f];
      const bool bad = !shape_passes({judged.vertices[static_cast<size_t>(t[0])], judged.vertices[static_cast<size_t>(t[1])],
                                      judged.vertices[static_cast<size_t>(t[2])]},
                                     criteria.min_angle);
      caught += bad && j.failing[f];
    }
    CHECK(caught == bad_shape);
  }
  SECTION("the triangles whose edges changed length are judged in full") {
    known.before = unsquashed;
    SurfaceMesh judged = mesh;
    const detail::Judged j = detail::judge_and_relax(complex, judged, none, criteria, &known);
    CHECK(j.carried == triangles - star);
    const std::vector<char> full = detail::failing_triangles(complex, mesh, mesh.triangles, criteria);
    for (size_t f = 0; f < mesh.triangles.size(); ++f) {
      const auto& t = mesh.triangles[f];
      if (t[0] == a || t[1] == a || t[2] == a) CHECK(j.failing[f] == full[f]);
    }
  }
}

TEST_CASE("moving balls: the same balls again give the same frame", "[moving]") {
  const std::vector<Ball> start = molecule_balls("pept.pdb");
  MovingBalls moving(start);
  const MorphFrame first = moving.frame();
  for (int k = 1; k <= 3; ++k) {
    const MorphFrame& f = moving.advance_to(start, k);
    REQUIRE(f.ids == first.ids);
    REQUIRE(f.mesh.triangles == first.mesh.triangles);
    double worst = 0;
    for (size_t v = 0; v < f.mesh.vertices.size(); ++v)
      worst = std::max(worst, (f.mesh.vertices[v] - first.mesh.vertices[v]).norm());
    CHECK(worst < 1e-12);
    CHECK_FALSE(f.stats.repaired);
  }
}

TEST_CASE("moving balls: a hinge motion of ubiquitin's C-terminal strand, every frame checked", "[moving][large]") {
  const UbiquitinTail tail = ubiquitin_tail(66);
  const std::vector<Ball>& start = tail.start;
  const std::vector<char>& strand = tail.moving;
  const Eigen::Vector3d& pivot = tail.pivot;
  const Eigen::Vector3d axis(0, 0, 1);
  MovingOptions options;
  options.max_step = 1.0;  // one internal step a frame: the continuity bound below is the step's
  MovingBalls moving(start, options);
  const int frames = 20;
  const double degrees = 40;
  std::vector<Ball> before = start;
  for (int k = 1; k <= frames; ++k) {
    const std::vector<Ball> balls = hinged(start, strand, pivot, axis, degrees * k / frames);
    double atom_move = 0;
    for (size_t i = 0; i < balls.size(); ++i) atom_move = std::max(atom_move, (balls[i].center - before[i].center).norm());
    REQUIRE(atom_move <= 1.0);
    // Where each vertex id was, and how far it may go and keep its id: the
    // largest atom move plus its longest edge (MovingOptions::continuity 1).
    std::unordered_map<long, std::pair<Eigen::Vector3d, double>> was;
    {
      const MorphFrame& last = moving.frame();
      std::vector<double> longest(last.mesh.vertices.size(), 0.0);
      for (const auto& t : last.mesh.triangles)
        for (int i = 0; i < 3; ++i) {
          const auto a = static_cast<size_t>(t[static_cast<size_t>(i)]), b = static_cast<size_t>(t[static_cast<size_t>((i + 1) % 3)]);
          const double length = (last.mesh.vertices[a] - last.mesh.vertices[b]).norm();
          longest[a] = std::max(longest[a], length);
          longest[b] = std::max(longest[b], length);
        }
      for (size_t v = 0; v < last.ids.size(); ++v) was[last.ids[v]] = {last.mesh.vertices[v], atom_move + longest[v]};
    }
    const MorphFrame& f = moving.advance_to(balls, static_cast<double>(k) / frames);
    REQUIRE(f.stats.steps == 1);
    long too_far = 0;
    for (size_t v = 0; v < f.ids.size(); ++v) {
      const auto found = was.find(f.ids[v]);
      if (found != was.end()) too_far += (f.mesh.vertices[v] - found->second.first).norm() > found->second.second + 1e-9;
    }
    CHECK(too_far == 0);
    INFO("frame " << k << ": " << f.stats.vertices << " vertices, ids kept " << f.stats.ids_kept << ", remeshed "
                   << f.stats.remeshed);
    // A frame remeshed whole (a void vanished that is not a component of its
    // own in the frame before) gives new ids to what refinement inserts.
    CHECK(f.stats.ids_kept >= (f.stats.remeshed ? 0.8 : 0.9));
    if (k % 4 == 0) check_frame(moving, balls, 20.0);  // five values of t
    before = balls;
  }
}

TEST_CASE("moving balls: triangles where the step left the skin as it was keep their verdict unjudged", "[moving]") {
  // Ubiquitin's last two residues turned a degree a frame about the CA
  // atom before them: most of the skin is far from them and stays. Each
  // frame is judged again in full, by the same judge over every triangle
  // and the frame's own complex: a triangle taken as passing where the skin
  // changed under it fails here.
  const UbiquitinTail tail = ubiquitin_tail(75);
  MovingOptions options;
  // Ubiquitin is small: a patch's context reaches over half of it. Patches
  // that large are taken, so that frames are mended locally, not remeshed.
  options.repair.patch.max_sample_share = 0.9;
  MovingBalls moving(tail.start, options);
  long settled_frames = 0;
  for (int k = 1; k <= 6; ++k) {
    const MorphFrame& f = moving.advance_to(hinged(tail.start, tail.moving, tail.pivot, Eigen::Vector3d(0, 0, 1), 1.0 * k), k);
    INFO("frame " << k << ": " << f.stats.settled << " of " << f.stats.triangles << " settled, remeshed "
                   << f.stats.remeshed << " " << f.stats.remeshed_because);
    CHECK(f.stats.settled < f.stats.triangles);  // the strand's skin changed
    settled_frames += f.stats.settled > 0;
    const std::vector<char> failing =
        detail::failing_triangles(moving.complex(), f.mesh, f.mesh.triangles, options.frames);
    CHECK(std::count(failing.begin(), failing.end(), 1) == 0);
  }
  // The first step follows the first frame, not judged at the frames'
  // criteria; a frame remeshed whole is not judged either: the next judges all.
  CHECK(settled_frames >= 3);
}

TEST_CASE("skin_unchanged_near: where it proves the skin unchanged, the oracle finds it so, before and after", "[moving]") {
  // Ubiquitin's strand from residue 72 on turned by 8 degrees. Independent
  // oracle (the QP of MATH.md section 2) on both ball sets: at points within
  // each proven vertex's reach, the same value and support. A vertex whose
  // own point is held by an atom that moved must not be proven, and most
  // vertices far from every moved atom must be.
  const UbiquitinTail tail = ubiquitin_tail(72);
  const std::vector<Ball> after = hinged(tail.start, tail.moving, tail.pivot, Eigen::Vector3d(1, 2, 0), 8.0);
  const SkinComplex from = build_skin_complex(tail.start);
  const SkinMeshResult made = mesh_skin(from);
  REQUIRE(made.status == MeshingStatus::ok);
  const SurfaceMesh& mesh = made.mesh;
  const std::vector<char> all(mesh.vertices.size(), 1);
  const std::vector<double> reach = detail::judged_reach(mesh, MeshingOptions{}.tolerance, all);
  const std::vector<char> unchanged = detail::skin_unchanged_near(from, after, mesh, reach, all);
  const SkinOracle before_oracle(tail.start, 0.5), after_oracle(after, 0.5);
  std::mt19937 random(7);
  long proven = 0, far = 0, far_proven = 0, checked = 0;
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    const Eigen::Vector3d& x0 = mesh.vertices[v];
    const OracleResult at = before_oracle.evaluate(x0);
    const bool held_by_moved =
        std::any_of(at.support.begin(), at.support.end(), [&](const auto& b) { return tail.moving[static_cast<size_t>(b.first)] != 0; });
    if (held_by_moved) CHECK_FALSE(unchanged[v]);
    double nearest = INFINITY;
    for (size_t b = 0; b < after.size(); ++b)
      if (tail.moving[b])
        nearest = std::min({nearest, (tail.start[b].center - x0).norm(), (after[b].center - x0).norm()});
    far += nearest > 12;
    far_proven += nearest > 12 && unchanged[v];
    if (!unchanged[v]) continue;
    ++proven;
    if (v % 5 != 0) continue;
    checked += same_skin_around(before_oracle, after_oracle, {}, x0, reach[v], 1e-12, random);
  }
  INFO(proven << " of " << mesh.vertices.size() << " proven; far from moved atoms " << far_proven << " of " << far);
  CHECK(checked > 1000);
  CHECK(far > 1000);
  CHECK(far_proven > far / 2);
  CHECK(proven < static_cast<long>(mesh.vertices.size()));
}

TEST_CASE("balls_moving_with: where the skin is proven carried by a motion, the oracle finds it moved with it", "[moving]") {
  // Ubiquitin from residue 55 on turned by 8 degrees about a pivot: seen
  // moving with that turn, the other atoms moved. Independent oracle (the
  // QP of MATH.md section 2): at points x within each proven vertex's
  // reach, F after the turn at turn(x) equals F before at x, with the same
  // support. A vertex whose own point is held by an atom that did not turn
  // must not be proven, and most vertices 9 A from every such atom must be.
  const UbiquitinTail tail = ubiquitin_tail(55);
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 2, 0).normalized();
  const std::vector<Ball> after = hinged(tail.start, tail.moving, tail.pivot, axis, 8.0);
  detail::RigidMotion turn;
  turn.rotation = Eigen::AngleAxisd(8.0 * M_PI / 180, axis).toRotationMatrix();
  turn.translation = tail.pivot - turn.rotation * tail.pivot;
  const SkinComplex from = build_skin_complex(tail.start);
  const SkinMeshResult made = mesh_skin(from);
  REQUIRE(made.status == MeshingStatus::ok);
  const SurfaceMesh& mesh = made.mesh;
  const std::vector<char> all(mesh.vertices.size(), 1);
  const std::vector<double> reach = detail::judged_reach(mesh, MeshingOptions{}.tolerance, all);
  const std::vector<Ball> seen = detail::balls_moving_with(turn, tail.start, after);
  for (size_t b = 0; b < seen.size(); ++b)  // the turned atoms where they were, bit for bit
    if (tail.moving[b]) CHECK((seen[b].center == tail.start[b].center && seen[b].weight == tail.start[b].weight));
  const std::vector<char> carried = detail::skin_unchanged_near(from, seen, mesh, reach, all);
  const SkinOracle before_oracle(tail.start, 0.5), after_oracle(after, 0.5);
  std::mt19937 random(11);
  long proven = 0, far = 0, far_proven = 0, checked = 0;
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    const Eigen::Vector3d& x0 = mesh.vertices[v];
    const OracleResult at = before_oracle.evaluate(x0);
    const bool held_by_still = std::any_of(at.support.begin(), at.support.end(),
                                           [&](const auto& b) { return tail.moving[static_cast<size_t>(b.first)] == 0; });
    if (held_by_still) CHECK_FALSE(carried[v]);
    double nearest = INFINITY;  // of the atoms that did not turn, at both places seen from the turn
    for (size_t b = 0; b < after.size(); ++b)
      if (!tail.moving[b]) nearest = std::min({nearest, (tail.start[b].center - x0).norm(), (seen[b].center - x0).norm()});
    far += nearest > 9;
    far_proven += nearest > 9 && carried[v];
    if (!carried[v]) continue;
    ++proven;
    if (v % 3 != 0) continue;
    checked += same_skin_around(before_oracle, after_oracle, turn, x0, reach[v], 1e-10, random);
  }
  INFO(proven << " of " << mesh.vertices.size() << " proven; far from still atoms " << far_proven << " of " << far);
  CHECK(checked > 1000);
  CHECK(far > 200);
  CHECK(far_proven > far / 2);
  CHECK(proven < static_cast<long>(mesh.vertices.size()));
}

TEST_CASE("a matched motion leaves the atoms that do not move where they are, bit for bit", "[moving]") {
  // Ubiquitin with its last two residues turned by 6 degrees, as a user's
  // two PDB files of one domain motion: every other atom is at the same
  // place on both sides. Written as (1 - t) a + t a, a centre moves by a
  // rounding, and a radius squared again changes its weight by one: the
  // engine then found no skin left as it was and judged every triangle.
  const UbiquitinTail tail = ubiquitin_tail(75);
  const Molecule ubi = read_molecule(test::data_file("1ubi.pdb"));
  Molecule turned = ubi;
  const std::vector<Ball> end = hinged(tail.start, tail.moving, tail.pivot, Eigen::Vector3d(0, 0, 1), 6.0);
  for (size_t i = 0; i < turned.atoms.size(); ++i) turned.atoms[i].position = end[i].center;
  const MatchedMotion motion = match_motion(ubi, tail.start, turned, balls_from_molecule(turned, 0.5));
  REQUIRE(motion.matched == static_cast<long>(ubi.atoms.size()));
  MovingOptions options;
  options.max_step = 0.05;  // several internal steps a frame: those keep them in place too
  options.repair.patch.max_sample_share = 0.9;  // ubiquitin is small (as above)
  MovingBalls moving(motion.balls_at(0), options);
  for (int k = 1; k <= 3; ++k) {
    const double t = k / 3.0;
    const std::vector<Ball> balls = motion.balls_at(t);
    for (size_t i = 0; i < balls.size(); ++i)
      if (!tail.moving[i]) {
        REQUIRE(balls[i].center == tail.start[i].center);
        REQUIRE(balls[i].weight == tail.start[i].weight);
      }
    const MorphFrame& f = moving.advance_to(balls, t);
    INFO("frame " << k << ": " << f.stats.steps << " steps, " << f.stats.settled << " settled, remeshed "
                   << f.stats.remeshed_because);
    CHECK(f.stats.steps > 1);
    // The first step follows the first frame, meshed at other criteria, and
    // judges every triangle; in later frames every step finds most of the
    // skin as it was (settled counts each step's).
    if (k > 1) CHECK(f.stats.settled > f.stats.steps * f.stats.triangles / 3);
  }
}

TEST_CASE("moving balls: a patch's new triangles pass the frame judge next to necks about to pinch", "[moving][large]") {
  // Half of ubiquitin's atoms (from index 300 on) turned 3 degrees a frame
  // about an axis through atom 300, in steps of up to 0.5 A: steps that
  // open and pinch necks where the halves meet. At frame 5 a patch's
  // refinement made triangles whose Voronoi edge crossed the skin once
  // where the judge's window about the circumcentre crosses it twice; the
  // judge refused them, the patch could not change them, and the frame was
  // remeshed whole. The patch's refinement now holds its facets to the
  // judge's window.
  std::vector<Ball> start = molecule_balls("1ubi.pdb");
  centre_balls(start);
  const size_t first = 300;
  const Eigen::Vector3d pivot = start[first].center;
  std::vector<char> moving(start.size(), 0);
  std::fill(moving.begin() + static_cast<long>(first), moving.end(), 1);
  MovingOptions options;
  options.repair.patch.max_sample_share = 0.9;  // ubiquitin is small (as above)
  MovingBalls engine(start, options);
  for (int k = 1; k <= 5; ++k) {
    const std::vector<Ball> balls = hinged(start, moving, pivot, Eigen::Vector3d(1, 2, 3), 3.0 * k);
    const MorphFrame& f = engine.advance_to(balls, k);
    INFO("frame " << k << ": remeshed " << f.stats.remeshed << " " << f.stats.remeshed_because);
    CHECK(f.stats.remeshed_because.find("new triangles failing the frame criteria") == std::string::npos);
    if (k == 5) check_frame(engine, balls, options.frames.min_angle);
  }
}

TEST_CASE("moving balls: necks that open in a step are mended by the local patch with their topology and ids",
          "[moving][large]") {
  // 3mht's chain A with residues 187-304 turning 0.2 degrees a frame about
  // the axis through the CA atoms of residues 186 and 305, as the frames of
  // a PDB trajectory hold them (coordinates to 1e-3 A). At frame 8 necks
  // open where the domains meet (the skin's Euler characteristic rises by
  // 4); the smallest, of size 0.03 A, has no vertex on it. Without skin
  // points at the step's topology changes, the local patch failed its Euler
  // check and the whole remesh from the vertices closed that neck again, so
  // the frame was meshed from scratch, every id new. Seeded there, the
  // patch mends the step.
  const Molecule m = read_molecule(test::data_file("3mht.pdb"));
  const std::vector<Ball> all = balls_from_molecule(m, 0.5);
  std::vector<Ball> start;
  std::vector<char> moving;
  Eigen::Vector3d pivot = Eigen::Vector3d::Zero(), end = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < m.atoms.size(); ++i) {
    const Atom& a = m.atoms[i];
    if (a.chain != "A") continue;
    start.push_back(all[i]);
    moving.push_back(a.residue_number >= 187 && a.residue_number <= 304);
    if (a.name == "CA" && a.residue_number == 186) pivot = a.position;
    if (a.name == "CA" && a.residue_number == 305) end = a.position;
  }
  const auto frame_balls = [&](int k) {
    std::vector<Ball> balls = hinged(start, moving, pivot, end - pivot, 0.2 * k);
    for (Ball& b : balls)
      for (int c = 0; c < 3; ++c) b.center[c] = std::round(b.center[c] * 1000) / 1000;
    return balls;
  };
  const SkinTopology before = skin_topology(frame_balls(7)), after = skin_topology(frame_balls(8));
  REQUIRE(after.euler != before.euler);  // the premise: the skin's topology changes in the step
  MovingBalls engine(frame_balls(0));
  // A frame reports the critical events of its steps: none while the
  // skin's topology stays, and when not at least one per 2 of the skin's
  // Euler change (each critical cell changes the body's Euler
  // characteristic by 1, its boundary's by 2).
  SkinTopology was = skin_topology(frame_balls(0));
  for (int k = 1; k <= 8; ++k) {
    const MorphFrame& frame = engine.advance_to(frame_balls(k), k);
    const SkinTopology now = skin_topology(frame_balls(k));
    INFO("frame " << k << ": " << frame.stats.events << " events, " << was.text() << " -> " << now.text());
    if (now == was && frame.stats.steps == 1) CHECK(frame.stats.events == 0);
    CHECK(2 * frame.stats.events >= std::abs(now.euler - was.euler));
    was = now;
  }
  const MorphFrame& f = engine.frame();
  INFO("frame 8: remeshed " << f.stats.remeshed << " (" << f.stats.remeshed_because << "), from scratch "
                            << f.stats.full_rebuild << ", ids kept " << f.stats.ids_kept);
  CHECK_FALSE(f.stats.remeshed);
  CHECK_FALSE(f.stats.full_rebuild);
  CHECK(f.stats.ids_kept >= 0.9);
  CHECK(f.stats.topology_certified);
  CHECK(mesh_topology(f.mesh) == after);
}

TEST_CASE("moving balls: necks that open and pinch are mended by surgery, every frame checked", "[moving]") {
  // Two balls of radius 1.6 A approach from 0.65 A apart to 0.35 A into
  // each other and part again, 0.1 A a frame (shrink factor 1/2: their skins
  // join when the balls meet). At the step where they meet a neck opens,
  // at the step where they part it pinches; each is cut and joined or
  // capped (necks.hpp), and the frame is made without a whole remesh.
  const double r = 1.6;
  const auto balls_at = [&](double gap) {
    return std::vector<Ball>{{Eigen::Vector3d(-(r + gap / 2), 0.05, 0.02), r * r},
                             {Eigen::Vector3d(r + gap / 2, -0.03, 0.0), r * r}};
  };
  std::vector<double> gaps;
  for (int k = 6; k >= -4; --k) gaps.push_back(0.1 * k + 0.05);
  for (int k = -3; k <= 6; ++k) gaps.push_back(0.1 * k + 0.05);
  MovingBalls engine(balls_at(gaps.front()));
  std::set<long> ids_before(engine.frame().ids.begin(), engine.frame().ids.end());
  long necks = 0;
  for (size_t k = 1; k < gaps.size(); ++k) {
    const std::vector<Ball> balls = balls_at(gaps[k]);
    const MorphFrame& f = engine.advance_to(balls, static_cast<double>(k));
    INFO("frame " << k << " (gap " << gaps[k] << " A): " << f.stats.events << " events, " << f.stats.necks
                  << " necks, undone " << f.stats.surgeries_undone << ", remeshed " << f.stats.remeshed << " ("
                  << f.stats.remeshed_because << ")");
    check_frame(engine, balls, MovingOptions{}.frames.min_angle);
    CHECK(f.stats.surgeries_undone == 0);
    if (f.stats.events > 0) {
      CHECK(f.stats.necks == f.stats.events);
      CHECK_FALSE(f.stats.remeshed);
    }
    // The surgery and the edits after it change the mesh near the neck
    // only: at the events every vertex more than 1.5 A from the plane
    // between the balls keeps its id.
    long new_far = 0;
    for (size_t v = 0; v < f.mesh.vertices.size(); ++v)
      new_far += std::abs(f.mesh.vertices[v].x()) > 1.5 && !ids_before.count(f.ids[v]);
    if (f.stats.events > 0) CHECK(new_far == 0);
    ids_before = std::set<long>(f.ids.begin(), f.ids.end());
    necks += f.stats.necks;
  }
  CHECK(necks == 2);

  // A frame the edits and the patch cannot finish after a surgery (here
  // its first certificate is made to fail) is mended again from before it,
  // by the patch (which may take nearly the whole of so small a frame).
  MovingOptions options;
  options.repair.patch.max_sample_share = 0.9;
  MovingBalls again(balls_at(gaps.front()), options);
  bool armed = false;
  detail::inject_certificate_fault(again, [&](SurfaceMesh& mesh, std::vector<long>&) {
    if (armed) mesh.triangles.pop_back();
    armed = false;
  });
  long undone = 0;
  for (size_t k = 1; k < gaps.size(); ++k) {
    armed = true;
    const std::vector<Ball> balls = balls_at(gaps[k]);
    const MorphFrame& f = again.advance_to(balls, static_cast<double>(k));
    INFO("frame " << k << ": " << f.stats.events << " events, undone " << f.stats.surgeries_undone << ", remeshed "
                  << f.stats.remeshed << " (" << f.stats.remeshed_because << ")");
    check_frame(again, balls, MovingOptions{}.frames.min_angle);
    if (f.stats.events > 0) {
      CHECK(f.stats.surgeries_undone == f.stats.events);
      CHECK(f.stats.necks == 0);
      CHECK_FALSE(f.stats.remeshed);
    }
    undone += f.stats.surgeries_undone;
  }
  CHECK(undone == 2);
}

TEST_CASE("moving balls: a void born is meshed as a sphere by surgery, every frame checked", "[moving]") {
  // Four balls at the corners of a tetrahedron (four_balls.hpp) move out
  // from 2.425 A to 2.515 A from its centre and back, 0.01 A a frame: the
  // orthogonal sphere's R2 (about l^2 - 6.1) turns positive between 2.465
  // and 2.475 A, where a void is born in the tetrahedron's cell (shrink
  // factor 1/2), and negative again on the way back, where it is filled.
  // The birth is meshed as a sphere of its own (births.hpp): no patch, no
  // remesh. With birth surgery off the patch meshes it, as a check that the
  // frames are the same skin either way.
  const auto balls_at = [](double l) { return test::tetrahedron_of_balls(l); };
  std::vector<double> distances;
  for (int k = 0; k <= 9; ++k) distances.push_back(2.425 + 0.01 * k);
  for (int k = 8; k >= 0; --k) distances.push_back(2.425 + 0.01 * k);
  for (const bool surgery : {true, false}) {
    INFO((surgery ? "by surgery" : "by the patch"));
    MovingOptions options;
    options.repair.birth_surgery = surgery;
    MovingBalls engine(balls_at(distances.front()), options);
    REQUIRE(engine.frame().stats.topology_certified);
    long births = 0, voids_seen = 0;
    for (size_t k = 1; k < distances.size(); ++k) {
      const std::vector<long> ids_before = engine.frame().ids;
      const std::vector<Ball> balls = balls_at(distances[k]);
      const MorphFrame& f = engine.advance_to(balls, static_cast<double>(k));
      INFO("frame " << k << " (" << distances[k] << " A): " << f.stats.events << " events, " << f.stats.births
                    << " births, patch " << f.stats.patch_triangles << ", remeshed " << f.stats.remeshed << " ("
                    << f.stats.remeshed_because << ")");
      check_frame(engine, balls, MovingOptions{}.frames.min_angle);
      CHECK_FALSE(f.stats.remeshed);
      CHECK(f.stats.surgeries_undone == 0);
      voids_seen += mesh_topology(f.mesh).voids;
      if (f.stats.births > 0) {
        CHECK(f.stats.patch_triangles == 0);
        // The void's vertices are new; the outer skin keeps its ids as in a step without events.
        const std::set<long> had(ids_before.begin(), ids_before.end());
        const SurfaceComponents parts = surface_components(f.mesh);
        std::vector<char> in_void(f.mesh.vertices.size(), 0);
        for (size_t t = 0; t < f.mesh.triangles.size(); ++t)
          if (parts.is_cavity(parts.of_triangle[t]))
            for (int v : f.mesh.triangles[t]) in_void[static_cast<size_t>(v)] = 1;
        long void_kept = 0, outer = 0, outer_kept = 0;
        for (size_t v = 0; v < in_void.size(); ++v) {
          const long kept = static_cast<long>(had.count(f.ids[v]));
          if (in_void[v]) void_kept += kept;
          else ++outer, outer_kept += kept;
        }
        CHECK(std::count(in_void.begin(), in_void.end(), 1) > 0);
        CHECK(void_kept == 0);
        CHECK(static_cast<double>(outer_kept) >= 0.9 * static_cast<double>(outer));
      }
      births += f.stats.births;
    }
    CHECK(births == (surgery ? 1 : 0));
    CHECK(voids_seen >= 2);  // premise: the void is there for a few frames
  }
}

TEST_CASE("moving balls: atoms on one side only grow out of and shrink into their anchor", "[moving]") {
  ReadOptions read;
  const Molecule full = read_molecule(test::data_file("pept.pdb"), read);
  Molecule fewer = full;
  // A side chain's end present in the target only, the first atom in the source only.
  const size_t dropped = fewer.atoms.size() - 1;
  fewer.atoms.erase(fewer.atoms.begin() + static_cast<long>(dropped));
  Molecule target = full;
  target.atoms.erase(target.atoms.begin());
  const std::vector<Ball> source_balls = balls_from_molecule(fewer, 0.5), target_balls = balls_from_molecule(target, 0.5);
  const MatchedMotion motion = match_motion(fewer, source_balls, target, target_balls);
  CHECK(motion.source_only == 1);
  CHECK(motion.target_only == 1);
  CHECK(motion.matched == static_cast<long>(full.atoms.size()) - 2);
  // The ends are the sides' own skins.
  const std::vector<Ball> at0 = motion.balls_at(0), at1 = motion.balls_at(1);
  const SkinOracle source_oracle(source_balls, 0.5), target_oracle(target_balls, 0.5);
  MovingBalls moving(at0);
  for (const Eigen::Vector3d& x : moving.frame().mesh.vertices) REQUIRE(source_oracle.evaluate(x).distance() < 1e-8);
  for (int k = 1; k <= 4; ++k) {
    const double t = k / 4.0;
    const std::vector<Ball> balls = motion.balls_at(t);
    moving.advance_to(balls, t);
    check_frame(moving, balls, 20.0);
  }
  double worst = 0;
  for (const Eigen::Vector3d& x : moving.frame().mesh.vertices) worst = std::max(worst, target_oracle.evaluate(x).distance());
  CHECK(worst < 1e-8);
}

TEST_CASE("moving balls: ubiquitin's NMR models 1 -> 2 -> 3 as one motion, ids kept across models", "[moving]") {
  // data/2k39_3models.pdb (residues 1-10 of three models), each model
  // fitted onto the first, five frames from one model to the next.
  ReadOptions read;
  const Molecule first = read_molecule(test::data_file("2k39_3models.pdb"), read);
  MovingBalls moving(balls_from_molecule(first, 0.5));
  std::vector<Ball> before = moving.balls();
  for (int model = 2; model <= 3; ++model) {
    read.model = model;
    Molecule m = read_molecule(test::data_file("2k39_3models.pdb"), read);
    const RigidMotion fit = align(first, m, AlignmentMethod::kabsch).motion;  // before m is moved from
    m = moved(std::move(m), fit);
    const std::vector<Ball> keyframe = balls_from_molecule(m, 0.5);
    REQUIRE(keyframe.size() == before.size());
    for (int k = 1; k <= 5; ++k) {
      std::vector<Ball> balls = keyframe;
      for (size_t i = 0; i < balls.size(); ++i) balls[i].center = before[i].center + k / 5.0 * (keyframe[i].center - before[i].center);
      if (k == 5) balls = keyframe;
      const MorphFrame& f = moving.advance_to(balls, model - 1 + k / 5.0);
      INFO("model " << model << " frame " << k << ": ids kept " << f.stats.ids_kept << ", remeshed " << f.stats.remeshed);
      CHECK(f.stats.ids_kept >= 0.5);
      CHECK(f.stats.topology_certified);
    }
    check_frame(moving, keyframe, 20.0);  // the keyframe reached exactly: the model's own skin
    before = keyframe;
  }
}

TEST_CASE("moving balls: complexes built ahead, the next call's told or not, make the same frames as built in step",
          "[moving]") {
  // 2k39 model 1 -> 3 (residues 1-10) in 6 frames, internal steps of at
  // most 0.3 A, so that a frame takes several: each step's complex is
  // built beside the repair of the step before, within a frame and across
  // frames, against an engine that builds every complex in its own step.
  // Frame 3 announces model 3 itself while frame 4 follows: what was
  // built ahead is not the step asked for, and must not be used.
  const auto models = models_1_and_3_of_2k39();
  const std::vector<Ball>& from = models.first;
  const std::vector<Ball>& to = models.second;
  REQUIRE(from.size() == to.size());
  const auto frame_balls = [&](int k) {
    std::vector<Ball> balls = from;
    for (size_t i = 0; i < balls.size(); ++i) balls[i].center += k / 6.0 * (to[i].center - from[i].center);
    return k == 6 ? to : balls;
  };
  MovingOptions options;
  options.max_step = 0.3;
  MovingOptions serial = options;
  serial.build_ahead = false;
  MovingBalls plain(from, serial), ahead(from, options);
  long built_ahead = 0, steps = 0;
  for (int k = 1; k <= 6; ++k) {
    INFO("frame " << k);
    const std::vector<Ball> announced = k == 3 ? to : k < 6 ? frame_balls(k + 1) : std::vector<Ball>{};
    const MorphFrame& a = plain.advance_to(frame_balls(k), k);
    const MorphFrame& b = ahead.advance_to(frame_balls(k), k, announced);
    test::check_same_frames(a, b);
    CHECK(a.stats.built_ahead == 0);
    CHECK(b.stats.steps > 1);
    // Every step but a frame's first is built ahead; the first too, unless
    // the frame before announced other balls (frame 4) or nothing (frame 1).
    CHECK(b.stats.built_ahead == b.stats.steps - (k == 1 || k == 4 ? 1 : 0));
    built_ahead += b.stats.built_ahead;
    steps += b.stats.steps;
  }
  CHECK(built_ahead >= steps - 2);
}

TEST_CASE("moving balls: a step with few triangles failing after the edits is patched, not remeshed whole",
          "[moving]") {
  // 2k39 model 1 -> 3 (residues 1-10, about 5,300 triangles) in 101 frames,
  // as bench_moving runs it. One step leaves more triangles failing after
  // the edits than 1% of the frame, and is remeshed whole without
  // PatchPolicy::always_patch_up_to; with it (the default) no step
  // is remeshed for fewer failing triangles than that, and every frame is
  // certified by the engine as before.
  const auto models = models_1_and_3_of_2k39();
  const std::vector<Ball>& from = models.first;
  const std::vector<Ball>& to = models.second;
  REQUIRE(from.size() == to.size());
  long patched = 0;  // frames a patch mended
  const auto run = [&](long always_patch_up_to, long& remeshed, long& remeshed_for_share, long& least_share) {
    MovingOptions options;
    options.repair.patch.always_patch_up_to = always_patch_up_to;
    MovingBalls moving(from, options);
    remeshed = remeshed_for_share = 0;
    least_share = LONG_MAX;
    for (int k = 1; k <= 100; ++k) {
      std::vector<Ball> balls = from;
      for (size_t i = 0; i < balls.size(); ++i) balls[i].center += k / 100.0 * (to[i].center - from[i].center);
      const MorphFrame& f = moving.advance_to(k == 100 ? to : balls, k / 100.0);
      CHECK(f.stats.topology_certified);
      // The edits' and the patches' time are parts of the repair's.
      CHECK(f.stats.seconds_edits + f.stats.seconds_patch <= f.stats.seconds_repair);
      CHECK((f.stats.patch_attempts > 0) == (f.stats.seconds_patch > 0));
      if (f.stats.patch_triangles > 0) CHECK(f.stats.patch_attempts > 0);
      patched += f.stats.patch_triangles > 0;
      remeshed += f.stats.remeshed;
      const long share = test::remeshed_for_share(f.stats.remeshed_because);
      if (share >= 0) {
        ++remeshed_for_share;
        least_share = std::min(least_share, share);
      }
    }
  };
  long remeshed = 0, for_share = 0, least = 0;
  run(0, remeshed, for_share, least);
  CHECK(for_share >= 1);  // the premise
  CHECK(least < 200);
  const long remeshed_by_share_alone = remeshed;
  run(MovingOptions{}.repair.patch.always_patch_up_to, remeshed, for_share, least);
  REQUIRE(MovingOptions{}.repair.patch.always_patch_up_to == 200);
  CHECK((for_share == 0 || least >= 200));
  CHECK(remeshed < remeshed_by_share_alone);
  CHECK(patched > 0);
}

TEST_CASE("moving balls: ubiquitin's atoms in thermal motion, voids opening and closing, every frame valid", "[moving][large]") {
  // Each frame puts every atom at its rest place plus its own offset, up to
  // 0.15 A along each axis (seeded): an MD-like ensemble, whose small voids
  // and tunnels open and close from one frame to the next. Every frame is
  // checked as the commands check theirs (check_guarantees: the static
  // oracle, where it cannot certify the complex of the frame's balls built
  // from scratch; the angle bound; a closed oriented manifold without
  // self-intersections; the skin's topology from its alpha complex).
  ReadOptions read;
  const std::vector<Ball> rest = balls_from_molecule(read_molecule(test::data_file("1ubi.pdb"), read), 0.5);
  std::mt19937 random(34);
  std::uniform_real_distribution<double> offset(-0.15, 0.15);
  MovingBalls moving(rest);
  std::vector<SkinTopology> seen{skin_topology(rest)};
  for (int k = 1; k <= 4; ++k) {
    std::vector<Ball> balls = rest;
    for (Ball& b : balls)
      for (int axis = 0; axis < 3; ++axis) b.center[axis] += offset(random);  // drawn in a fixed order
    const MorphFrame& f = moving.advance_to(balls, k);
    INFO("frame " << k << ": " << f.stats.vertices << " vertices, ids kept " << f.stats.ids_kept << ", remeshed "
                   << f.stats.remeshed << " (" << f.stats.remeshed_because << ")");
    GuaranteeOptions bounds;
    bounds.min_angle = 20;
    const GuaranteeReport g = check_guarantees(f.mesh, balls, 0.5, bounds);
    CHECK(g.all_hold());
    CHECK(g.surface_error.max < 1e-8);
    CHECK(f.stats.topology_certified);
    CHECK(f.stats.ids_kept >= 0.5);
    seen.push_back(*g.skin);
  }
  // The premise: the skin's topology changed between frames.
  CHECK(std::adjacent_find(seen.begin(), seen.end(), std::not_equal_to<SkinTopology>()) != seen.end());
}

TEST_CASE("the topology certificate refuses a frame whose bookkeeping is wrong", "[moving]") {
  // Two separate atoms, one moved a little: no topology change, nothing to
  // mend. The fault drops the component of the mesh's last vertex, as
  // bookkeeping that lost a component would.
  std::vector<Ball> balls{{Eigen::Vector3d::Zero(), 4.0}, {Eigen::Vector3d(6, 0, 0), 4.0}};
  MovingBalls moving(balls);
  REQUIRE(mesh_topology(moving.frame().mesh) == SkinTopology{2, 0, 4});
  const auto drop_a_component = [](SurfaceMesh& mesh, std::vector<long>& ids) {
    const SurfaceComponents parts = surface_components(mesh);
    std::vector<char> keep(mesh.triangles.size());
    for (size_t f = 0; f < keep.size(); ++f) keep[f] = parts.of_triangle[f] != parts.of_triangle.back();
    std::vector<int> kept_from;
    mesh = detail::used_part(mesh, keep, kept_from);
    std::vector<long> kept_ids;
    for (int v : kept_from) kept_ids.push_back(ids[static_cast<size_t>(v)]);
    ids = kept_ids;
  };
  balls[1].center.x() += 0.3;
  SECTION("a mended frame that lost a component is not output: the step is remeshed") {
    int faults = 0;
    detail::inject_certificate_fault(moving, [&](SurfaceMesh& mesh, std::vector<long>& ids) {
      if (faults++ == 0) drop_a_component(mesh, ids);
    });
    const MorphFrame& f = moving.advance_to(balls, 1);
    REQUIRE(faults >= 1);
    CHECK(mesh_topology(f.mesh) == skin_topology(balls));
    CHECK(f.stats.remeshed);
    CHECK(f.stats.remeshed_because.find("the mended mesh has") != std::string::npos);
    CHECK(f.ids.size() == f.mesh.vertices.size());
  }
  SECTION("a frame still wrong after the remesh is refused with an error") {
    detail::inject_certificate_fault(moving, drop_a_component);
    CHECK_THROWS_WITH(moving.advance_to(balls, 1), Catch::Contains("the frame is refused"));
  }
}

TEST_CASE("moving balls: vertices stay where no ball of their cell moved, and turn with the hinge where it carried all",
          "[moving]") {
  // Ubiquitin's residues 70-76 turned by a degree about the CA atom before
  // them, one step. Near the hinge, a cell of atoms that stayed has
  // neighbours that moved: its vertices stay put rather than turn with that
  // neighbourhood, and a cell of atoms the hinge carried turns with the
  // hinge rather than with a neighbourhood that mixes both.
  const UbiquitinTail tail = ubiquitin_tail(70);
  const Eigen::Vector3d axis(0, 0, 1);
  MovingBalls moving(tail.start, MovingOptions{});
  const MorphFrame before = moving.frame();
  std::unordered_map<long, Eigen::Vector3d> was;
  for (size_t v = 0; v < before.ids.size(); ++v) was[before.ids[v]] = before.mesh.vertices[v];
  const std::vector<Ball> after = hinged(tail.start, tail.moving, tail.pivot, axis, 1.0);
  const MorphFrame& f = moving.advance_to(after, 1);
  REQUIRE(f.stats.steps == 1);
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(M_PI / 180, axis).toRotationMatrix();
  long still = 0, stayed = 0, carried = 0, turned = 0;
  for (size_t v = 0; v < f.ids.size(); ++v) {
    const auto old = was.find(f.ids[v]);
    if (old == was.end()) continue;
    const MixedCell& cell = moving.complex().cell(f.mesh.cells[v]);
    bool all_still = true, all_moving = true;
    for (int i = 0; i <= cell.dim; ++i) {
      const auto b = static_cast<size_t>(cell.balls[static_cast<size_t>(i)]);
      all_still = all_still && !tail.moving[b];
      all_moving = all_moving && tail.moving[b];
    }
    if (all_still) {
      ++still;
      stayed += f.mesh.vertices[v] == old->second;
    } else if (all_moving) {
      ++carried;
      turned += (f.mesh.vertices[v] - (tail.pivot + turn * (old->second - tail.pivot))).norm() <= 1e-9;
    }
  }
  INFO(stayed << " of " << still << " vertices in cells of atoms that stayed are where they were; " << turned << " of "
              << carried << " in cells of atoms the hinge carried moved with it");
  CHECK(still > 1000);
  CHECK(carried > 100);
  CHECK(stayed >= 0.99 * still);
  CHECK(turned >= 0.97 * carried);
  check_frame(moving, after, MovingOptions{}.frames.min_angle);
}
