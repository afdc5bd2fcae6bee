#include "skinmesh/morph/morph.hpp"
#include "skinmesh/core/skin_topology.hpp"
#include "skinmesh/morph/blend_topology.hpp"
#include "skinmesh/morph/moving_balls.hpp"
#include "skinmesh/quality/mesh_quality.hpp"  // mesh_topology

#include "skinmesh/core/error.hpp"
#include "skinmesh/core/stopwatch.hpp"
#include "skinmesh/mesher/triangle_estimate.hpp"
#include "skinmesh/morph/relaxation.hpp"
#include "skinmesh/morph/transport.hpp"

#include "judge.hpp"
#include "local_repair.hpp"
#include "mesh_part.hpp"
#include "births.hpp"
#include "surgery.hpp"
#include "vanishing.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <utility>

namespace skinmesh {

namespace {

// Whether a critical event falls in the step (from, to].
bool in_step(const TopologyEvent& e, double from, double to) { return e.t > from && e.t <= to; }

// Whether it takes a whole component or void away (dimension 0 or 3,
// lowering the Euler characteristic): drop_vanished's case.
bool takes_a_sphere(const TopologyEvent& e) { return (e.dim == 0 || e.dim == 3) && e.euler_change < 0; }

// The critical events in (from, to] as places where the local repair must
// change the topology, with the change of the Euler characteristic they add
// up to. A component or a void born (dimension 0 or 3, the Euler
// characteristic up by 2) is seeded around its centre. One that vanishes
// (down by 2) and was `handled` (its component dropped, drop_vanished) is
// left out; one that cancels an event of the same step (`partner`,
// cancelling_partners) is a place with its partner, adding nothing to the
// Euler characteristic. One that vanishes and was neither (the frame
// before does not hold it as a component of its own: a neck to it pinched
// in the same step) is a place whose patch must take it away. The patch
// reaches 1 A plus twice the feature's size from the event's apex at `to`,
// past the vertices transport left around it: the size at `to` for a
// feature that opens or is born, at `from` for one that vanishes (its size
// at `to` is about nothing).
void add_topology_changes(const std::vector<TopologyEvent>& events, const std::vector<CellSize>& sizes, double from,
                          double to, const std::vector<char>& handled, const std::vector<int>& partner,
                          detail::LocalRepairOptions& local) {
  for (size_t i = 0; i < events.size(); ++i) {
    const TopologyEvent& e = events[i];
    if (!in_step(e, from, to) || handled[i]) continue;
    const bool cancelled = partner[i] >= 0;
    const bool vanishing = takes_a_sphere(e) && !cancelled;
    const bool sphere = e.dim == 0 || e.dim == 3;
    const CellSize& size = sizes[static_cast<size_t>(e.cell)];
    const double feature = std::sqrt(std::abs(size.at(vanishing ? from : to)));
    detail::TopologyChange change;
    change.point = size.center(to);
    change.radius = 1.0 + 2 * feature;
    change.birth = sphere && e.euler_change > 0 && !cancelled;
    change.size = feature;
    change.cell = e.cell;
    change.dim = e.dim;
    change.euler_change = cancelled ? 0 : e.euler_change;
    change.neck_cell = e.dim == 1 || e.dim == 2 ? e.cell : -1;
    local.changes.push_back(change);
    if (!cancelled) local.euler_change += e.euler_change;
  }
}

MeshingOptions with_size_margin(MeshingOptions o, double margin) {
  o.sizing.epsilon *= margin;
  o.edge_length *= margin;
  o.tolerance *= margin;
  return o;
}

}  // namespace

// The morph's state and its steps: Morph's public calls forward here.
struct Morph::Impl {
  Impl(std::vector<Ball> source, std::vector<Ball> target, std::vector<BallPair> pairs, SkinComplex middle,
       const MorphOptions& options);
  const MorphFrame& advance_to(double t, double next_t);
  std::vector<std::array<int, 2>> vertex_atoms() const;
  bool too_dense(const SkinComplex& next, const SurfaceMesh& mesh) const;
  void rebuild_thinned(const SkinComplex& next, double t);
  void rebuild(const SkinComplex& next, const MeshingOptions& criteria, double t);
  void remesh_or_rebuild(const SkinComplex& next, const SurfaceMesh& moved, const std::vector<char>& drop,
                         const std::vector<SkinSample>& seeds = {});
  bool repair(const SkinComplex& next, const SurfaceMesh& moved, const std::vector<char>& drop,
              const std::vector<SkinSample>& seeds);
  long mend_by_surgery(const SkinComplex& next, SurfaceMesh& moved, std::vector<char>& failing, std::vector<char>& drop,
                       detail::LocalRepairOptions& local, long left);
  long mend_by_edits(const SkinComplex& next, SurfaceMesh& moved, std::vector<char>& failing,
                     std::vector<char>& drop);
  std::vector<char> move_vertices(const SkinComplex& next, SurfaceMesh& mesh, FrameStats& stats,
                                  std::vector<char>& stayed) const;
  std::vector<char> drop_vanished(double t, const std::vector<char>& stayed, SurfaceMesh& moved,
                                  std::vector<char>& lost, FrameStats& stats);
  bool repair_locally(const SkinComplex& next, const SurfaceMesh& moved, const std::vector<char>& failing,
                      const detail::LocalRepairOptions& local);

