// Construction of the mixed complex from CGAL's regular triangulation (exact
// predicates). CGAL stays in this file: the complex it produces is plain data.
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/error.hpp"

#include "dual_complex.hpp"
#include "regular_triangulation.hpp"

#include <Eigen/Dense>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <tuple>
#include <cmath>
#include <string>
#include <limits>
#include <numeric>

namespace skinmesh {
namespace {

using SkinComplexCoface = SkinComplex::Coface;

using K = detail::RtKernel;
using Regular = detail::RegularTriangulation<int>;

// Whether a Gram matrix's smallest eigenvalue is surely above 1e-14 times its
// largest (the flat test below) without solving for them: the smallest is at
// least det / largest^(d-1) and the largest at most the trace, so
// det > 1e-10 trace^d leaves four orders of magnitude for rounding. Nearly
// every cell of a morph's frames passes, which spares moving the complex the
// eigenvalues of nearly every cell.
template <class Mat>
bool clearly_not_flat(const Mat& g) {
  const double trace = g.trace();
  switch (g.rows()) {
    case 1: return g(0, 0) > 1e-10 * trace;
    case 2: return g(0, 0) * g(1, 1) - g(0, 1) * g(1, 0) > 1e-10 * trace * trace;
    case 3:
      return g(0, 0) * (g(1, 1) * g(2, 2) - g(1, 2) * g(2, 1)) - g(0, 1) * (g(1, 0) * g(2, 2) - g(1, 2) * g(2, 0)) +
                 g(0, 2) * (g(1, 0) * g(2, 1) - g(1, 1) * g(2, 0)) >
             1e-10 * trace * trace * trace;
    default: return false;
  }
}

// The geometry of a simplex that is not flat from E's columns, the edges
// from the first ball: 2 <z - z_0, e_j> = rhs_j with z - z_0 = E a. Solved
// through the normal equations (E^T E) a = rhs / 2, the error grows with the
// square of E's condition: enough, for an overlay tetrahedron with a nearly
// flat side, to put a morph frame's vertex off the skin by more than a
// frame is held to (bench/morph_precision). Here it grows with the
// condition itself: with E = QR (thin), R^T (R a) = rhs / 2,
// so z - z_0 = Q R^-T rhs / 2, P = Q Q^T and the affine coordinates are
// R^-1 Q^T. A tetrahedron's E is square: z - z_0 = E^-T rhs / 2, P = I and
// the affine coordinates E^-1 (by LU: Householder QR made frames slower).
void set_geometry(MixedCell& cell, const Ball& b0, const Eigen::Vector3d& offset) {
  cell.center = b0.center + offset;
  cell.R2 = offset.squaredNorm() - b0.weight;
}

void solve_not_flat(MixedCell& cell, const Ball& b0, const Eigen::Matrix3d& E, const Eigen::Vector3d& rhs) {
  const Eigen::Matrix3d inverse = E.partialPivLu().inverse();
  set_geometry(cell, b0, 0.5 * (inverse.transpose() * rhs));
  cell.P.setIdentity();
  cell.to_affine = inverse;
}

void solve_not_flat(MixedCell& cell, const Ball& b0, const Eigen::Matrix<double, 3, 2>& E, const Eigen::Vector2d& rhs) {
  // Thin QR by Gram-Schmidt: q0 along e0, q1 the rest of e1.
  const double r00 = E.col(0).norm();
  const Eigen::Vector3d q0 = E.col(0) / r00;
  const double r01 = q0.dot(E.col(1));
  const Eigen::Vector3d rest = E.col(1) - r01 * q0;
  const double r11 = rest.norm();
  const Eigen::Vector3d q1 = rest / r11;
  // R^T y = rhs / 2, forward.
  const double y0 = 0.5 * rhs[0] / r00;
  const double y1 = (0.5 * rhs[1] - r01 * y0) / r11;
  set_geometry(cell, b0, y0 * q0 + y1 * q1);
  cell.P = q0 * q0.transpose() + q1 * q1.transpose();
  // R^-1 Q^T, backward.
  cell.to_affine.row(1) = q1.transpose() / r11;
  cell.to_affine.row(0) = (q0.transpose() - r01 * cell.to_affine.row(1)) / r00;
}

void solve_not_flat(MixedCell& cell, const Ball& b0, const Eigen::Matrix<double, 3, 1>& E,
                    const Eigen::Matrix<double, 1, 1>& rhs) {
  const double length2 = E.squaredNorm();
  set_geometry(cell, b0, (0.5 * rhs[0] / length2) * E);
  cell.P = E * E.transpose() / length2;
  cell.to_affine.row(0) = E.transpose() / length2;
}

// Centre z_X (equal power to every ball of X within aff(delta_X)), size R2 and
// the projector onto the directions of aff(delta_X) (docs/math.md section 3),
// for a simplex of D+1 balls. Fixed-size matrices: a morph moves its complex
// every frame, and with matrices of dynamic size (at most 3) this was a
// large share of a frame.
template <int D>
void simplex_geometry(MixedCell& cell, const std::vector<Ball>& balls) {
  using Mat = Eigen::Matrix<double, D, D>;
  using Vec = Eigen::Matrix<double, D, 1>;
  const Ball& b0 = balls[cell.balls[0]];
  Eigen::Matrix<double, 3, D> E;
  Vec rhs;
  for (int j = 0; j < D; ++j) {
    const Ball& bj = balls[cell.balls[j + 1]];
    E.col(j) = bj.center - b0.center;
    // |z - z_j|^2 - w_j = |z - z_0|^2 - w_0  <=>  2 <z - z_0, e_j> = |e_j|^2 - w_j + w_0
    rhs[j] = E.col(j).squaredNorm() - bj.weight + b0.weight;
  }
  const Mat gram = E.transpose() * E;
  if (clearly_not_flat(gram)) return solve_not_flat(cell, b0, E, rhs);
  const Eigen::SelfAdjointEigenSolver<Mat> eig(gram);
  const Vec values = eig.eigenvalues();
  const double largest = values.maxCoeff();
  if (values.minCoeff() > 1e-14 * largest) return solve_not_flat(cell, b0, E, rhs);
  // Affinely dependent vertices (a flat simplex from cospherical input):
  // pseudo-inverse on the span that exists.
  cell.degenerate = true;
  Vec inv = values;
  for (int i = 0; i < D; ++i) inv[i] = inv[i] > 1e-14 * largest ? 1.0 / inv[i] : 0.0;
  const Mat gram_inv = eig.eigenvectors() * inv.asDiagonal() * eig.eigenvectors().transpose();
  const Eigen::Vector3d offset = E * (0.5 * gram_inv * rhs);
  cell.center = b0.center + offset;
  cell.R2 = offset.squaredNorm() - b0.weight;
  cell.P = E * gram_inv * E.transpose();
  const Eigen::Matrix<double, D, 3> affine = gram_inv * E.transpose();
  for (int j = 0; j < D; ++j) cell.to_affine.row(j) = affine.row(j);
}

void compute_cell_geometry(MixedCell& cell, const std::vector<Ball>& balls) {
  switch (cell.dim) {
    case 0: {
      const Ball& b0 = balls[cell.balls[0]];
      cell.center = b0.center;
      cell.R2 = -b0.weight;
      return;
    }
    case 1: return simplex_geometry<1>(cell, balls);
    case 2: return simplex_geometry<2>(cell, balls);
    default: return simplex_geometry<3>(cell, balls);
  }
}

// A cell X whose coface Y is flat (see compute_cell_geometry) would take
// from Y's balls no bound on its Voronoi part nu_X: they are co-orthogonal
// with X's along it. The true bound comes from the cells beyond the flat
// cluster (the flat cells of Y's dimension joined through shared faces):
// every ball of such a cell T outside the cluster bounds nu_X, and a walk
// leaving X that way goes on from T. Any ball gives a valid bound (nu_X is where X's
// balls have the least power of all), so extra ones are safe.
void add_constraints_beyond_flat_cofaces(std::vector<MixedCell>& cells, const std::vector<int>& faces,
                                         const std::vector<int>& face_offset, std::vector<SkinComplexCoface>& cofaces,
                                         std::vector<int>& coface_offset) {
  const size_t m = cells.size();
  std::vector<std::vector<SkinComplexCoface>> extra(m);
  std::vector<char> in_cluster(m, 0);
  for (size_t y = 0; y < m; ++y) {
    if (!cells[y].degenerate || in_cluster[y]) continue;
    std::vector<int> cluster{static_cast<int>(y)}, beyond;
    in_cluster[y] = 1;
    for (size_t k = 0; k < cluster.size(); ++k) {
      const int member = cluster[k];
      for (int f = face_offset[static_cast<size_t>(member)]; f < face_offset[static_cast<size_t>(member) + 1]; ++f) {
        const int face = faces[static_cast<size_t>(f)];
        for (int g = coface_offset[static_cast<size_t>(face)]; g < coface_offset[static_cast<size_t>(face) + 1]; ++g) {
          const int other = cofaces[static_cast<size_t>(g)].cell;
          if (cells[static_cast<size_t>(other)].degenerate) {
            if (!in_cluster[static_cast<size_t>(other)]) {
              in_cluster[static_cast<size_t>(other)] = 1;
              cluster.push_back(other);
            }
          } else {
            beyond.push_back(other);
          }
        }
      }
    }
    // The cluster's own balls are co-orthogonal with X's along aff(nu_X):
    // their bounds are void, so only the other balls of the cells beyond count.
    std::vector<int> cluster_balls;
    for (const int member : cluster)
      for (int j = 0; j <= cells[static_cast<size_t>(member)].dim; ++j)
        cluster_balls.push_back(cells[static_cast<size_t>(member)].balls[static_cast<size_t>(j)]);
    std::sort(cluster_balls.begin(), cluster_balls.end());
    for (const int member : cluster)
      for (int f = face_offset[static_cast<size_t>(member)]; f < face_offset[static_cast<size_t>(member) + 1]; ++f) {
        const int x = faces[static_cast<size_t>(f)];
        if (cells[static_cast<size_t>(x)].degenerate) continue;
        for (const int t : beyond)
          for (int j = 0; j <= cells[static_cast<size_t>(t)].dim; ++j) {
            const int ball = cells[static_cast<size_t>(t)].balls[static_cast<size_t>(j)];
            if (std::binary_search(cluster_balls.begin(), cluster_balls.end(), ball)) continue;
            SkinComplexCoface beyond_flat;
            beyond_flat.ball = ball;
            beyond_flat.cell = t;
            beyond_flat.beyond = true;
            extra[static_cast<size_t>(x)].push_back(beyond_flat);
          }
      }
  }
  std::vector<SkinComplexCoface> merged;
  std::vector<int> offset(m + 1, 0);
  for (SkinComplexCoface& c : cofaces) c.flat = cells[static_cast<size_t>(c.cell)].degenerate;
  for (size_t i = 0; i < m; ++i) {
    merged.insert(merged.end(), cofaces.begin() + coface_offset[i], cofaces.begin() + coface_offset[i + 1]);
    merged.insert(merged.end(), extra[i].begin(), extra[i].end());
    offset[i + 1] = static_cast<int>(merged.size());
  }
  cofaces = std::move(merged);
  coface_offset = std::move(offset);
}

void check_finite(const std::vector<Ball>& balls) {
  for (const Ball& b : balls)
    if (!b.center.allFinite() || !std::isfinite(b.weight)) contract_error("ball with a non-finite centre or weight");
}

void check_input(const std::vector<Ball>& balls, const SkinComplexOptions& options) {
  if (!(options.shrink > 0.0 && options.shrink < 1.0))
    contract_error("shrink factor must lie in (0,1), got " + std::to_string(options.shrink));
  if (balls.empty()) contract_error("cannot build a skin complex of no balls");
  check_finite(balls);
}

}  // namespace

// Builds the parts of a SkinComplex in order; a friend of it.
struct SkinComplexBuilder {
  // A simplex of the regular triangulation: its dimension and ball tuple
  // (ascending ids, unused entries -1).
  struct Key {
    int dim;
    std::array<int, 4> balls;
  };

