#include "skinmesh/morph/morph.hpp"

#include "skinmesh/core/error.hpp"
#include "skinmesh/core/stopwatch.hpp"
#include "skinmesh/morph/transport.hpp"

#include <algorithm>

namespace skinmesh {

Morph::Morph(std::vector<Ball> source, std::vector<Ball> target, std::vector<BallPair> pairs, SkinComplex middle,
             const MorphOptions& options)
    : source_(std::move(source)),
      target_(std::move(target)),
      pairs_(std::move(pairs)),
      middle_(std::move(middle)),
      current_(middle_),
      options_(options) {
  const std::vector<CellSize> sizes = cell_sizes(middle_, source_, target_, pairs_);
  const MorphOracle oracle(source_, target_, options.shrink);
  events_ = critical_events(topology_events(sizes), sizes, middle_, pairs_, oracle);
}

void Morph::rebuild(const SkinComplex& next, const MeshingOptions& criteria) {
  SkinMeshResult made = mesh_skin(next, criteria);
  if (made.status != MeshingStatus::ok) throw Error("morph frame at t = " + std::to_string(t_) + ": " + made.message);
  frame_.mesh = std::move(made.mesh);
  frame_.ids.resize(frame_.mesh.vertices.size());
  for (long& id : frame_.ids) id = next_id_++;
  frame_.stats.full_rebuild = true;
}

// Transport (eq. 19) or, off the cell, projection onto the new skin from
// the transported point. False when a vertex cannot be put on the skin.
bool Morph::move_vertices(const SkinComplex& next, SurfaceMesh& mesh, FrameStats& stats) const {
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    const int cell = mesh.cells[v];
    const TransportedPoint moved = transport(current_, next, cell, mesh.vertices[v]);
    const Eigen::Vector3d start = moved.status == TransportStatus::size_vanished ? mesh.vertices[v] : moved.point;
    if (moved.status == TransportStatus::in_cell) {
      mesh.vertices[v] = moved.point;
      ++stats.moved;
    } else {
      const Projection p = next.project(start, cell, 1e-14);
      if (!p.converged) return false;
      mesh.vertices[v] = p.point;
      mesh.cells[v] = p.cell;
      ++stats.relocated;
    }
    mesh.normals[v] = next.evaluate(mesh.vertices[v], mesh.cells[v]).gradient.normalized();
  }
  return true;
}

long Morph::count_bad_triangles(const SkinComplex& next, const SurfaceMesh& mesh) const {
  long bad = 0;
  for (const auto& t : mesh.triangles) {
    const std::array<Eigen::Vector3d, 3> corners{mesh.vertices[static_cast<size_t>(t[0])],
                                                 mesh.vertices[static_cast<size_t>(t[1])],
                                                 mesh.vertices[static_cast<size_t>(t[2])]};
    const auto restricted =
        restricted_triangle(next, corners, options_.frames.tolerance, mesh.cells[static_cast<size_t>(t[0])]);
    bad += !restricted || triangle_defect(next, *restricted, options_.frames) != TriangleDefect::none;
  }
  return bad;
}

const MorphFrame& Morph::advance_to(double t) {
  if (!(t > t_ && t < 1)) contract_error("advance_to: t must lie after the current frame and below 1");
  const auto start = Clock::now();
  const SkinComplex next = middle_.with_balls(interpolated_balls(source_, target_, pairs_, t));
  FrameStats stats;
  stats.t = t;
  stats.events = std::count_if(events_.begin(), events_.end(),
                               [&](const TopologyEvent& e) { return e.t > t_ && e.t <= t; });
  SurfaceMesh moved = frame_.mesh;
  const bool on_skin = stats.events == 0 && move_vertices(next, moved, stats);
  if (on_skin) stats.bad_triangles = count_bad_triangles(next, moved);
  t_ = t;
  frame_.stats = stats;
  if (on_skin && stats.bad_triangles == 0) {
    frame_.mesh = std::move(moved);  // ids stay: every vertex survives
  } else {
    rebuild(next, options_.frames);
  }
  current_ = next;
  frame_.stats.t = t;
  frame_.stats.vertices = static_cast<long>(frame_.mesh.vertices.size());
  frame_.stats.triangles = static_cast<long>(frame_.mesh.triangles.size());
  frame_.stats.seconds = seconds_since(start);
  return frame_;
}

Morph prepare_morph(std::vector<Ball> source, std::vector<Ball> target, double t0, const MorphOptions& options) {
  if (!(t0 > 0 && t0 < 1)) contract_error("prepare_morph: the first frame must lie in (0,1)");
  std::vector<BallPair> pairs = live_pairs(source, target);
  SkinComplex middle = build_skin_complex(interpolated_balls(source, target, pairs, 0.5), {options.shrink});
  Morph morph(std::move(source), std::move(target), std::move(pairs), std::move(middle), options);
  morph.current_ = morph.middle_.with_balls(interpolated_balls(morph.source_, morph.target_, morph.pairs_, t0));
  morph.t_ = t0;
  morph.rebuild(morph.current_, options.first);
  morph.frame_.stats.t = t0;
  morph.frame_.stats.vertices = static_cast<long>(morph.frame_.mesh.vertices.size());
  morph.frame_.stats.triangles = static_cast<long>(morph.frame_.mesh.triangles.size());
  return morph;
}

}  // namespace skinmesh