  void reseat(const SkinComplex& next, FrameStats& stats);
  SkinComplex overlay_at(double t) const;
  void overlay_at(double t, SkinComplex& out) const;  // into out's storage (see with_balls)
  std::vector<SkinComplex::KnownCell> known_cells(double t) const;  // the overlay cells' centres and sizes at t
  void finish_frame(double t, Clock::time_point start);
  // A frame after transport, relaxation and judging, before its repair.
  struct Transported {
    SurfaceMesh mesh;
    std::vector<char> failing;        // per triangle
    std::vector<char> drop;           // per vertex: lost (removed at a whole-frame remesh)
    std::vector<char> handled;        // per event: its vanishing component was dropped (drop_vanished)
    std::vector<int> partner;         // per event: the event of the step it cancels, or -1 (cancelling_partners)
    long first_new_id = 0, before = 0;  // the first id this frame may give; vertices of the frame before
    long lost_left = 0;               // lost vertices still in `mesh` (merge_lost)
  };
  void merge_lost(Transported& moved);
  void mend_frame(const SkinComplex& next, double t, Transported& moved, const std::function<void()>& before_remesh);
  SkinTopology count_skin(const SkinComplex& next, double t);

  std::vector<Ball> source_, target_;
  std::vector<BallPair> pairs_;
  SkinComplex middle_, current_;
  SkinComplex spare_;  // the complex of the frame before last: storage for the next frame's
  double spare_t_ = -1;  // the frame spare_ was moved to ahead (advance_to's next_t); -1: none
  bool on_overlay_ = true;  // current_ is the overlay complex (cells numbered as middle_)
  MorphOptions options_;
  std::vector<CellSize> sizes_;  // per cell of middle_: its size and centre as functions of t
  std::vector<TopologyEvent> events_;
  // The remeshes' certificate: the skin's topology, carried from one
  // remesh's count to the next where no change can lie between; made at
  // the first remesh.
  std::optional<CarriedTopology> skin_counts_;
  MorphFrame frame_;
  double t_ = 0;
  long next_id_ = 0;
  // Thinning contractions the edits were refused, kept for the next frame's
  // (detail::RefusedEdges in surgery.hpp).
  detail::RefusedEdges refused_thinning_;
  std::function<void(SurfaceMesh&, std::vector<long>&)> remesh_fault_;  // detail::inject_remesh_fault
};

MeshingOptions MorphOptions::repair_criteria() const {
  MeshingOptions r = with_size_margin(frames, repair_size_margin);
  r.min_angle = std::min(30.0, frames.min_angle + repair_angle_margin);
  return r;
}

MeshingOptions MorphOptions::first_criteria() const { return with_size_margin(first, first_size_margin); }

Morph::Impl::Impl(std::vector<Ball> source, std::vector<Ball> target, std::vector<BallPair> pairs, SkinComplex middle,
             const MorphOptions& options)
    : source_(std::move(source)),
      target_(std::move(target)),
      pairs_(std::move(pairs)),
      middle_(std::move(middle)),
      current_(middle_),
      options_(options) {
  sizes_ = cell_sizes(middle_, source_, target_, pairs_);
  const MorphOracle oracle(source_, target_, options.shrink);
  events_ = critical_events(topology_events(sizes_), sizes_, middle_, pairs_, oracle);
}

void Morph::Impl::rebuild(const SkinComplex& next, const MeshingOptions& criteria, double t) {
  SkinMeshResult made = mesh_skin(next, criteria);
  if (made.status != MeshingStatus::ok)
    throw MeshingFailed(made.status, "morph frame at t = " + std::to_string(t) + ": " + made.message);
  frame_.mesh = std::move(made.mesh);
  frame_.ids.resize(frame_.mesh.vertices.size());
  for (long& id : frame_.ids) id = next_id_++;
  frame_.stats.full_rebuild = true;
}

// More than max_over_fresh times the triangles of a fresh mesh of `next`'s
// skin, as the mesher estimates it; the estimate (about 0.07 s on
// ubiquitin) only where the cheap density measure passes the screen.
bool Morph::Impl::too_dense(const SkinComplex& next, const SurfaceMesh& mesh) const {
  if (!(detail::density_over_fresh(next, mesh, options_.frames) > options_.density_screen)) return false;
  const TriangleEstimate fresh = estimate_triangles(skin_area_profile(next), options_.frames);
  return static_cast<double>(mesh.triangles.size()) > options_.max_over_fresh * std::max(fresh.triangles, 1.0);
}

// The frame meshed afresh because it is too dense (too_dense).
void Morph::Impl::rebuild_thinned(const SkinComplex& next, double t) {
  const long before = static_cast<long>(frame_.ids.size());
  const auto start = Clock::now();
  rebuild(next, options_.repair_criteria(), t);
  frame_.stats.thinned = true;
  frame_.stats.inserted = static_cast<long>(frame_.ids.size());
  frame_.stats.removed = before;
  frame_.stats.seconds_repair += seconds_since(start);
}

// Transport (eq. 19) or, off the cell, projection onto the new skin from
// the transported point. Returns per vertex 1 where it could not be put on
// the skin (lost), else 0.
std::vector<char> Morph::Impl::move_vertices(const SkinComplex& next, SurfaceMesh& mesh, FrameStats& stats,
                                       std::vector<char>& stayed) const {
  const size_t n = mesh.vertices.size();
  std::vector<char> state(n, 0);  // 0 moved, 1 lost, 2 relocated
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 512), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v) {
      const int cell = mesh.cells[v];
      const TransportedPoint moved = transport(current_, next, cell, mesh.vertices[v]);
      if (moved.status == TransportStatus::in_cell) {
        mesh.vertices[v] = moved.point;
      } else {
        const Eigen::Vector3d start = moved.status == TransportStatus::size_vanished ? mesh.vertices[v] : moved.point;
        const Projection p = next.project(start, cell, 1e-14);
        if (!p.converged) {
          state[v] = 1;
          continue;
        }
        mesh.vertices[v] = p.point;
        mesh.cells[v] = p.cell;
        state[v] = 2;
      }
      mesh.normals[v] = next.evaluate(mesh.vertices[v], mesh.cells[v]).gradient.normalized();
    }
  });
  std::vector<char> lost(n, 0);
  stayed.assign(n, 0);
  for (size_t v = 0; v < n; ++v) {
    lost[v] = state[v] == 1;
    stayed[v] = state[v] == 0;
    stats.moved += state[v] == 0;
    stats.relocated += state[v] == 2;
    stats.lost += state[v] == 1;
  }
  return lost;
}

