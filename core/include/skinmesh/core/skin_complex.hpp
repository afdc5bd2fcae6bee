// The mixed complex of a ball set and the skin surface on it (docs/math.md section 3;
// H. Edelsbrunner, "Deformable smooth surface design", Discrete Comput. Geom. 21
// (1999) 87-115). Built once from the regular triangulation (CGAL, exact
// predicates, used only inside build); afterwards a plain value that answers
// point location, the skin function, projection and segment crossings, and is
// safe to query from many threads.
//
// Every query takes an optional cell hint and returns the cell it ended in, so
// that a mesh vertex can remember its mixed cell and be moved and re-projected
// with a short walk instead of a search.
#pragma once

#include "skinmesh/core/balls.hpp"
#include "skinmesh/core/skin_topology.hpp"

#include <Eigen/Core>

#include <array>
#include <optional>
#include <vector>

namespace skinmesh {

// One cell mu_X = (1-s) delta_X + s nu_X of the mixed complex.
struct MixedCell {
  int dim = 0;                             // dimension of delta_X: 0 vertex .. 3 tetrahedron
  std::array<int, 4> balls{{-1, -1, -1, -1}};  // X as indices into SkinComplex::balls(), ascending
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // z_X = aff(delta_X) ∩ aff(nu_X)
  double R2 = 0.0;                         // squared radius of the sphere orthogonal to X (Angstrom^2)
  Eigen::Matrix3d P = Eigen::Matrix3d::Zero();  // orthogonal projector onto the directions of aff(delta_X)
  // Rows 0..dim-1: x -> affine coordinates of x in delta_X relative to its first
  // vertex (barycentric coordinate i+1); unused rows are zero.
  Eigen::Matrix3d to_affine = Eigen::Matrix3d::Zero();
  bool degenerate = false;                 // delta_X affinely dependent (cospherical input)
};

struct SkinEval {
  int cell = -1;
  double value = 0.0;                      // F(x): negative inside the body, zero on the skin
  Eigen::Vector3d gradient = Eigen::Vector3d::Zero();  // grad F = 2 (x - Z l*), points outward
};

struct Projection {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  int cell = -1;
  int iterations = 0;
  bool converged = false;
  double distance = 0.0;                   // |F| / |grad F| at the result (first-order distance, Angstrom)
};

struct SegmentCrossing {
  double t = 0.0;                          // parameter on a + t (b - a), in [0, 1]
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  int cell = -1;
  bool entering = false;                   // F goes from + to - (the segment enters the body)
};

struct PrincipalCurvatures {
  double k1 = 0.0, k2 = 0.0;               // k1 >= k2, 1/Angstrom; positive where the body is convex
  Eigen::Vector3d d1 = Eigen::Vector3d::Zero(), d2 = Eigen::Vector3d::Zero();  // principal directions
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // unit outward normal
  double max_abs() const;
};

struct SkinComplexBuilder;

struct SkinComplexOptions {
  double shrink = 0.5;                     // s in (0,1)
  // Also count the skin's topology (SkinComplex::topology) from the
  // complex's own regular triangulation, as skin_topology counts it from
  // one of its own: done only when every ball has positive weight and the
  // triangulation is three-dimensional.
  bool count_topology = false;
};

class SkinComplex {
 public:
  double shrink() const { return shrink_; }
  const std::vector<Ball>& balls() const { return balls_; }
  const std::vector<MixedCell>& cells() const { return cells_; }
  const MixedCell& cell(int index) const { return cells_[static_cast<size_t>(index)]; }
  int triangulation_dimension() const { return dimension_; }  // of the regular triangulation: 0..3
  const std::vector<int>& hidden_balls() const { return hidden_; }  // redundant balls, no cell of their own
  // The skin's topology counted at the build (SkinComplexOptions::
  // count_topology); empty when not counted, and in a complex made by
  // with_balls (its balls moved, its alpha complex not recounted).
  const std::optional<SkinTopology>& topology() const { return topology_; }
  std::array<long, 4> cell_counts() const;                          // by dimension of delta_X
  long degenerate_cell_count() const;
  int vertex_cell(int ball) const { return vertex_cell_[static_cast<size_t>(ball)]; }  // -1 if hidden

