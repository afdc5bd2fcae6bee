// The quality mesher side by side with CGAL's skin meshers on the same
// weighted points (w = r^2/s, s = 1/2):
//   - skinmesh, curvature-adaptive sizing (the default of `skinmesh mesh`),
//     with all threads and with one;
//   - skinmesh with its edge-contraction clean-up (--contract-below 0.5);
//   - skinmesh with edges capped at L (--edge-length L; the curvature bound
//     still applies where it is smaller);
//   - CGAL's skin mesher (Kruithof-Vegter, certified topology; what
//     make_skin_surface_mesh_3 builds, with faces that keep their mixed-complex
//     cell so that each subdivision projects from there), 0 and 1 subdivision
//     steps;
//   - CGAL Surface_mesher (restricted Delaunay refinement) on the same skin as
//     an implicit surface, angle bound 30 degrees, Delaunay-ball radius bound
//     L/sqrt(3) and distance bound 0.1 A: the criteria of the capped skinmesh
//     run, whose size rule is "radius > L/sqrt(3)" (plus its curvature bound);
//     once with skinmesh's complex evaluating the skin function, once with
//     CGAL's Skin_surface_3 giving its sign (what a user of CGAL alone runs).
// Each run is a forked child (own peak memory, a time limit). After timing,
// the child grades its mesh with the project's grader and measures every
// vertex with the oracle of docs/math.md section 2. Prints JSON lines, then a
// markdown table, then the ratios.
//
//   bench_mesher [--edge-length L] [--timeout S] [--skip-surface-mesher] [--only TEXT] [FILE...]
//   (--only: run the methods whose name contains TEXT)
//   (default files: data/pept.pdb, data/1ubi.pdb, data/1hpv.pdb, data/3mht.pdb)
#include "cgal_reference.hpp"
#include "skinmesh/core/molecule.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/quality/mesh_quality.hpp"
#include "skinmesh/quality/on_surface_error.hpp"
#include "skinmesh/mesher/skin_mesher.hpp"

#include <CGAL/Complex_2_in_triangulation_3.h>
#include <CGAL/IO/facets_in_complex_2_to_triangle_mesh.h>
#include <CGAL/Implicit_surface_3.h>
#include <CGAL/Skin_surface_3.h>
#include <CGAL/Skin_surface_traits_3.h>
#include <Eigen/Geometry>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_default_criteria_3.h>
#include <CGAL/Surface_mesh_default_triangulation_3.h>
#include <CGAL/make_surface_mesh.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

using namespace skinmesh;
using Clock = std::chrono::steady_clock;