// The failing triangles, and those around the topology changes since the
// current frame, remeshed in patches (local_repair.hpp); false when an event
// needs the whole frame, the seam does not hold or the topology is not what
// the events say (the caller remeshes the frame).
bool Morph::Impl::repair_locally(const SkinComplex& next, const SurfaceMesh& moved, const std::vector<char>& failing,
                                 const detail::LocalRepairOptions& local) {
  const auto start = Clock::now();
  detail::RepairResult r =
      detail::repair_locally(next, moved, failing, options_.repair_criteria(), options_.frames, local);
  frame_.stats.seconds_patch += seconds_since(start);
  frame_.stats.patch_attempts += r.attempts;
  if (!r.ok) {
    frame_.stats.remeshed_because = "the local patch failed: " + r.failed_because;
    return false;
  }
  detail::take_ids_and_counts(r, frame_.ids, next_id_, frame_.stats);  // inserted and removed: by ids (advance_to)
  frame_.mesh = std::move(r.mesh);
  return true;
}

// The necks that open or pinch in the frame's step cut and joined or
// capped (necks.hpp), their new triangles left failing for the edits, and
// the components and voids born meshed as spheres (births.hpp); the
// changes made leave the patch's places and the Euler characteristic it
// must make. Returns how many triangles fail (`left` when none was made).
long Morph::Impl::mend_by_surgery(const SkinComplex& next, SurfaceMesh& moved, std::vector<char>& failing,
                                  std::vector<char>& drop, detail::LocalRepairOptions& local, long left) {
  const auto start = Clock::now();
  detail::EventSurgery surgery =
      detail::surgery_at_events(next, moved, failing, options_.frames, options_.repair, local);
  frame_.stats.seconds_edits += seconds_since(start);
  detail::RepairResult& cut = surgery.result;
  if (!cut.ok) return left;
  std::vector<char> dropped(cut.origin.size(), 0);
  for (size_t v = 0; v < dropped.size(); ++v)
    if (cut.origin[v] >= 0 && static_cast<size_t>(cut.origin[v]) < drop.size())
      dropped[v] = drop[static_cast<size_t>(cut.origin[v])];
  drop = std::move(dropped);
  detail::take_ids_and_counts(cut, frame_.ids, next_id_, frame_.stats);
  moved = std::move(cut.mesh);
  failing = std::move(cut.failing);
  frame_.stats.necks += surgery.necks;
  frame_.stats.births += surgery.births;
  return cut.left;
}