  // `keys` in the order of (dim, balls), ball ids below n: counted into
  // buckets by dimension and first ball, then each bucket (the simplices
  // of one ball with higher ones, a few dozen) sorted alone, in cache,
  // instead of one sort of every key.
  static void sort_by_dimension_and_tuple(std::vector<Key>& keys, int n) {
    const auto bucket = [n](const Key& k) {
      return static_cast<size_t>(k.dim) * static_cast<size_t>(n) + static_cast<size_t>(k.balls[0]);
    };
    std::vector<int> first(4 * static_cast<size_t>(n) + 1, 0);
    for (const Key& k : keys) ++first[bucket(k) + 1];
    std::partial_sum(first.begin(), first.end(), first.begin());
    std::vector<Key> sorted(keys.size());
    std::vector<int> fill(first.begin(), first.end() - 1);
    for (const Key& k : keys) sorted[static_cast<size_t>(fill[bucket(k)]++)] = k;
    for (size_t b = 0; b + 1 < first.size(); ++b)
      std::sort(sorted.begin() + first[b], sorted.begin() + first[b + 1],
                [](const Key& x, const Key& y) { return x.balls < y.balls; });
    keys.swap(sorted);
  }

  // Simplices of every dimension of the regular triangulation, as sorted ball
  // tuples; balls without a vertex are hidden.
  static void add_simplices(const Regular& rt, SkinComplex& sc) {
    const int n = static_cast<int>(sc.balls_.size());
    // Sorted as small keys, then made cells in one allocation: sorting and
    // growing the cells themselves (about 200 bytes each) was most of the
    // complex's construction on 3mht (90,519 cells).
    std::vector<Key> keys;
    keys.reserve(static_cast<size_t>(rt.number_of_vertices()) + 7 * rt.number_of_cells());
    auto add = [&](std::array<int, 4> ids, int count) {  // unused entries of ids are -1
      keys.push_back({count - 1, SkinComplex::ball_tuple(ids)});
    };
    for (auto v = rt.finite_vertices_begin(); v != rt.finite_vertices_end(); ++v) add({v->info(), -1, -1, -1}, 1);
    if (rt.dimension() >= 1)
      for (auto e = rt.finite_edges_begin(); e != rt.finite_edges_end(); ++e)
        add({e->first->vertex(e->second)->info(), e->first->vertex(e->third)->info(), -1, -1}, 2);
    if (rt.dimension() >= 2)
      for (auto f = rt.finite_facets_begin(); f != rt.finite_facets_end(); ++f) {
        std::array<int, 4> ids{{-1, -1, -1, -1}};
        for (int k = 0; k < 3; ++k) ids[static_cast<size_t>(k)] = f->first->vertex((f->second + 1 + k) & 3)->info();
        add(ids, 3);
      }
    if (rt.dimension() == 3)
      for (auto c = rt.finite_cells_begin(); c != rt.finite_cells_end(); ++c)
        add({c->vertex(0)->info(), c->vertex(1)->info(), c->vertex(2)->info(), c->vertex(3)->info()}, 4);
    // Numbered by dimension and ball tuple, not in CGAL's order: its edge
    // and facet iterators report each simplex from the cell with the
    // smaller handle, i.e. by memory address, and the numbering then
    // changed with the heap's layout (the same morph gave a different cell,
    // and one vertex an ulp elsewhere, when its output path was one
    // character longer). Walks start from and step through these numbers.
    sort_by_dimension_and_tuple(keys, n);
    std::vector<MixedCell>& cells = sc.cells_;
    cells.resize(keys.size());
    for (size_t i = 0; i < keys.size(); ++i) {
      cells[i].dim = keys[i].dim;
      cells[i].balls = keys[i].balls;
    }
    sc.vertex_cell_.assign(static_cast<size_t>(n), -1);
    for (size_t i = 0; i < cells.size() && cells[i].dim == 0; ++i)
      sc.vertex_cell_[static_cast<size_t>(cells[i].balls[0])] = static_cast<int>(i);
    for (int i = 0; i < n; ++i)
      if (sc.vertex_cell_[static_cast<size_t>(i)] < 0) sc.hidden_.push_back(i);
    // The tuple -> cell lookup (find_cell).
    sc.index_cells();
  }

