// Who is right about a morph frame's vertex near t = 0 or 1, where the
// morph oracle (docs/math.md section 4) puts it more than 1e-8 A off the skin
// of B(t) while the overlay complex puts it on it (docs/morph.md, "What is
// not there yet")? A third, independent reference decides: the sign of CGAL's
// Skin_surface_3 skin function of B(t) at the vertex moved along its normal
// by +-delta. Where the sign changes between -delta and +delta, the skin
// crosses the normal within delta of the vertex.
//
//   morph_precision [--t T,...] [PAIR]     (default: 2k39 model 1 -> 3 at 0.99, 0.995, 0.999)
//
// For each t, two meshes: the morph's first frame meshed at t on the overlay
// complex (prepare_morph), and the mesher's mesh of B(t)'s own complex (a
// regular triangulation of the live pairs' balls at t). Each one's vertex
// farthest off the skin by the oracle is examined: the oracle's distance,
// |F| / |grad F| of the overlay complex and of B(t)'s own complex, and
// CGAL's sign bracket. CGAL gets B(t)'s balls (live pairs)
// with centres moved by at most 1e-10 A, which it needs on B(t)'s
// cospherical groups; that moves the skin by about as much.
#include "cgal_reference.hpp"
#include "morph_pairs.hpp"

#include "skinmesh/core/interpolation.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/skin_oracle.hpp"
#include "skinmesh/mesher/skin_mesher.hpp"
#include "skinmesh/morph/morph.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Skin_surface_3.h>

#include <cmath>
#include <memory>
#include <cstdio>
#include <exception>
#include <sstream>
#include <string>
#include <vector>

using namespace skinmesh;

namespace {

constexpr double kShrink = 0.5;
constexpr double kJitter = 1e-10;  // Angstrom, per coordinate

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Skin = CGAL::Skin_surface_3<CGAL::Skin_surface_traits_3<K>>;

// The sign of CGAL's skin function at x: -1 inside the body, +1 outside.
int cgal_sign(const Skin& skin, int inside, const Eigen::Vector3d& x) {
  const CGAL::Sign s = skin.sign(K::Point_3(x.x(), x.y(), x.z()));
  return s == CGAL::ZERO ? 0 : (s == CGAL::NEGATIVE ? -1 : 1) * inside;
}

struct Verdict {
  double t = 0;
  const char* mesh = "";  // whose mesh the vertex is from
  double oracle = 0, overlay = 0, own = 0;
  double bracket = -1;  // smallest delta at which CGAL's sign differs at +-delta (-1: none up to 1e-7)
};

// CGAL's skin of B(t) (live pairs, jittered by kJitter) and the sign it
// gives inside the body.
struct CgalSkin {
  std::unique_ptr<Skin> skin;
  int inside = 1;
  explicit CgalSkin(std::vector<Ball> balls) {
    balls = test::jittered(std::move(balls), kJitter);
    std::vector<K::Weighted_point_3> points;
    for (const Ball& b : balls) points.emplace_back(K::Point_3(b.center.x(), b.center.y(), b.center.z()), b.weight);
    skin = std::make_unique<Skin>(points.begin(), points.end(), kShrink, /*grow_balls=*/false);
    const Eigen::Vector3d c = balls.front().center;
    inside = skin->sign(K::Point_3(c[0], c[1], c[2])) == CGAL::NEGATIVE ? 1 : -1;
  }
  double bracket(const Eigen::Vector3d& x, const Eigen::Vector3d& n) const {
    for (double delta : {1e-9, 2e-9, 5e-9, 1e-8, 2e-8, 5e-8, 1e-7})
      if (cgal_sign(*skin, inside, x - delta * n) != cgal_sign(*skin, inside, x + delta * n)) return delta;
    return -1;
  }
};

// The mesh's vertex farthest off the skin by the oracle, judged by all.
Verdict judge_worst(const SurfaceMesh& mesh, const char* name, double t, const MorphOracle& oracle,
                    const SkinComplex& overlay, const SkinComplex& own, const CgalSkin& cgal) {
  Verdict v;
  v.t = t;
  v.mesh = name;
  size_t worst = 0;
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    const double d = oracle.evaluate(mesh.vertices[i], t).distance();
    if (d > v.oracle) v.oracle = d, worst = i;
  }
  const Eigen::Vector3d x = mesh.vertices[worst];
  const SkinEval e = overlay.evaluate(x);
  v.overlay = std::abs(e.value) / e.gradient.norm();
  const SkinEval o = own.evaluate(x);
  v.own = std::abs(o.value) / o.gradient.norm();
  v.bracket = cgal.bracket(x, o.gradient.normalized());
  return v;
}