  // The stable identity of a mixed cell is its ball tuple X (MixedCell::balls),
  // not its index: two builds of the same balls may number their cells
  // differently, and a mesh vertex keeps its cell across a rebuild by looking
  // its tuple up here. `balls` in any order, unused entries -1. Returns the
  // cell's index, or -1 when X is no simplex of this complex.
  int find_cell(std::array<int, 4> balls) const;

  // The ball a point of `cell` belongs to: of the cell's balls, the one of
  // least power distance to x (its region of the power diagram holds x).
  int owning_ball(const Eigen::Vector3d& x, int cell) const;

  // Faces of a cell (X minus one ball; the i-th drops balls[i]) and cofaces
  // (X plus one ball), each with the ball whose power bounds nu_X. Where a
  // coface is flat (MixedCell::degenerate), the cells beyond its flat cluster
  // follow, with their balls X lacks (see build_skin_complex.cpp).
  struct Coface {
    int ball;
    int cell;
    bool beyond = false;  // a cell past a flat coface, not adjacent: walks locate from it
    bool flat = false;    // the coface is flat: its ball bounds nothing (kept here to spare a cell lookup)
  };
  const int* faces_begin(int c) const { return faces_.data() + face_offset_[c]; }
  const int* faces_end(int c) const { return faces_.data() + face_offset_[c + 1]; }
  const Coface* cofaces_begin(int c) const { return cofaces_.data() + coface_offset_[c]; }
  const Coface* cofaces_end(int c) const { return cofaces_.data() + coface_offset_[c + 1]; }

  // The same complex with its balls moved: a frame of a morph (docs/math.md
  // section 4). Cells, faces and cofaces are kept; each cell's centre, size and
  // projector are recomputed from `balls` and the start grid is rebuilt, with
  // no regular triangulation. Valid when the regular triangulation of `balls`
  // has the same simplices, as B(t) of one set of live pairs has for every t in
  // (0,1). Throws ContractError when the number of balls differs or a ball is
  // not finite.
  SkinComplex with_balls(std::vector<Ball> balls) const;
  // with_balls, except that each listed cell takes the given centre and size
  // and keeps this complex's projector P instead of recomputing them from
  // its balls: a morph's overlay cell, whose directions are the same for
  // every t in (0,1), whose centre is affine and whose size is quadratic in
  // t (docs/math.md section 4). Near t = 0 or 1 such a cell is a sliver, and
  // its geometry recomputed from its balls loses digits.
  // Throws ContractError for a cell index out of range or cells not listed
  // in ascending order.
  struct KnownCell {
    int cell = -1;
    Eigen::Vector3d center = Eigen::Vector3d::Zero();
    double R2 = 0.0;
  };
  SkinComplex with_balls(std::vector<Ball> balls, const std::vector<KnownCell>& known) const;
  // The same, written over `out`, whose storage is reused: a morph moves its
  // complex every frame, and a fresh copy of its cells was a large part of
  // moving it. When `out` was itself moved from a
  // complex of the same build (the morph's two frames in turn), only the
  // balls and the geometry are written: cells, faces, cofaces and the tuple
  // lookup are the same. `out` must not be this complex.
  void with_balls(std::vector<Ball> balls, const std::vector<KnownCell>& known, SkinComplex& out) const;
  // Whether two complexes of one combinatorics have the same flat cells
  // (MixedCell::degenerate): a frame whose flat cells differ from the complex
  // it was moved from has left the combinatorics it was built for.
  bool same_flat_cells(const SkinComplex& other) const;

  // Q_X(x) = (1-s)|(I-P)(x-z)|^2 - s|P(x-z)|^2 + s(1-s)R2, equal to (1-s) F(x) on mu_X.
  double quadric(int cell, const Eigen::Vector3d& x) const;
  // The gradient of F by the cell's quadric, for x known to lie in mu_X (a
  // crossing intersect_segment found there): evaluate without locating x.
  Eigen::Vector3d gradient(int cell, const Eigen::Vector3d& x) const;
  // Largest violation of x in mu_X (Angstrom-scaled): <= 0 means inside.
  double membership_violation(int cell, const Eigen::Vector3d& x) const;

  // The mixed cell holding x. hint: a cell near x (e.g. the one a vertex was in).
  int locate(const Eigen::Vector3d& x, int hint = -1) const;
  SkinEval evaluate(const Eigen::Vector3d& x, int hint = -1) const;
  double value(const Eigen::Vector3d& x, int hint = -1) const { return evaluate(x, hint).value; }

