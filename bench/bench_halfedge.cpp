// The morph's flat mesh with its edge index (morph/src/surgery.cpp) against
// OpenMesh's half-edge mesh (meshing/openmesh/) as the structure a frame's
// local edits work on. Everything else in a frame (transport, judging,
// relaxation, the check, the output) runs over flat arrays in parallel, so
// a half-edge mesh would be built from the frame and read back every frame.
// Per molecule, on the mesher's mesh, each in a forked child (time and peak
// memory; the best of --repeat runs):
//   flat      the edits' own structure with nothing to mend: the edge index
//             built over every triangle and the mesh compacted back
//             (detail::mend_by_edits with no failing triangle and no thinning);
//   openmesh  the frame into OpenMesh and back (to_openmesh, from_openmesh);
//   om edits  the same, plus --edits edge flips, midpoint splits and
//             collapses spread over the mesh (a third each, each checked
//             with is_flip_ok / is_collapse_ok), then garbage collection.
// Prints JSON lines, then a markdown table.
//
//   bench_halfedge [--repeat K] [--edits N] [FILE...]   (default: data/2k39_3models.pdb, 1ubi, 3mht)
#include "forked.hpp"
#include "skinmesh/core/balls.hpp"
#include "skinmesh/core/molecule.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/stopwatch.hpp"
#include "skinmesh/mesher/skin_mesher.hpp"
#include "skinmesh/openmesh/openmesh_mesh.hpp"

#include "surgery.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using namespace skinmesh;

namespace {

struct Timed {
  double seconds = 0;
  long triangles = 0;
  long edits = 0;
};

Timed flat_structure(const SkinComplex& complex, const SurfaceMesh& mesh) {
  const auto start = Clock::now();
  const std::vector<char> none(mesh.triangles.size(), 0);
  EditPolicy structure_only;
  structure_only.thin_below = 0;  // no thinning: only the index and the compaction
  const detail::RepairResult r = detail::mend_by_edits(complex, mesh, none, MeshingOptions{}, structure_only);
  return {seconds_since(start), static_cast<long>(r.mesh.triangles.size()), 0};
}

// `edits` operations spread evenly over the edges: flips, splits at the
// midpoint, collapses, in turn; an edge whose operation OpenMesh refuses is skipped.
long edit_openmesh(SkinTriMesh& om, long edits) {
  const long edges = static_cast<long>(om.n_edges());
  const long stride = std::max(1L, edges / std::max(1L, edits));
  long done = 0;
  for (long k = 0; k < edits && k * stride < edges; ++k) {
    const SkinTriMesh::EdgeHandle e(static_cast<int>(k * stride));
    if (om.status(e).deleted()) continue;
    if (k % 3 == 0 && om.is_flip_ok(e)) {
      om.flip(e);
      ++done;
    } else if (k % 3 == 1) {
      const auto h = om.halfedge_handle(e, 0);
      const auto mid = 0.5 * (om.point(om.from_vertex_handle(h)) + om.point(om.to_vertex_handle(h)));
      om.split(e, om.add_vertex(mid));
      ++done;
    } else if (k % 3 == 2) {
      const auto h = om.halfedge_handle(e, 0);
      if (om.is_collapse_ok(h)) {
        om.collapse(h);
        ++done;
      }
    }
  }
  om.garbage_collection();
  return done;
}

Timed openmesh_structure(const SurfaceMesh& mesh, long edits) {
  const auto start = Clock::now();
  SkinTriMesh om = to_openmesh(mesh);
  const long done = edits > 0 ? edit_openmesh(om, edits) : 0;
  const SurfaceMesh back = from_openmesh(om);
  return {seconds_since(start), static_cast<long>(back.triangles.size()), done};
}

struct Row {
  std::string file, column, status;
  long triangles = 0, edits = 0;
  double ms = 0, peak_mb = 0;
};

Row best_of(const std::string& file, const std::string& column, int repeat, const std::function<Timed()>& task) {
  Row row{file, column, "ok"};
  row.ms = 1e300;
  for (int k = 0; k < repeat; ++k) {
    const auto run = bench::run_forked<Timed>(600, task);
    if (run.status != "ok") {
      row.status = run.status;
      return row;
    }
    row.ms = std::min(row.ms, 1e3 * run.result.seconds);
    row.triangles = run.result.triangles;
    row.edits = run.result.edits;
    row.peak_mb = std::max(row.peak_mb, run.peak_mb);
  }
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  int repeat = 3;
  long edits = 300;
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--repeat" && i + 1 < argc) repeat = std::atoi(argv[++i]);
    else if (a == "--edits" && i + 1 < argc) edits = std::atol(argv[++i]);
    else if (!a.empty() && a[0] == '-') {
      std::fprintf(stderr, "usage: bench_halfedge [--repeat K] [--edits N] [FILE...]\n");
      return 2;
    } else files.push_back(a);
  }
  if (files.empty())
    for (const char* f : {"2k39_3models.pdb", "1ubi.pdb", "3mht.pdb"}) files.push_back(std::string(SKINMESH_DATA_DIR) + "/" + f);
  std::vector<Row> rows;
  for (const std::string& file : files) {
    const std::vector<Ball> balls = balls_from_molecule(read_molecule(file), 0.5);
    const SkinComplex complex = build_skin_complex(balls, {0.5});
    const SkinMeshResult made = mesh_skin(complex);
    if (made.status != MeshingStatus::ok) {
      std::fprintf(stderr, "%s: the mesher failed: %s\n", file.c_str(), made.message.c_str());
      return 1;
    }
    const std::string name = file.substr(file.find_last_of('/') + 1);
    rows.push_back(best_of(name, "flat", repeat, [&] { return flat_structure(complex, made.mesh); }));
    rows.push_back(best_of(name, "openmesh", repeat, [&] { return openmesh_structure(made.mesh, 0); }));
    rows.push_back(best_of(name, "om edits", repeat, [&] { return openmesh_structure(made.mesh, edits); }));
    for (size_t k = rows.size() - 3; k < rows.size(); ++k) {
      const Row& r = rows[k];
      std::printf("{\"molecule\": \"%s\", \"column\": \"%s\", \"status\": \"%s\", \"triangles\": %ld, \"edits\": %ld, "
                  "\"ms\": %.3f, \"peak_mb\": %.1f}\n",
                  r.file.c_str(), r.column.c_str(), r.status.c_str(), r.triangles, r.edits, r.ms, r.peak_mb);
    }
    std::fflush(stdout);
  }
  std::printf("\n| molecule | triangles | flat ms | openmesh ms | om edits ms (edits) | openmesh / flat | peak MB flat, openmesh |\n"
              "|---|---|---|---|---|---|---|\n");
  for (size_t k = 0; k + 2 < rows.size(); k += 3) {
    const Row &f = rows[k], &o = rows[k + 1], &e = rows[k + 2];
    std::printf("| %s | %ld | %.1f | %.1f | %.1f (%ld) | %.1f | %.0f, %.0f |\n", f.file.c_str(), f.triangles, f.ms, o.ms, e.ms,
                e.edits, o.ms / f.ms, f.peak_mb, o.peak_mb);
  }
  return 0;
}