// The failing triangles mended by edits of the mesh (surgery.hpp); `moved`,
// `failing` and `drop` become the edited mesh's, and the frame's ids follow
// its vertices. Returns how many triangles still fail.
long Morph::Impl::mend_by_edits(const SkinComplex& next, SurfaceMesh& moved, std::vector<char>& failing,
                                std::vector<char>& drop) {
  const auto start = Clock::now();
  detail::RepairResult r = detail::mend_by_edits(next, std::move(moved), failing, options_.frames,
                                                 options_.repair.edits, &frame_.ids, &refused_thinning_);
  detail::take_ids_and_counts(r, frame_.ids, next_id_, frame_.stats);
  moved = std::move(r.mesh);
  failing = std::move(r.failing);
  drop.assign(moved.vertices.size(), 0);
  frame_.stats.seconds_edits += seconds_since(start);
  return r.left;
}

// Remeshes the frame from the transported vertices not dropped and `seeds`;
// false when the mesher cannot (then the caller rebuilds from scratch).
bool Morph::Impl::repair(const SkinComplex& next, const SurfaceMesh& moved, const std::vector<char>& drop,
                         const std::vector<SkinSample>& seeds) {
  detail::RepairResult r = detail::remesh_from_vertices(next, moved, drop, options_.repair_criteria(), seeds);
  if (!r.ok) return false;
  const long kept = std::count_if(r.origin.begin(), r.origin.end(), [](long o) { return o >= 0; });
  detail::take_ids_and_counts(r, frame_.ids, next_id_, frame_.stats);
  frame_.stats.remeshed = true;
  frame_.stats.inserted = static_cast<long>(r.origin.size()) - kept;
  frame_.stats.removed = static_cast<long>(moved.vertices.size()) - kept;
  frame_.mesh = std::move(r.mesh);
  return true;
}

// Every vertex projected onto the skin of another complex (the target's at
// t = 1, the overlay after a first frame at t = 0), then the frame remeshed
// from them: the cells of the two complexes are not the same cells.
void Morph::Impl::reseat(const SkinComplex& next, FrameStats& stats) {
  const auto transport_start = Clock::now();
  SurfaceMesh moved = frame_.mesh;
  std::vector<char> lost(moved.vertices.size(), 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, lost.size(), 512), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v) {
      const Projection p = next.project(moved.vertices[v], -1, 1e-14);
      lost[v] = !p.converged;
      if (p.converged) {
        moved.vertices[v] = p.point;
        moved.cells[v] = p.cell;
      }
    }
  });
  stats.lost = std::count(lost.begin(), lost.end(), 1);
  stats.relocated = static_cast<long>(lost.size()) - stats.lost;
  stats.seconds_transport = seconds_since(transport_start);
  frame_.stats = stats;
  if (stats.lost == 0 && too_dense(next, moved)) {
    rebuild_thinned(next, stats.t);
    return;
  }
  const auto repair_start = Clock::now();
  frame_.stats.remeshed_because = "the frame moves between one side's own complex (t = 0 or 1) and the overlay's";
  remesh_or_rebuild(next, moved, lost);
  frame_.stats.seconds_repair = seconds_since(repair_start);
}

