// The restricted Delaunay refiner behind mesh_skin (private to meshing/):
// the 3D Delaunay triangulation of the samples, what its facets say about the
// skin, and the refinement and clean-up that change it. Included by
// skin_mesher.cpp (refinement) and edge_contraction.cpp (clean-up) only.
#pragma once

#include "skinmesh/meshing/skin_mesher.hpp"

#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Delaunay_triangulation_cell_base_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_cell_base_with_info_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>
#include <Eigen/Geometry>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <queue>
#include <tuple>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace skinmesh::detail {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
struct VertexInfo {
  int cell = -1;  // mixed cell of the sample (a hint for every walk that starts near it)
  int id = -1;    // insertion order
};
using Vb = CGAL::Triangulation_vertex_base_with_info_3<VertexInfo, K>;
// Cell info: a stamp that changes whenever the cell is (re)created, so that an
// evaluation of a facet can tell whether its Voronoi edge is still the same.
// A cell made by the triangulation itself (a vertex removal) starts as
// kFreshCell until the refiner stamps it.
constexpr unsigned kFreshCell = std::numeric_limits<unsigned>::max();
struct CellStamp {
  unsigned value = kFreshCell;
};
using Cb = CGAL::Triangulation_cell_base_with_info_3<CellStamp, K, CGAL::Delaunay_triangulation_cell_base_3<K>>;
using Tds = CGAL::Triangulation_data_structure_3<Vb, Cb>;
using Delaunay = CGAL::Delaunay_triangulation_3<K, Tds>;
using Vertex_handle = Delaunay::Vertex_handle;
using Cell_handle = Delaunay::Cell_handle;
using Facet = Delaunay::Facet;
using Clock = std::chrono::steady_clock;

// The distance criterion measures the skin's deviation at one point of each
// triangle (its circumcentre's normal line); the deviation elsewhere in the
// triangle is a little larger, so the criterion keeps this margin.
constexpr double kToleranceMargin = 0.7;

inline Eigen::Vector3d to_eigen(const K::Point_3& p) { return {p.x(), p.y(), p.z()}; }

enum class Defect { none, topology, size, distance, shape };

// What the Voronoi edge dual to one Delaunay facet says about it.
struct FacetEval {
  int crossings = 0;                 // of the Voronoi edge with the skin; restricted iff > 0
  Eigen::Vector3d center;            // surface Delaunay ball centre (farthest crossing if several)
  int cell = -1;                     // its mixed cell
  double radius = 0;                 // surface Delaunay ball radius
  Eigen::Vector3d outward;           // outward skin normal direction along the Voronoi edge
  Defect defect = Defect::none;
  bool force = false;                // a vertex-star repair: insert even without a defect
  std::array<Vertex_handle, 3> v;
  unsigned stamp_c = 0, stamp_n = 0; // of the two cells when evaluated
};

inline double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Whether the link of a vertex (the opposite edges of its restricted
// triangles) is one closed cycle: the vertex star is a disk.
bool is_single_cycle(const std::vector<std::pair<int, int>>& edges);

// A facet by its vertices' ids, ascending.
using FacetKey = std::array<int, 3>;
struct FacetKeyHash {
  size_t operator()(const FacetKey& k) const {
    size_t h = static_cast<size_t>(k[0]);
    h = h * 0x9E3779B97F4A7C15ull ^ static_cast<size_t>(k[1]);
    return h * 0x9E3779B97F4A7C15ull ^ static_cast<size_t>(k[2]);
  }
};
using FacetSet = std::unordered_set<FacetKey, FacetKeyHash>;

class Refiner {
 public:
  Refiner(const SkinComplex& complex, const MeshingOptions& options) : complex_(complex), options_(options) {
    // The skin lies inside the union of the input balls: rays beyond this box miss it.
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d hi = -lo;
    double max_radius = 0;
    for (const Ball& b : complex.balls()) {
      lo = lo.cwiseMin(b.center);
      hi = hi.cwiseMax(b.center);
      max_radius = std::max(max_radius, std::sqrt(std::max(0.0, b.weight)));
    }
    box_center_ = 0.5 * (lo + hi);
    box_radius_ = 0.5 * (hi - lo).norm() + max_radius + 1.0;
    const double angle = options.min_angle * M_PI / 180.0;
    max_radius_edge_ = 1.0 / (2.0 * std::sin(angle));
  }

  SkinMeshResult run();

 private:
  FacetEval evaluate(const Facet& facet) const;
  void insert_seeds();
  Vertex_handle insert(const Eigen::Vector3d& p, int cell, Cell_handle hint);
  void push_if_bad(FacetEval e, bool force = false);
  void refine();
  std::vector<Facet> star_facets(Vertex_handle v) const;  // after insert(v)
  std::vector<FacetEval> evaluate_all(const std::vector<Facet>& facets) const;
  bool global_pass(std::vector<FacetEval>* restricted);
  bool repair_stars(const std::vector<FacetEval>& restricted, const std::vector<Vertex_handle>& vertices);
  void local_passes();
  SurfaceMesh extract(const std::vector<FacetEval>& restricted) const;
  void report(const char* stage, bool always = false, long pending = 0);
  void refine_until_clean(std::vector<FacetEval>* restricted);

  // Clean-up (edge_contraction.cpp).
  long contract_short_edges(const std::vector<FacetEval>& restricted);
  bool try_contract(Vertex_handle a, Vertex_handle b, const Projection& target, unsigned pass_stamp,
                    const FacetSet& restricted_before, std::unordered_set<int>* touched);
  bool region_is_good(const std::vector<Vertex_handle>& region, unsigned pass_stamp,
                      const FacetSet& restricted_before) const;
  Vertex_handle reinsert(const Eigen::Vector3d& p, const VertexInfo& info, Cell_handle hint);
  void stamp_fresh_cells(const std::vector<Vertex_handle>& vertices);  // around these vertices
  void check_budget() const;

  const SkinComplex& complex_;
  const MeshingOptions& options_;
  Delaunay dt_;
  std::vector<FacetEval> pending_;   // bad facets waiting for their surface ball centre
  std::vector<Cell_handle> star_;    // cells made by the last insertion
  std::vector<Vertex_handle> recent_;  // inserted since the last global or local pass
  unsigned stamp_ = 0;
  // The restricted facets of the last global pass, by vertex ids, and the
  // stamp then: cells stamped no later are unchanged since.
  std::unordered_map<FacetKey, FacetEval, FacetKeyHash> pass_cache_;
  unsigned last_pass_stamp_ = 0;
  bool have_pass_cache_ = false;
  Eigen::Vector3d box_center_;
  double box_radius_ = 0;
  double max_radius_edge_ = 1;
  int next_id_ = 0;
  MeshingStats stats_;
  Clock::time_point last_report_ = Clock::now();
};

}  // namespace skinmesh::detail