namespace {

constexpr double kShrink = 0.5;

// What a child sends back: fixed-size, so it goes through a pipe as raw bytes.
struct Measured {
  double seconds = 0, peak_mb = 0;
  double vertices = 0, triangles = 0;
  double min_angle = 0, share_below_20 = 0, share_below_10 = 0;
  double max_error = 0, uncertified = 0;
  double closed_manifold_oriented = 0;  // 1 or 0
  double self_intersecting_pairs = -1;  // -1: not checkable (not a manifold)
  double components = 0, genus = -1;
};

struct Outcome {
  std::string status = "ok";  // ok | timeout | failed
  Measured m;
};

double peak_rss_mb() {
  struct rusage usage {};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;
}

// Runs `make_mesh` in a child with a time limit; the child grades the mesh
// after the clock stops, so grading costs neither time nor peak memory.
Outcome run_in_child(int timeout_seconds, const std::vector<Ball>& balls,
                     const std::function<SurfaceMesh()>& make_mesh) {
  int fds[2];
  if (pipe(fds) != 0) throw std::runtime_error("pipe failed");
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    alarm(static_cast<unsigned>(timeout_seconds));
    Measured m;
    try {
      const auto t0 = Clock::now();
      const SurfaceMesh mesh = make_mesh();
      m.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
      m.peak_mb = peak_rss_mb();
      alarm(0);
      const MeshQuality q = grade_mesh(mesh);
      const SurfaceError e = on_surface_error(mesh.vertices, balls, kShrink);
      m.vertices = static_cast<double>(q.vertices);
      m.triangles = static_cast<double>(q.triangles);
      m.min_angle = q.min_angle;
      m.share_below_20 = q.share_below_20;
      m.share_below_10 = q.share_below_10;
      m.max_error = e.max;
      m.uncertified = static_cast<double>(e.uncertified);
      m.closed_manifold_oriented = q.closed && q.manifold && q.oriented ? 1.0 : 0.0;
      m.self_intersecting_pairs = q.self_intersections_checked ? static_cast<double>(q.self_intersecting_pairs) : -1.0;
      m.components = static_cast<double>(q.components);
      m.genus = static_cast<double>(q.genus);
    } catch (const std::exception& error) {
      std::fprintf(stderr, "  failed: %s\n", error.what());
      _exit(2);
    }
    if (write(fds[1], &m, sizeof m) != static_cast<ssize_t>(sizeof m)) _exit(1);
    _exit(0);
  }
  close(fds[1]);
  Outcome out;
  const ssize_t got = read(fds[0], &out.m, sizeof out.m);
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (WIFSIGNALED(status) && WTERMSIG(status) == SIGALRM) out.status = "timeout";
  else if (got != static_cast<ssize_t>(sizeof out.m) || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
    out.status = "failed";
  return out;
}

// A CGAL face graph (here the Surface_mesh of Surface_mesher's output) as a SurfaceMesh.
template <class Mesh>
SurfaceMesh from_face_graph(const Mesh& m) {
  SurfaceMesh out;
  std::map<typename boost::graph_traits<Mesh>::vertex_descriptor, int> index;
  for (auto v : vertices(m)) {
    const auto& p = get(CGAL::vertex_point, m, v);
    index[v] = static_cast<int>(out.vertices.size());
    out.vertices.emplace_back(CGAL::to_double(p.x()), CGAL::to_double(p.y()), CGAL::to_double(p.z()));
  }
  for (auto f : faces(m)) {
    std::array<int, 3> t{};
    int k = 0;
    for (auto v : CGAL::vertices_around_face(halfedge(f, m), m))
      if (k < 3) t[static_cast<size_t>(k++)] = index[v];
    if (k == 3) out.triangles.push_back(t);
  }
  return out;
}

using SurfaceTr = CGAL::Surface_mesh_default_triangulation_3;
using SurfaceGT = SurfaceTr::Geom_traits;

// CGAL's Surface_mesher (30 degrees, the given radius and distance bounds,
// Manifold_tag) on the implicit surface `function` < 0, inside a sphere
// around the first atom (inside the body, where the function is negative).
template <class Function>
SurfaceMesh surface_mesher_on(const Function& function, const std::vector<Ball>& balls, double radius_bound,
                              double distance_bound) {
  const Eigen::Vector3d c = balls.front().center;
  double reach = 0;
  for (const Ball& b : balls) reach = std::max(reach, (b.center - c).norm() + std::sqrt(std::max(0.0, b.weight)));
  reach += 2.0;
  const CGAL::Implicit_surface_3<SurfaceGT, Function> surface(
      function, SurfaceGT::Sphere_3(SurfaceGT::Point_3(c[0], c[1], c[2]), reach * reach), 1e-7);
  SurfaceTr triangulation;
  CGAL::Complex_2_in_triangulation_3<SurfaceTr> c2t3(triangulation);
  const CGAL::Surface_mesh_default_criteria_3<SurfaceTr> criteria(30.0, radius_bound, distance_bound);
  CGAL::make_surface_mesh(c2t3, surface, criteria, CGAL::Manifold_tag());
  CGAL::Surface_mesh<SurfaceGT::Point_3> mesh;
  CGAL::facets_in_complex_2_to_triangle_mesh(c2t3, mesh);
  return from_face_graph(mesh);
}

// CGAL's Surface_mesher on F (our mixed complex evaluates it exactly; the
// oracle that grades the result is independent of it).
SurfaceMesh cgal_surface_mesher(const std::vector<Ball>& balls, double radius_bound, double distance_bound) {
  using GT = SurfaceGT;
  const SkinComplex complex = build_skin_complex(balls, {kShrink});
  struct SkinFunction {
    const SkinComplex* complex;
    std::shared_ptr<int> hint = std::make_shared<int>(-1);  // walking starts where the last query ended
    GT::FT operator()(const GT::Point_3& p) const {
      const SkinEval e = complex->evaluate(Eigen::Vector3d(p.x(), p.y(), p.z()), *hint);
      *hint = e.cell;
      return e.value;
    }
  };
  return surface_mesher_on(SkinFunction{&complex}, balls, radius_bound, distance_bound);
}

// CGAL's Surface_mesher on CGAL's own skin: the sign of Skin_surface_3's skin
// function (exact, located in its triangulated mixed complex from its default
// start) as the implicit function, which is what a user of CGAL alone runs;
// the sign is all the mesher's bisection needs. Same balls (grow_balls off:
// the weights are already r^2/s), same criteria as cgal_surface_mesher.
SurfaceMesh cgal_surface_mesher_on_cgal_skin(const std::vector<Ball>& balls, double radius_bound,
                                             double distance_bound) {
  using GT = SurfaceGT;
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Skin = CGAL::Skin_surface_3<CGAL::Skin_surface_traits_3<K>>;
  std::vector<K::Weighted_point_3> points;
  for (const Ball& b : balls) points.emplace_back(K::Point_3(b.center.x(), b.center.y(), b.center.z()), b.weight);
  const Skin skin(points.begin(), points.end(), kShrink, /*grow_balls=*/false);
  // Skin_surface_3 locates only inside its own bounding box (beyond it the
  // walk meets infinite cells and crashes): a point outside every ball's box
  // is outside the skin, and is answered without it.
  Eigen::AlignedBox3d box;
  for (const Ball& b : balls) {
    const double r = std::sqrt(std::max(0.0, b.weight));
    box.extend(b.center - Eigen::Vector3d::Constant(r));
    box.extend(b.center + Eigen::Vector3d::Constant(r));
  }
  struct SkinSign {
    const Skin* skin;
    Eigen::AlignedBox3d box;
    double inside;  // the sign CGAL gives inside the body, so that inside is negative here
    GT::FT operator()(const GT::Point_3& p) const {
      if (!box.contains(Eigen::Vector3d(p.x(), p.y(), p.z()))) return 1.0;
      const CGAL::Sign sign = skin->sign(K::Point_3(p.x(), p.y(), p.z()));
      return sign == CGAL::ZERO ? 0.0 : (sign == CGAL::NEGATIVE ? -1.0 : 1.0) * inside;
    }
  };
  const Eigen::Vector3d c = balls.front().center;
  const double inside = skin.sign(K::Point_3(c[0], c[1], c[2])) == CGAL::NEGATIVE ? 1.0 : -1.0;
  return surface_mesher_on(SkinSign{&skin, box, inside}, balls, radius_bound, distance_bound);
}

SurfaceMesh ours(const std::vector<Ball>& balls, double edge_length, int threads, double contract_below = 0.0) {
  const SkinComplex complex = build_skin_complex(balls, {kShrink});
  MeshingOptions options;
  options.edge_length = edge_length;
  options.threads = threads;
  options.contract_below = contract_below;
  SkinMeshResult result = mesh_skin(complex, options);
  if (result.status != MeshingStatus::ok) throw std::runtime_error(result.message);
  return std::move(result.mesh);
}

struct Row {
  std::string molecule, method;
  Outcome outcome;
};

void print_json(const Row& r, long atoms, double baseline_mb) {
  const Measured& m = r.outcome.m;
  std::printf(
      "{\"molecule\": \"%s\", \"atoms\": %ld, \"method\": \"%s\", \"status\": \"%s\", \"seconds\": %.3f, "
      "\"peak_mb\": %.1f, \"process_baseline_mb\": %.1f, \"vertices\": %.0f, \"triangles\": %.0f, "
      "\"min_angle\": %.4f, \"share_below_20\": %.5f, \"share_below_10\": %.5f, \"max_on_surface_error\": %.3e, "
      "\"uncertified_vertices\": %.0f, \"closed_manifold_oriented\": %s, \"self_intersecting_pairs\": %.0f, "
      "\"components\": %.0f, \"genus\": %.0f}\n",
      r.molecule.c_str(), atoms, r.method.c_str(), r.outcome.status.c_str(), m.seconds, m.peak_mb, baseline_mb,
      m.vertices, m.triangles, m.min_angle, m.share_below_20, m.share_below_10, m.max_error, m.uncertified,
      m.closed_manifold_oriented > 0 ? "true" : "false", m.self_intersecting_pairs, m.components, m.genus);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  double edge_length = 1.0;
  int timeout = 900;
  bool surface_mesher = true;
  std::string only;
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--edge-length" && i + 1 < argc) edge_length = std::atof(argv[++i]);
    else if (a == "--timeout" && i + 1 < argc) timeout = std::max(1, std::atoi(argv[++i]));
    else if (a == "--skip-surface-mesher") surface_mesher = false;
    else if (a == "--only" && i + 1 < argc) only = argv[++i];
    else if (!a.empty() && a[0] == '-') {
      std::fprintf(stderr,
                   "usage: bench_mesher [--edge-length L] [--timeout S] [--skip-surface-mesher] [--only TEXT] "
                   "[FILE...]\n");
      return 2;
    } else files.push_back(a);
  }
  if (!(edge_length > 0)) {
    std::fprintf(stderr, "bench_mesher: --edge-length must be positive\n");
    return 2;
  }
  if (files.empty())
    files = {std::string(SKINMESH_DATA_DIR) + "/pept.pdb", std::string(SKINMESH_DATA_DIR) + "/1ubi.pdb",
             std::string(SKINMESH_DATA_DIR) + "/1hpv.pdb", std::string(SKINMESH_DATA_DIR) + "/3mht.pdb"};