// The whole frame remeshed from its transported vertices, or, when the
// mesher cannot or the remesh's topology is not the skin's, meshed from
// scratch (counted as a full rebuild). Either mesh is certified: its
// components, voids and Euler characteristic must be those of the skin of
// the frame's balls, counted from their weighted alpha complex
// (skin_topology.hpp), or carried from an earlier remesh's count where no
// change can lie between (blend_topology.hpp), beside the remesh:
// refinement from transported vertices can close a thin handle that seeds
// and refinement from scratch keep. Throws Error when the mesh from scratch
// is not certified either.
void Morph::Impl::remesh_or_rebuild(const SkinComplex& next, const SurfaceMesh& moved, const std::vector<char>& drop,
                                    const std::vector<SkinSample>& seeds) {
  SkinTopology skin;
  tbb::task_group counting;
  const double t = frame_.stats.t;  // read here: the remesh writes frame_.stats beside the count
  counting.run([&] { skin = count_skin(next, t); });
  const long before = static_cast<long>(frame_.ids.size());
  const std::vector<long> ids = frame_.ids;  // of `moved`'s vertices, for a second remesh
  bool remeshed = repair(next, moved, drop, {});
  if (remeshed && remesh_fault_) remesh_fault_(frame_.mesh, frame_.ids);
  counting.wait();
  // A neck that opened can be too thin for any vertex to lie on: the remesh
  // then closes it. Seeded at the topology changes, it resolves them
  // (seeding every remesh made larger meshes where it was not needed).
  if ((!remeshed || mesh_topology(frame_.mesh) != skin) && !seeds.empty()) {
    frame_.ids = ids;
    remeshed = repair(next, moved, drop, seeds);
    if (remeshed && remesh_fault_) remesh_fault_(frame_.mesh, frame_.ids);
    frame_.stats.remeshed_because += "; remeshed again with seeds at the topology changes";
  }
  if (remeshed) {
    const SkinTopology made = mesh_topology(frame_.mesh);
    if (made == skin) return;
    frame_.stats.remeshed_because += "; the remesh had " + made.text() + " where the skin has " + skin.text() +
                                     ", so the frame was meshed from scratch";
  }
  rebuild(next, options_.repair_criteria(), frame_.stats.t);
  frame_.stats.inserted = static_cast<long>(frame_.mesh.vertices.size());
  frame_.stats.removed = before;
  if (remesh_fault_) remesh_fault_(frame_.mesh, frame_.ids);
  const SkinTopology made = mesh_topology(frame_.mesh);
  if (made != skin)
    throw Error("morph frame at t = " + std::to_string(frame_.stats.t) + ": the mesh has " + made.text() +
                " where the skin has " + skin.text() + "; the frame is refused");
}

// The skin topology of `next`, the complex of the frame at t: counted from
// its balls, or carried from an earlier remesh's count (blend_topology.hpp).
SkinTopology Morph::Impl::count_skin(const SkinComplex& next, double t) {
  if (!skin_counts_)
    skin_counts_.emplace(
        TopologyWindows(middle_, sizes_, source_, target_, pairs_, MorphOracle(source_, target_, options_.shrink)));
  return skin_counts_->at(t, next.balls()).topology;
}

void Morph::Impl::finish_frame(double t, Clock::time_point start) {
  frame_.stats.density = detail::density_over_fresh(current_, frame_.mesh, options_.frames);
  if (!frame_.stats.full_rebuild && frame_.stats.density > options_.density_screen &&
      too_dense(current_, frame_.mesh)) {
    rebuild_thinned(current_, t);
    frame_.stats.density = detail::density_over_fresh(current_, frame_.mesh, options_.frames);
  }
  t_ = t;
  frame_.stats.t = t;
  frame_.stats.vertices = static_cast<long>(frame_.mesh.vertices.size());
  frame_.stats.triangles = static_cast<long>(frame_.mesh.triangles.size());
  frame_.stats.seconds = seconds_since(start);
}

// A component or void that vanishes in the step (a critical event of
// dimension 0 or 3 lowering the Euler characteristic) is found in the frame
// before it (vanishing.hpp) and dropped from `moved`, with its vertices'
// ids and their entries in `lost`. Returns per event whether its component
// was dropped.
std::vector<char> Morph::Impl::drop_vanished(double t, const std::vector<char>& stayed, SurfaceMesh& moved,
                                       std::vector<char>& lost, FrameStats& stats) {
  std::vector<char> handled(events_.size(), 0);
  std::vector<detail::VanishingSphere> spheres;
  std::vector<size_t> which;
  for (size_t i = 0; i < events_.size(); ++i) {
    const TopologyEvent& e = events_[i];
    if (!in_step(e, t_, t) || !takes_a_sphere(e)) continue;
    const CellSize& size = sizes_[static_cast<size_t>(e.cell)];
    spheres.push_back({size.center(t_), 1.0 + 2 * std::sqrt(std::abs(size.at(t_)))});
    which.push_back(i);
  }
  if (spheres.empty()) return handled;
  std::vector<char> found;
  const std::vector<char> gone = detail::vanishing_components(frame_.mesh, stayed, spheres, found);
  for (size_t k = 0; k < found.size(); ++k) handled[which[k]] = found[k];
  if (std::find(found.begin(), found.end(), 1) == found.end()) return handled;
  for (size_t v = 0; v < gone.size(); ++v)
    if (gone[v]) {
      stats.lost -= lost[v];
      stats.relocated -= !lost[v];
    }
  std::vector<char> keep(moved.triangles.size());
  for (size_t f = 0; f < keep.size(); ++f)  // a component's triangles go with it
    keep[f] = !gone[static_cast<size_t>(moved.triangles[f][0])];
  std::vector<int> kept_from;
  moved = detail::used_part(moved, keep, kept_from);
  std::vector<long> ids;
  std::vector<char> kept_lost;
  for (int v : kept_from) {
    ids.push_back(frame_.ids[static_cast<size_t>(v)]);
    kept_lost.push_back(lost[static_cast<size_t>(v)]);
  }
  lost = std::move(kept_lost);
  frame_.ids = std::move(ids);
  return handled;
}