  // The tuple of cell c's face without its ball at `drop`: still ascending.
  static std::array<int, 4> face_tuple(const MixedCell& c, int drop) {
    std::array<int, 4> ids{{-1, -1, -1, -1}};
    int k = 0;
    for (int j = 0; j <= c.dim; ++j)
      if (j != drop) ids[static_cast<size_t>(k++)] = c.balls[static_cast<size_t>(j)];
    return ids;
  }

  // Faces (drop one ball) and cofaces (add one ball) of every cell, in CSR form.
  static void link_faces(SkinComplex& sc) {
    const std::vector<MixedCell>& cells = sc.cells_;
    const size_t m = cells.size();
    sc.face_offset_.assign(m + 1, 0);
    std::vector<int> coface_count(m, 0);
    for (size_t i = 0; i < m; ++i) sc.face_offset_[i + 1] = sc.face_offset_[i] + (cells[i].dim > 0 ? cells[i].dim + 1 : 0);
    sc.faces_.assign(static_cast<size_t>(sc.face_offset_[m]), -1);
    // A face's slot in find_cell's table is found and fetched kAhead cells
    // before it is read: the table is megabytes long, and a lookup in it
    // misses the cache but for the fetch.
    constexpr size_t kAhead = 16;
    std::array<std::array<size_t, 4>, kAhead> slots{};
    const auto fetch = [&](size_t i) {
      const MixedCell& c = cells[i];
      for (int drop = 0; drop < (c.dim > 0 ? c.dim + 1 : 0); ++drop) {
        const size_t slot = sc.slot_of(face_tuple(c, drop));
        slots[i % kAhead][static_cast<size_t>(drop)] = slot;
        __builtin_prefetch(&sc.cell_table_[slot]);
      }
    };
    for (size_t i = 0; i < std::min(m, kAhead); ++i) fetch(i);
    for (size_t i = 0; i < m; ++i) {
      const MixedCell& c = cells[i];
      for (int drop = 0; drop < (c.dim > 0 ? c.dim + 1 : 0); ++drop) {
        const int face = sc.find_cell_from(face_tuple(c, drop), slots[i % kAhead][static_cast<size_t>(drop)]);
        sc.faces_[static_cast<size_t>(sc.face_offset_[i] + drop)] = face;
        ++coface_count[static_cast<size_t>(face)];
      }
      if (i + kAhead < m) fetch(i + kAhead);
    }
    sc.coface_offset_.assign(m + 1, 0);
    for (size_t i = 0; i < m; ++i) sc.coface_offset_[i + 1] = sc.coface_offset_[i] + coface_count[i];
    sc.cofaces_.resize(static_cast<size_t>(sc.coface_offset_[m]));
    std::vector<int> fill(sc.coface_offset_.begin(), sc.coface_offset_.end() - 1);
    for (size_t i = 0; i < m; ++i) {
      const MixedCell& c = cells[i];
      for (int drop = 0; drop < (c.dim > 0 ? c.dim + 1 : 0); ++drop) {
        const int face = sc.faces_[static_cast<size_t>(sc.face_offset_[i] + drop)];
        SkinComplexCoface coface;
        coface.ball = c.balls[static_cast<size_t>(drop)];
        coface.cell = static_cast<int>(i);
        sc.cofaces_[static_cast<size_t>(fill[static_cast<size_t>(face)]++)] = coface;
      }
    }
  }