  char uniform[64], sm[96], sm_cgal_skin[128];
  std::snprintf(uniform, sizeof uniform, "skinmesh edges <= %g A", edge_length);
  std::snprintf(sm, sizeof sm, "CGAL Surface_mesher 30deg r<=%.3g d<=0.1", edge_length / std::sqrt(3.0));
  std::snprintf(sm_cgal_skin, sizeof sm_cgal_skin, "CGAL Surface_mesher 30deg r<=%.3g d<=0.1 on CGAL Skin_surface_3",
                edge_length / std::sqrt(3.0));
  std::vector<Row> rows;
  std::map<std::string, long> atoms_of;
  for (const std::string& file : files) {
    const std::string name = file.substr(file.find_last_of('/') + 1);
    std::vector<Ball> balls;
    try {
      balls = balls_from_molecule(read_molecule(file), kShrink);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "bench_mesher: %s\n", e.what());
      return 1;
    }
    atoms_of[name] = static_cast<long>(balls.size());
    const double baseline = peak_rss_mb();
    std::vector<std::pair<std::string, std::function<SurfaceMesh()>>> methods = {
        {"skinmesh adaptive", [&] { return ours(balls, 0.0, 0); }},
        {"skinmesh adaptive 1 thread", [&] { return ours(balls, 0.0, 1); }},
        {"skinmesh adaptive + contraction", [&] { return ours(balls, 0.0, 0, 0.5); }},
        {uniform, [&] { return ours(balls, edge_length, 0); }},
        {"CGAL skin 0 subdiv", [&] { return test::cgal_skin_mesh(balls, kShrink, 0); }},
        {"CGAL skin 1 subdiv", [&] { return test::cgal_skin_mesh(balls, kShrink, 1); }},
    };
    if (surface_mesher) {
      methods.emplace_back(sm, [&] { return cgal_surface_mesher(balls, edge_length / std::sqrt(3.0), 0.1); });
      methods.emplace_back(sm_cgal_skin, [&] {
        return cgal_surface_mesher_on_cgal_skin(balls, edge_length / std::sqrt(3.0), 0.1);
      });
    }
    for (const auto& [method, make] : methods) {
      if (!only.empty() && method.find(only) == std::string::npos) continue;
      std::fprintf(stderr, "%s: %s ...\n", name.c_str(), method.c_str());
      Row row{name, method, run_in_child(timeout, balls, make)};
      print_json(row, atoms_of[name], baseline);
      rows.push_back(row);
    }
  }

  std::printf("\n| molecule | method | s | peak MB | triangles | k triangles/s | min angle | <20 deg | <10 deg | "
              "max error A | closed manifold | self-int pairs | components | genus |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Row& r : rows) {
    const Measured& m = r.outcome.m;
    if (r.outcome.status != "ok") {
      std::printf("| %s | %s | %s (limit %d s) | | | | | | | | | | | |\n", r.molecule.c_str(), r.method.c_str(),
                  r.outcome.status.c_str(), timeout);
      continue;
    }
    std::printf("| %s | %s | %.2f | %.0f | %.0f | %.1f | %.2f | %.1f%% | %.1f%% | %.1e | %s | %.0f | %.0f | %.0f |\n",
                r.molecule.c_str(), r.method.c_str(), m.seconds, m.peak_mb, m.triangles,
                m.triangles / m.seconds / 1000.0, m.min_angle,
                100 * m.share_below_20, 100 * m.share_below_10, m.max_error,
                m.closed_manifold_oriented > 0 ? "yes" : "no", m.self_intersecting_pairs, m.components, m.genus);
  }
  // Speed ratio at the same criteria: Surface_mesher time over skinmesh uniform time.
  std::printf("\n");
  for (const auto& [name, atoms] : atoms_of) {
    const Row *u = nullptr, *s = nullptr, *cgal_skin = nullptr, *adaptive = nullptr;
    for (const Row& r : rows)
      if (r.molecule == name && r.outcome.status == "ok") {
        if (r.method == uniform) u = &r;
        if (r.method == sm) s = &r;
        if (r.method == sm_cgal_skin) cgal_skin = &r;
        if (r.method == "skinmesh adaptive") adaptive = &r;
      }
    for (const Row* ours_row : {adaptive, u})
      if (ours_row && cgal_skin)
        std::printf("%s (%ld atoms): CGAL Surface_mesher on CGAL's Skin_surface_3 takes %.2fx the time of %s "
                    "(%.2fx its triangles)\n",
                    name.c_str(), atoms, cgal_skin->outcome.m.seconds / ours_row->outcome.m.seconds,
                    ours_row->method.c_str(), cgal_skin->outcome.m.triangles / ours_row->outcome.m.triangles);
    if (u && s) {
      const Measured &a = s->outcome.m, &b = u->outcome.m;
      std::printf(
          "%s (%ld atoms): CGAL Surface_mesher vs skinmesh at the same criteria: %.2fx the time for %.2fx the "
          "triangles; skinmesh makes %.1fx as many triangles per second\n",
          name.c_str(), atoms, a.seconds / b.seconds, a.triangles / b.triangles,
          (b.triangles / b.seconds) / (a.triangles / a.seconds));
    }
  }
  return 0;
}