// The vertices transport lost merged into neighbours it placed
// (merge_lost_vertices), with their ids; the triangles left around them are
// judged with the rest. When one cannot be merged, the frame keeps its lost
// vertices (lost_left) and is remeshed whole without them.
void Morph::Impl::merge_lost(Transported& moved) {
  std::vector<int> kept_from;
  std::vector<char> touched;  // every triangle is judged after transport: not needed here
  if (!detail::merge_lost_vertices(moved.mesh, moved.drop, kept_from, touched)) return;
  std::vector<long> ids;
  ids.reserve(kept_from.size());
  for (int v : kept_from) ids.push_back(frame_.ids[static_cast<size_t>(v)]);
  frame_.ids = std::move(ids);
  moved.lost_left = 0;
}

const MorphFrame& Morph::Impl::advance_to(double t, double next_t) {
  if (!(t > t_ && t <= 1)) contract_error("advance_to: t must lie after the current frame and at most 1");
  const auto start = Clock::now();
  FrameStats stats;
  stats.t = t;
  stats.events = std::count_if(events_.begin(), events_.end(),
                               [&](const TopologyEvent& e) { return in_step(e, t_, t); });
  if (t == 1.0 || !on_overlay_) {
    SkinComplex next = t == 1.0 ? build_skin_complex(target_, {options_.shrink}) : overlay_at(t);
    stats.seconds_complex = seconds_since(start);
    reseat(next, stats);
    current_ = std::move(next);
    spare_t_ = -1;
    on_overlay_ = t < 1.0;
    finish_frame(t, start);
    return frame_;
  }
  if (spare_t_ != t) overlay_at(t, spare_);
  stats.seconds_complex = seconds_since(start);
  const SkinComplex& next = spare_;
  Transported moved;
  moved.mesh = frame_.mesh;
  moved.first_new_id = next_id_;
  moved.before = static_cast<long>(frame_.ids.size());
  std::vector<char> stayed;
  auto stage_start = Clock::now();
  moved.drop = move_vertices(next, moved.mesh, stats, stayed);
  moved.handled = drop_vanished(t, stayed, moved.mesh, moved.drop, stats);
  moved.partner = cancelling_partners(events_, sizes_, t_, t, moved.handled);  // voids born and gone in the step
  moved.lost_left = std::count(moved.drop.begin(), moved.drop.end(), 1);
  if (moved.lost_left > 0) merge_lost(moved);
  stats.seconds_transport = seconds_since(stage_start);
  // Too dense to be worth mending (a skin that shrank under it): afresh.
  if (moved.lost_left == 0 && too_dense(next, moved.mesh)) {
    frame_.stats = stats;
    rebuild_thinned(next, t);
    std::swap(current_, spare_);
    spare_t_ = -1;
    finish_frame(t, start);
    return frame_;
  }
  if (moved.lost_left == 0) {
    // Every vertex is relaxed before judging, where moving atoms relax only
    // the corners of failing triangles (detail::judge_and_relax): the
    // overlay's cells scale by different factors every frame and shear the
    // triangles across their faces, and relaxing them all costs less than
    // patching what they go on to fail (judged first and relaxed locally,
    // bench_morph's 2k39 1 -> 3 and pept -> 3al1 frames took 7% and 32%
    // longer, their patches 1.7 and 1.6 times as long).
    stage_start = Clock::now();
    if (options_.relaxation.passes > 0) relax_tangentially(next, moved.mesh, options_.relaxation);
    stats.seconds_relax = seconds_since(stage_start);
    stage_start = Clock::now();
    moved.failing = detail::failing_triangles(next, moved.mesh, moved.mesh.triangles, options_.frames);
    stats.bad_triangles = std::count(moved.failing.begin(), moved.failing.end(), 1);
    stats.seconds_judge = seconds_since(stage_start);
  }
  frame_.stats = stats;
  // While the frame is mended by edits or a patch, mostly on one core, the
  // next frame's complex is moved on the other into current_, which
  // transport no longer needs. It is waited for before a whole-frame
  // remesh, which runs partly on both cores: overlapping that too saved
  // little and raised the peak memory (glibc's heap for the other thread).
  // The cell list and balls are made on this thread for the same reason.
  const bool ahead = next_t > t && next_t < 1 && moved.lost_left == 0;
  std::vector<SkinComplex::KnownCell> known;
  std::vector<Ball> balls;
  tbb::task_group lookahead;  // after what its task reads: if the repair throws, it waits before they go
  if (ahead) {
    known = known_cells(next_t);
    balls = interpolated_balls(source_, target_, pairs_, next_t);
    lookahead.run([&] { middle_.with_balls(std::move(balls), known, current_); });
  }
  mend_frame(next, t, moved, [&] { lookahead.wait(); });
  lookahead.wait();
  std::swap(current_, spare_);  // swapped, not copied: a copy of the complex costs a share of every frame
  spare_t_ = ahead ? next_t : -1;
  finish_frame(t, start);
  return frame_;
}

