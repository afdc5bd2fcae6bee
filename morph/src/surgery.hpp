// Repair of a transported frame by edits of the mesh itself (private to
// morph/): each failing triangle is mended by an edge split at a new skin
// point, Delaunay edge flips around it, a flip alone, or the contraction of
// a short edge, the "insert, remove, move or flip", with no
// Delaunay triangulation built. Every edit keeps the mesh closed, oriented
// and manifold and leaves its topology alone (a contraction is made only
// where the link condition holds); every triangle an edit makes is judged
// by the frame's criteria again. What the edits cannot mend is left
// failing for the local repair (local_repair.hpp) or the frame's remesh.
//
// Why: a local repair builds a Delaunay triangulation of its patch with
// its context, which costs about as much as remeshing the whole frame,
// however few triangles fail (docs/morph.md, "Mending by edits").
#pragma once

#include "repair_result.hpp"

#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/surface_mesh.hpp"
#include "skinmesh/mesher/skin_mesher.hpp"
#include "skinmesh/morph/repair_policy.hpp"

#include <functional>
#include <utility>
#include <vector>

namespace skinmesh::detail {

// Thinning contractions refused, by the vertex ids of the edge's ends
// (smaller first): the edge's length then and the frames since. Kept by the
// caller from frame to frame. Every short edge near a change looks itself
// up in every frame, and each frame's memo is made anew: one array of
// entries with an open-addressing table of their keys, no sort and no
// allocation per edge.
class RefusedEdges {
 public:
  using Key = std::pair<long, long>;
  using Entry = std::pair<Key, std::pair<double, int>>;  // the ids; the length (Angstrom) and the frames since

  bool empty() const { return entries_.empty(); }
  size_t size() const { return entries_.size(); }
  // Entries in the order added; their keys are not to be changed.
  std::vector<Entry>::iterator begin() { return entries_.begin(); }
  std::vector<Entry>::iterator end() { return entries_.end(); }
  std::vector<Entry>::const_iterator begin() const { return entries_.begin(); }
  std::vector<Entry>::const_iterator end() const { return entries_.end(); }
  // The entry of `key`, or end().
  std::vector<Entry>::const_iterator find(const Key& key) const;
  // A key already held keeps its first entry.
  void add(const Key& key, double length, int frames);
  void reserve(size_t n);
  void swap(RefusedEdges& other) noexcept {
    entries_.swap(other.entries_);
    slots_.swap(other.slots_);
  }

 private:
  size_t slot_of(const Key& key) const;  // the key's slot, or the empty one it would take
  void grow();
  std::vector<Entry> entries_;
  std::vector<int> slots_;  // an entry's index, -1 empty; a power of two, at most half full
};

// `failing`: per triangle of `mesh`, non-zero where it fails `accept` on the
// skin of `complex`; the others are taken to pass. With `ids` (per vertex of
// `mesh`, stable from frame to frame) and `refused`, thinning skips the
// edges refused before (EditPolicy::retry_shrink) and `refused` becomes
// this frame's. With `still` (per vertex of `mesh`: 1 where the vertex and
// the skin around it moved, since the frame before was thinned, only as one
// rigid body), thinning tries only edges with an end whose triangles have a
// corner that is not still or that an edit of this frame touched. The
// others were tried when the frame before was thinned (or made after it by
// a local patch, whose refinement spaced them) and would be judged again on
// a congruent fan and skin.
RepairResult mend_by_edits(const SkinComplex& complex, SurfaceMesh mesh, const std::vector<char>& failing,
                      const MeshingOptions& accept, const EditPolicy& options = {},
                      const std::vector<long>* ids = nullptr, RefusedEdges* refused = nullptr,
                      const std::vector<char>* still = nullptr);

}  // namespace skinmesh::detail