// At t: the morph's first frame (meshed on the overlay complex) and the
// mesher's mesh of B(t)'s own complex, each judged at its worst vertex.
std::vector<Verdict> examine(const bench::Pair& p, double t) {
  const Morph morph = prepare_morph(p.source, p.target, t);
  const MorphOracle oracle(p.source, p.target, kShrink);
  const std::vector<Ball> balls = interpolated_balls(p.source, p.target, morph.pairs(), t);
  const SkinComplex own = build_skin_complex(balls, {kShrink});
  const CgalSkin cgal(balls);
  MeshingOptions frames;
  frames.min_angle = 20.0;
  const SkinMeshResult own_mesh = mesh_skin(own, frames);
  std::vector<Verdict> out{judge_worst(morph.frame().mesh, "morph frame (overlay)", t, oracle, morph.complex(), own, cgal)};
  if (own_mesh.status == MeshingStatus::ok)
    out.push_back(judge_worst(own_mesh.mesh, "mesher on B(t)'s own complex", t, oracle, morph.complex(), own, cgal));
  return out;
}

std::vector<double> parse_times(const std::string& text) {
  std::vector<double> out;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) out.push_back(std::stod(item));
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<double> times{0.99, 0.995, 0.999};
  std::string spec = std::string(SKINMESH_DATA_DIR) + "/2k39_3models.pdb#1:#3";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--t" && i + 1 < argc) times = parse_times(argv[++i]);
    else if (a.rfind("--", 0) == 0) {
      std::fprintf(stderr, "usage: morph_precision [--t T,...] [PAIR]\n");
      return 2;
    } else spec = a;
  }
  const bench::Pair p = bench::load_pair(spec, kShrink);
  std::vector<Verdict> rows;
  for (double t : times) {
    std::vector<Verdict> found;
    try {
      found = examine(p, t);
    } catch (const std::exception& e) {  // a frame the mesher cannot make there: say so, go on
      std::printf("{\"pair\": \"%s\", \"t\": %.6g, \"error\": \"%s\"}\n", p.name.c_str(), t, e.what());
      continue;
    }
    for (const Verdict& v : found) {
      rows.push_back(v);
      std::printf("{\"pair\": \"%s\", \"t\": %.6g, \"mesh\": \"%s\", \"oracle_A\": %.3e, "
                  "\"overlay_complex_A\": %.3e, \"own_complex_A\": %.3e, \"cgal_sign_change_within_A\": %.1e}\n",
                  p.name.c_str(), v.t, v.mesh, v.oracle, v.overlay, v.own, v.bracket);
    }
    std::fflush(stdout);
  }
  std::printf("\n| t | worst vertex of | oracle (A) | overlay complex (A) | B(t)'s own complex (A) | CGAL's sign changes within (A) |\n"
              "|---|---|---|---|---|---|\n");
  for (const Verdict& v : rows) {
    char bracket[32];
    if (v.bracket < 0) std::snprintf(bracket, sizeof bracket, "not within 1e-7");
    else std::snprintf(bracket, sizeof bracket, "%.0e", v.bracket);
    std::printf("| %.6g | %s | %.2e | %.2e | %.2e | %s |\n", v.t, v.mesh, v.oracle, v.overlay, v.own, bracket);
  }
  return 0;
}