// The transported frame made the frame at t: kept as it is, or repaired,
// cheapest first (morph.hpp); `before_remesh` is called before the whole
// frame is remeshed.
void Morph::Impl::mend_frame(const SkinComplex& next, double t, Transported& moved,
                       const std::function<void()>& before_remesh) {
  const FrameStats stats = frame_.stats;  // as transported (the repairs add to frame_.stats)
  if (stats.events == 0 && stats.lost == 0 && stats.bad_triangles == 0) {
    frame_.mesh = std::move(moved.mesh);  // ids stay: every vertex survives
    return;
  }
  const auto repair_start = Clock::now();
  // Edits and local repair are for frames without lost vertices left in
  // the mesh (merge_lost); the others are remeshed whole.
  detail::LocalRepairOptions local;
  local.crowded_below = options_.repair.crowded_below;
  local.policy = options_.repair.patch;
  add_topology_changes(events_, sizes_, t_, t, moved.handled, moved.partner, local);
  const bool mendable = moved.lost_left == 0;
  long left = stats.bad_triangles;
  const bool surgery = options_.repair.neck_surgery || options_.repair.birth_surgery;
  if (mendable && !local.changes.empty() && surgery && options_.repair.edits.enabled)
    left = mend_by_surgery(next, moved.mesh, moved.failing, moved.drop, local, left);
  if (mendable && left > 0 && options_.repair.edits.enabled) left = mend_by_edits(next, moved.mesh, moved.failing, moved.drop);
  if (mendable && local.changes.empty() && left == 0) {
    frame_.mesh = std::move(moved.mesh);
    frame_.stats.repaired = true;
  } else {
    const double share = std::max(options_.repair.patch.max_failing_share * static_cast<double>(moved.failing.size()),
                                   static_cast<double>(options_.repair.patch.always_patch_up_to));
    const bool small = left <= share;
    if (moved.lost_left > 0)
      frame_.stats.remeshed_because = std::to_string(moved.lost_left) +
                                      " vertices could not be put on the new skin nor merged into a neighbour";
    else if (!small)
      frame_.stats.remeshed_because =
          std::to_string(left) + " triangles still failing after the edits (" +
          detail::failing_kinds(next, moved.mesh, moved.failing, options_.frames).text() +
          "), more than the local share (" + std::to_string(static_cast<long>(share)) + ")";
    if (!(mendable && small && repair_locally(next, moved.mesh, moved.failing, local))) {
      before_remesh();
      frame_.stats.crowded =
          detail::mark_crowded(next, moved.mesh, options_.frames, options_.repair.crowded_below, moved.drop);
      remesh_or_rebuild(next, moved.mesh, moved.drop, detail::seeds_at_changes(next, local.changes));
    }
  }
  // Counted by ids, as vertices an edit inserted may be gone again after
  // the repair that followed.
  const long first_new_id = moved.first_new_id;
  frame_.stats.inserted = std::count_if(frame_.ids.begin(), frame_.ids.end(), [&](long id) { return id >= first_new_id; });
  frame_.stats.removed = moved.before - (static_cast<long>(frame_.ids.size()) - frame_.stats.inserted);
  frame_.stats.seconds_repair = seconds_since(repair_start);
}