  // Every cell's geometry from the balls, each cell on its own, on every
  // core: a morph moves the complex every frame, and serially this was a
  // tenth of a frame. Every field of the geometry is written, so a cell's
  // earlier frame leaves nothing behind.
  static void compute_geometry(SkinComplex& sc) {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, sc.cells_.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t c = r.begin(); c != r.end(); ++c) {
        sc.cells_[c].degenerate = false;
        compute_cell_geometry(sc.cells_[c], sc.balls_);
      }
    });
  }

  // A uniform grid over the centres of the non-hidden balls: walks start from
  // the vertex cell of the ball of least power in the nearest buckets.
  static void build_start_grid(SkinComplex& sc) {
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::max());
    Eigen::Vector3d hi = -lo;
    std::vector<int> live;
    for (int i = 0; i < static_cast<int>(sc.balls_.size()); ++i)
      if (sc.vertex_cell_[static_cast<size_t>(i)] >= 0) {
        live.push_back(i);
        lo = lo.cwiseMin(sc.balls_[static_cast<size_t>(i)].center);
        hi = hi.cwiseMax(sc.balls_[static_cast<size_t>(i)].center);
      }
    const Eigen::Vector3d extent = (hi - lo).cwiseMax(1e-9);
    const double volume = extent.prod();
    sc.grid_step_ = std::max({2.0, std::cbrt(volume / static_cast<double>(live.size()) * 2.0), extent.maxCoeff() / 256.0});
    sc.grid_origin_ = lo;
    for (int k = 0; k < 3; ++k)
      sc.grid_size_[static_cast<size_t>(k)] = std::max(1, static_cast<int>(std::floor(extent[k] / sc.grid_step_)) + 1);
    const size_t buckets = static_cast<size_t>(sc.grid_size_[0]) * sc.grid_size_[1] * sc.grid_size_[2];
    sc.grid_offset_.assign(buckets + 1, 0);
    auto bucket_of = [&](int ball) { return sc.grid_bucket(sc.grid_cell_of(sc.balls_[static_cast<size_t>(ball)].center)); };
    for (int i : live) ++sc.grid_offset_[bucket_of(i) + 1];
    for (size_t b = 0; b < buckets; ++b) sc.grid_offset_[b + 1] += sc.grid_offset_[b];
    sc.grid_balls_.resize(live.size());
    std::vector<int> cursor(sc.grid_offset_.begin(), sc.grid_offset_.end() - 1);
    for (int i : live) sc.grid_balls_[static_cast<size_t>(cursor[bucket_of(i)]++)] = i;
  }

  // `out` = `from` with its balls moved, each cell listed in `known` (by
  // ascending cell) taking its centre and size from there and its projector
  // from `from`. Copy-assigned, so that a complex moved before keeps its
  // allocations; not even copied when `out` holds `from`'s combinatorics
  // already (a morph's frames): the copy of the cells, cofaces and tuple
  // map was about half of moving a complex.
  static void moved(const SkinComplex& from, std::vector<Ball> balls, const std::vector<SkinComplex::KnownCell>& known,
                    SkinComplex& out) {
    if (balls.size() != from.balls_.size()) contract_error("with_balls: the number of balls differs from the complex's");
    if (&out == &from) contract_error("with_balls: the complex cannot be moved onto itself");
    check_finite(balls);
    for (size_t k = 0; k < known.size(); ++k)
      if (known[k].cell < 0 || known[k].cell >= static_cast<int>(from.cells_.size()) ||
          (k > 0 && known[k].cell <= known[k - 1].cell))
        contract_error("with_balls: known cells must be in range and ascending");
    if (out.combinatorics_ != from.combinatorics_ || out.cells_.size() != from.cells_.size()) out = from;
    out.topology_.reset();
    out.balls_ = std::move(balls);
    compute_geometry(out);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, known.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t k = r.begin(); k != r.end(); ++k) {
        MixedCell& cell = out.cells_[static_cast<size_t>(known[k].cell)];
        cell.center = known[k].center;
        cell.R2 = known[k].R2;
        cell.P = from.cells_[static_cast<size_t>(known[k].cell)].P;
      }
    });
    build_start_grid(out);
  }

  static SkinComplex build(std::vector<Ball> balls, const SkinComplexOptions& options) {
    check_input(balls, options);
    SkinComplex sc;
    sc.shrink_ = options.shrink;
    sc.balls_ = std::move(balls);
    std::vector<std::pair<Regular::Weighted_point, int>> points;
    points.reserve(sc.balls_.size());
    for (size_t i = 0; i < sc.balls_.size(); ++i) {
      const Ball& b = sc.balls_[i];
      points.emplace_back(Regular::Weighted_point(K::Point_3(b.center.x(), b.center.y(), b.center.z()), b.weight),
                          static_cast<int>(i));
    }
    Regular rt(points.begin(), points.end());
    const auto all_positive = [&sc] {
      return std::all_of(sc.balls_.begin(), sc.balls_.end(), [](const Ball& b) { return b.weight > 0; });
    };
    if (options.count_topology && rt.dimension() == 3 && all_positive())
      sc.topology_ = detail::count_dual_complex(rt, sc.balls_.size());
    static std::atomic<unsigned long> builds{0};
    sc.combinatorics_ = ++builds;
    sc.dimension_ = rt.dimension();
    add_simplices(rt, sc);
    link_faces(sc);
    compute_geometry(sc);
    add_constraints_beyond_flat_cofaces(sc.cells_, sc.faces_, sc.face_offset_, sc.cofaces_, sc.coface_offset_);
    build_start_grid(sc);
    return sc;
  }
};

SkinComplex SkinComplex::with_balls(std::vector<Ball> balls) const {
  SkinComplex sc;
  SkinComplexBuilder::moved(*this, std::move(balls), {}, sc);
  return sc;
}

SkinComplex SkinComplex::with_balls(std::vector<Ball> balls, const std::vector<KnownCell>& known) const {
  SkinComplex sc;
  with_balls(std::move(balls), known, sc);
  return sc;
}

void SkinComplex::with_balls(std::vector<Ball> balls, const std::vector<KnownCell>& known, SkinComplex& out) const {
  SkinComplexBuilder::moved(*this, std::move(balls), known, out);
}

bool SkinComplex::same_flat_cells(const SkinComplex& other) const {
  if (cells_.size() != other.cells_.size()) return false;
  for (size_t c = 0; c < cells_.size(); ++c)
    if (cells_[c].degenerate != other.cells_[c].degenerate) return false;
  return true;
}

SkinComplex build_skin_complex(std::vector<Ball> balls, const SkinComplexOptions& options) {
  return SkinComplexBuilder::build(std::move(balls), options);
}

}  // namespace skinmesh