  // The closest skin point to x (locally): onto the skin along the gradient line
  // (exact per cell, Newton iteration with cell switching as the fallback), then
  // tangential corrections, until |F|/|grad F| <= tolerance (Angstrom).
  Projection project(const Eigen::Vector3d& x, int hint = -1, double tolerance = 1e-12) const;

  // Every point where the segment a-b crosses the skin, ordered by t: exact per
  // mixed cell (the skin is a quadric there), walking the cells along the segment.
  std::vector<SegmentCrossing> intersect_segment(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                                 int hint = -1) const;
  // The same into `out` (cleared first), for callers that test many segments
  // with one buffer (the mesher: an allocation per segment was 3% of its time).
  void intersect_segment(const Eigen::Vector3d& a, const Eigen::Vector3d& b, int hint,
                         std::vector<SegmentCrossing>* out) const;

  // Principal curvatures of the skin patch of `cell` at x (x on or near the skin).
  PrincipalCurvatures curvature(const Eigen::Vector3d& x, int cell) const;
  // max(|k1|, |k2|) alone, what sizing asks for every triangle it judges:
  // the 2x2 shape operator's eigenvalues in closed form, no directions.
  double max_abs_curvature(const Eigen::Vector3d& x, int cell) const;

 private:
  friend struct SkinComplexBuilder;  // build_skin_complex.cpp
  int start_cell(const Eigen::Vector3d& x) const;
  Projection project_onto(const Eigen::Vector3d& x, int hint, double tolerance) const;
  std::optional<SegmentCrossing> nearest_crossing_on_rays(const Eigen::Vector3d& x, double reach, int hint) const;
  int locate_near(const Eigen::Vector3d& x, int from) const;  // breadth-first from a cell; -1 if not near
  int locate_by_search(const Eigen::Vector3d& x) const;
  // Ball ids ascending, unused entries (-1) last: the order of MixedCell::balls.
  static std::array<int, 4> ball_tuple(std::array<int, 4> ids);
  std::array<int, 3> grid_cell_of(const Eigen::Vector3d& x) const;  // clamped to the grid
  size_t grid_bucket(const std::array<int, 3>& g) const {
    return (static_cast<size_t>(g[2]) * static_cast<size_t>(grid_size_[1]) + static_cast<size_t>(g[1])) *
               static_cast<size_t>(grid_size_[0]) +
           static_cast<size_t>(g[0]);
  }

  double shrink_ = 0.5;
  int dimension_ = -1;
  std::optional<SkinTopology> topology_;
  std::vector<Ball> balls_;
  std::vector<MixedCell> cells_;
  std::vector<int> hidden_;
  std::vector<int> vertex_cell_;
  std::vector<int> face_offset_, faces_;
  std::vector<int> coface_offset_;
  std::vector<Coface> cofaces_;
  // find_cell's table: open addressing with linear probing, a power of
  // two at least 5/4 of the cells long, each slot a cell's ball tuple and
  // index (-1: empty). The key is kept in the slot: read from cells_, each
  // probe would miss the cache on a 200-byte cell. One array: a node per
  // cell cost milliseconds to allocate and to free with every complex.
  struct CellSlot {
    std::array<int, 4> balls;
    int cell;
  };
  void index_cells();
  size_t slot_of(const std::array<int, 4>& tuple) const;
  // find_cell of a tuple already in ball_tuple's order, from its slot_of.
  int find_cell_from(const std::array<int, 4>& tuple, size_t slot) const;
  std::vector<CellSlot> cell_table_;
  // Uniform grid over the centres of the non-hidden balls: a start for walks.
  Eigen::Vector3d grid_origin_ = Eigen::Vector3d::Zero();
  double grid_step_ = 1.0;
  std::array<int, 3> grid_size_{{1, 1, 1}};
  std::vector<int> grid_offset_, grid_balls_;
  // Which build the cells, faces and cofaces come from (copied with them):
  // with_balls onto a complex of the same build rewrites only the geometry.
  unsigned long combinatorics_ = 0;
};

// Throws ContractError on an empty or non-finite ball set or a shrink
// factor outside (0,1).
SkinComplex build_skin_complex(std::vector<Ball> balls, const SkinComplexOptions& options = {});

}  // namespace skinmesh