// The overlay complex at t: middle_ moved to B(t), each overlay cell's
// centre and size from its curves (eq. 17-18: z(t) affine, R2(t) quadratic)
// and its directions from B(1/2). Recomputed from the balls instead, a cell
// near t = 0 or 1 is a sliver and loses digits, enough to put a frame's
// vertices off the skin by more than the 1e-8 A a frame is held to
// (bench/morph_precision checks a frame against CGAL's skin sign).
SkinComplex Morph::Impl::overlay_at(double t) const {
  SkinComplex out;
  overlay_at(t, out);
  return out;
}

void Morph::Impl::overlay_at(double t, SkinComplex& out) const {
  middle_.with_balls(interpolated_balls(source_, target_, pairs_, t), known_cells(t), out);
}

std::vector<SkinComplex::KnownCell> Morph::Impl::known_cells(double t) const {
  std::vector<SkinComplex::KnownCell> known;
  for (size_t c = 0; c < sizes_.size(); ++c)
    if (sizes_[c].overlay_cell) known.push_back({static_cast<int>(c), sizes_[c].center(t), sizes_[c].at(t)});
  return known;
}

std::vector<std::array<int, 2>> Morph::Impl::vertex_atoms() const {
  const SurfaceMesh& mesh = frame_.mesh;
  std::vector<std::array<int, 2>> atoms(mesh.vertices.size());
  for (size_t v = 0; v < atoms.size(); ++v) {
    const int ball = current_.owning_ball(mesh.vertices[v], mesh.cells[v]);
    if (on_overlay_) atoms[v] = {pairs_[static_cast<size_t>(ball)].source, pairs_[static_cast<size_t>(ball)].target};
    else if (t_ == 0.0) atoms[v] = {ball, -1};
    else atoms[v] = {-1, ball};
  }
  return atoms;
}

namespace detail {

void inject_remesh_fault(Morph& morph, std::function<void(SurfaceMesh&, std::vector<long>&)> fault) {
  morph.impl_->remesh_fault_ = std::move(fault);
}

}  // namespace detail

Morph::Morph(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Morph::Morph(Morph&&) noexcept = default;
Morph& Morph::operator=(Morph&&) noexcept = default;
Morph::~Morph() = default;

const MorphFrame& Morph::advance_to(double t, double next_t) { return impl_->advance_to(t, next_t); }
double Morph::t() const { return impl_->t_; }
std::vector<std::array<int, 2>> Morph::vertex_atoms() const { return impl_->vertex_atoms(); }
const MorphFrame& Morph::frame() const { return impl_->frame_; }
const SkinComplex& Morph::complex() const { return impl_->current_; }
const std::vector<TopologyEvent>& Morph::events() const { return impl_->events_; }
const std::vector<BallPair>& Morph::pairs() const { return impl_->pairs_; }
const SkinComplex& Morph::middle_complex() const { return impl_->middle_; }
const std::vector<CellSize>& Morph::sizes() const { return impl_->sizes_; }

Morph prepare_morph(std::vector<Ball> source, std::vector<Ball> target, double t0, const MorphOptions& options) {
  if (!(t0 >= 0 && t0 < 1)) contract_error("prepare_morph: the first frame must lie in [0,1)");
  if (source.empty() || target.empty()) contract_error("prepare_morph: both ball sets must be non-empty");
  std::vector<BallPair> pairs = live_pairs(source, target);
  SkinComplex middle = build_skin_complex(interpolated_balls(source, target, pairs, 0.5), {options.shrink});
  auto m = std::make_unique<Morph::Impl>(std::move(source), std::move(target), std::move(pairs), std::move(middle),
                                         options);
  const auto start = Clock::now();
  m->on_overlay_ = t0 > 0;
  m->current_ = t0 > 0 ? m->overlay_at(t0) : build_skin_complex(m->source_, {options.shrink});
  m->t_ = t0;
  const double seconds_complex = seconds_since(start);
  const auto mesh_start = Clock::now();
  m->rebuild(m->current_, options.first_criteria(), t0);
  m->frame_.stats.seconds_complex = seconds_complex;
  m->frame_.stats.seconds_repair = seconds_since(mesh_start);  // meshed from scratch
  m->frame_.stats.inserted = static_cast<long>(m->frame_.mesh.vertices.size());
  m->finish_frame(t0, start);
  return Morph(std::move(m));
}

}  // namespace skinmesh
