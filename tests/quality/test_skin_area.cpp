// The skin's own area (skin_area.hpp) against closed forms, and the outer
// surface of a mesh with cavities and an island inside one.
#include "test_support.hpp"

#include "skinmesh/core/balls.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/mesher/skin_mesher.hpp"
#include "skinmesh/quality/mesh_quality.hpp"
#include "skinmesh/quality/skin_area.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace skinmesh;

namespace {

SurfaceMesh meshed(const std::vector<Ball>& balls) {
  const SkinMeshResult made = mesh_skin(build_skin_complex(balls));
  REQUIRE(made.status == MeshingStatus::ok);
  return made.mesh;
}

// `part` appended to `into`, its triangles turned over when `inward`.
void append(SurfaceMesh& into, const SurfaceMesh& part, bool inward) {
  const int offset = static_cast<int>(into.vertices.size());
  into.vertices.insert(into.vertices.end(), part.vertices.begin(), part.vertices.end());
  for (auto t : part.triangles) {
    if (inward) std::swap(t[1], t[2]);
    into.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  }
}

}  // namespace

TEST_CASE("the skin's area: a lone ball's is 4 pi s w, two apart the sum, nearer than the triangles'", "[quality][area]") {
  const double w = 4.0, s = 0.5;  // skin radius sqrt(s w)
  const double sphere = 4 * M_PI * s * w;
  for (const std::vector<Ball>& balls :
       {std::vector<Ball>{{Eigen::Vector3d(1, 2, 3), w}},
        std::vector<Ball>{{Eigen::Vector3d::Zero(), w}, {Eigen::Vector3d(10, 0, 0), w}}}) {
    const SkinComplex complex = build_skin_complex(balls);
    const SurfaceMesh mesh = meshed(balls);
    const SkinArea a = skin_area(complex, mesh);
    const double truth = sphere * static_cast<double>(balls.size());
    INFO(a.area << " against " << truth << ", uncertainty " << a.uncertainty);
    CHECK(a.converged);
    CHECK(std::abs(a.area - truth) < 1e-4 * truth);
    CHECK(std::abs(a.area - truth) <= a.uncertainty);
    CHECK(a.uncertainty < 1e-3 * truth);
    // The flat triangles' area is off by far more.
    CHECK(truth - grade_mesh(mesh).area > 10 * std::abs(a.area - truth));
  }
}

TEST_CASE("the outer surface drops a cavity and the island inside it, keeps two molecules side by side",
          "[quality][area]") {
  const SurfaceMesh big = meshed({{Eigen::Vector3d::Zero(), 50.0}});  // skin radius 5
  const SurfaceMesh hole = meshed({{Eigen::Vector3d::Zero(), 18.0}});  // 3
  const SurfaceMesh island = meshed({{Eigen::Vector3d::Zero(), 2.0}});  // 1
  SurfaceMesh shell;
  append(shell, big, false);
  append(shell, hole, true);     // the cavity's surface faces inward
  append(shell, island, false);  // an island inside the cavity
  SurfaceMesh beside = big;
  for (auto& v : beside.vertices) v.x() += 20;
  append(shell, beside, false);  // another molecule, outside the first
  const SurfaceComponents parts = surface_components(shell);
  REQUIRE(parts.enclosed_volume.size() == 4);
  const std::vector<char> enclosed = enclosed_components(shell, parts);
  CHECK(enclosed == std::vector<char>{0, 1, 1, 0});
  std::vector<int> kept_from;
  const SurfaceMesh outer = outer_surface(shell, &kept_from);
  CHECK(outer.vertices.size() == 2 * big.vertices.size());
  CHECK(outer.triangles.size() == 2 * big.triangles.size());
  CHECK(surface_components(outer).enclosed_volume.size() == 2);
  REQUIRE(kept_from.size() == outer.vertices.size());
  for (size_t v = 0; v < kept_from.size(); ++v) CHECK(outer.vertices[v] == shell.vertices[static_cast<size_t>(kept_from[v])]);
}
