// The morph's repair stages on their own, through their private headers
// (morph/src/surgery.hpp, local_repair.hpp): the edits' thinning, where an
// edge whose contraction was refused is not tried again in the next frame
// unless it has shrunk or its refusal has aged; and the local repair, which
// leaves a patch that is nearly the whole frame to the whole-frame remesh.
#include <catch2/catch.hpp>

#include "test_support.hpp"

#include "skinmesh/mesher/skin_mesher.hpp"
#include "local_repair.hpp"
#include "surgery.hpp"

#include <numeric>

using namespace skinmesh;

namespace {

// pept's skin meshed at the mesher's 30 degrees, to be judged at the frames'
// 20: the refinement leaves edges under half the target length, most of
// which cannot go without a triangle failing.
struct PeptFrame {
  SkinComplex complex;
  SurfaceMesh mesh;
  MeshingOptions accept;
};

PeptFrame pept_frame() {
  PeptFrame f{build_skin_complex(test::centred_model(test::data_file("pept.pdb"), 1)), {}, {}};
  SkinMeshResult made = mesh_skin(f.complex, MeshingOptions{});
  REQUIRE(made.status == MeshingStatus::ok);
  f.mesh = std::move(made.mesh);
  f.accept.min_angle = 20;
  return f;
}

}  // namespace

TEST_CASE("edits: thinning skips an edge refused in the frame before until it shrinks or its refusal ages",
          "[morph]") {
  const PeptFrame f = pept_frame();
  const SkinComplex& complex = f.complex;
  const MeshingOptions& accept = f.accept;
  std::vector<long> ids(f.mesh.vertices.size());
  std::iota(ids.begin(), ids.end(), 100);
  const std::vector<char> none_failing(f.mesh.triangles.size(), 0);
  const EditPolicy options;
  auto thin = [&](detail::RefusedEdges& refused) {
    return detail::mend_by_edits(complex, f.mesh, none_failing, accept, options, &ids, &refused);
  };

  detail::RefusedEdges refused;
  const detail::RepairResult first = thin(refused);
  REQUIRE(first.thin_tried > 0);
  REQUIRE(!refused.empty());
  const long refused_first = static_cast<long>(refused.size());
  CHECK(refused_first < first.thin_tried);  // some were contracted

  SECTION("the same frame again: none of the refused edges is tried") {
    const detail::RefusedEdges before = refused;
    const detail::RepairResult second = thin(refused);
    // An edge is skipped even where a contraction beside it would have let
    // it go later in the pass; so at most the others are tried.
    CHECK(second.thin_tried <= first.thin_tried - refused_first);
    CHECK(second.counts.contractions > 0);
    for (const auto& [edge, memo] : before) {
      const auto carried = refused.find(edge);
      REQUIRE(carried != refused.end());
      CHECK(carried->second.first == memo.first);
      CHECK(carried->second.second == 1);  // a frame older
    }
  }
  SECTION("edges shorter than when refused are tried again") {
    for (auto& [edge, memo] : refused) memo.first /= 1 - 2 * options.retry_shrink;
    CHECK(thin(refused).thin_tried == first.thin_tried);
  }
  SECTION("a refusal as old as retry_after_frames is tried again") {
    for (auto& [edge, memo] : refused) memo.second = options.retry_after_frames - 1;
    CHECK(thin(refused).thin_tried == first.thin_tried);
  }
  SECTION("without ids every short edge is tried") {
    const detail::RepairResult plain = detail::mend_by_edits(complex, f.mesh, none_failing, accept, options);
    CHECK(plain.thin_tried == first.thin_tried);
  }
}

TEST_CASE("local repair: a patch that would take nearly every vertex is left to the whole-frame remesh", "[morph]") {
  const PeptFrame f = pept_frame();
  const std::vector<char> all_failing(f.mesh.triangles.size(), 1);  // the patch is the whole mesh
  detail::LocalRepairOptions options;
  auto repair = [&] { return detail::repair_locally(f.complex, f.mesh, all_failing, MeshingOptions{}, f.accept, options); };
  CHECK_FALSE(repair().ok);
  options.policy.max_sample_share = 2;  // no bound: the same patch is meshed
  const detail::RepairResult meshed = repair();
  CHECK(meshed.ok);
  CHECK(meshed.counts.patch_triangles == static_cast<long>(f.mesh.triangles.size()));
}
