// Two engines' frames compared field by field (Catch2 checks): the same
// mesh, cells, ids and verdict counts. For tests that make one frame two
// ways that must agree (a complex moved or built ahead, or not).
#pragma once

#include "skinmesh/morph/morph.hpp"

#include <catch2/catch.hpp>

namespace skinmesh::test {

inline void check_same_frames(const MorphFrame& a, const MorphFrame& b) {
  REQUIRE(a.mesh.vertices.size() == b.mesh.vertices.size());
  CHECK(a.mesh.vertices == b.mesh.vertices);
  CHECK(a.mesh.triangles == b.mesh.triangles);
  CHECK(a.mesh.cells == b.mesh.cells);
  CHECK(a.ids == b.ids);
  CHECK(a.stats.bad_triangles == b.stats.bad_triangles);
  CHECK(a.stats.remeshed == b.stats.remeshed);
}

}  // namespace skinmesh::test
