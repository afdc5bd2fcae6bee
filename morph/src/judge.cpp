#include "judge.hpp"

#include "skinmesh/core/error.hpp"
#include "skinmesh/core/stopwatch.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <utility>

namespace skinmesh::detail {

Verdict judge_triangle(const SkinComplex& complex, const std::array<Eigen::Vector3d, 3>& corners, int hint,
                       const MeshingOptions& criteria) {
  const auto restricted = restricted_triangle(complex, corners, criteria.tolerance, hint);
  if (!restricted) return Verdict::other;
  switch (triangle_defect(complex, *restricted, criteria)) {
    case TriangleDefect::none: return faces_outward(complex, *restricted) ? Verdict::pass : Verdict::inward;
    case TriangleDefect::size:
    case TriangleDefect::distance: return Verdict::size;
    case TriangleDefect::shape: return Verdict::shape;
    default: return Verdict::other;
  }
}

namespace {

// Triangle t of `mesh` against the criteria, hinted by its first corner's cell.
bool passes(const SkinComplex& complex, const SurfaceMesh& mesh, const std::array<int, 3>& t,
            const MeshingOptions& criteria) {
  return triangle_passes(complex,
                         {mesh.vertices[static_cast<size_t>(t[0])], mesh.vertices[static_cast<size_t>(t[1])],
                          mesh.vertices[static_cast<size_t>(t[2])]},
                         mesh.cells[static_cast<size_t>(t[0])], criteria);
}

}  // namespace

std::vector<char> failing_triangles(const SkinComplex& complex, const SurfaceMesh& mesh,
                                    const std::vector<std::array<int, 3>>& triangles, const MeshingOptions& criteria) {
  std::vector<char> bad(triangles.size(), 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, triangles.size(), 512), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i != r.end(); ++i) bad[i] = !passes(complex, mesh, triangles[i], criteria);
  });
  return bad;
}

std::string FailingKinds::text() const {
  std::string out = "not restricted " + std::to_string(not_restricted) + ", shape " + std::to_string(shape) +
                    ", size or distance " + std::to_string(size) + ", facing inward " + std::to_string(inward);
  if (passing > 0) out += ", passing now " + std::to_string(passing);
  return out;
}

FailingKinds failing_kinds(const SkinComplex& complex, const SurfaceMesh& mesh, const std::vector<char>& failing,
                           const MeshingOptions& criteria) {
  if (failing.size() != mesh.triangles.size()) contract_error("failing_kinds: verdicts do not match the mesh");
  std::vector<size_t> at;
  for (size_t f = 0; f < failing.size(); ++f)
    if (failing[f]) at.push_back(f);
  std::vector<Verdict> verdicts(at.size(), Verdict::pass);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, at.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t k = r.begin(); k != r.end(); ++k) {
      const std::array<int, 3>& t = mesh.triangles[at[k]];
      verdicts[k] = judge_triangle(complex,
                                   {mesh.vertices[static_cast<size_t>(t[0])], mesh.vertices[static_cast<size_t>(t[1])],
                                    mesh.vertices[static_cast<size_t>(t[2])]},
                                   mesh.cells[static_cast<size_t>(t[0])], criteria);
    }
  });
  FailingKinds kinds;
  for (const Verdict v : verdicts) switch (v) {
      case Verdict::pass: ++kinds.passing; break;
      case Verdict::size: ++kinds.size; break;
      case Verdict::shape: ++kinds.shape; break;
      case Verdict::inward: ++kinds.inward; break;
      case Verdict::other: ++kinds.not_restricted; break;
    }
  return kinds;
}

namespace {

// The triangles of `mesh` numbered in `at` judged, their verdicts into `failing`.
void judge_these(const SkinComplex& complex, const SurfaceMesh& mesh, const std::vector<size_t>& at,
                 const MeshingOptions& criteria, std::vector<char>& failing) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, at.size(), 512), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t k = r.begin(); k != r.end(); ++k)
      failing[at[k]] = !passes(complex, mesh, mesh.triangles[at[k]], criteria);
  });
}

}  // namespace

long rejudge_moved(const SkinComplex& complex, const SurfaceMesh& mesh, const std::vector<char>& moved,
                   const MeshingOptions& criteria, std::vector<char>& failing) {
  if (failing.size() != mesh.triangles.size() || moved.size() != mesh.vertices.size())
    contract_error("rejudge_moved: verdicts or marks do not match the mesh");
  std::vector<size_t> at;
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    const std::array<int, 3>& t = mesh.triangles[f];
    if (moved[static_cast<size_t>(t[0])] || moved[static_cast<size_t>(t[1])] || moved[static_cast<size_t>(t[2])])
      at.push_back(f);
  }
  judge_these(complex, mesh, at, criteria, failing);
  return static_cast<long>(at.size());
}

namespace {

enum class Known : char { nothing, settled, carried };

// Whether the edge a - b kept its length through the step, to 1e-9 A.
bool kept_length(const SurfaceMesh& mesh, const std::vector<Eigen::Vector3d>& before, int a, int b) {
  const size_t i = static_cast<size_t>(a), k = static_cast<size_t>(b);
  return std::abs((mesh.vertices[i] - mesh.vertices[k]).norm() - (before[i] - before[k]).norm()) <= 1e-9;
}

// What `known` says of triangle t (KnownVerdicts).
Known known_of(const SurfaceMesh& mesh, const KnownVerdicts& known, const std::array<int, 3>& t) {
  const auto marked = [&](const std::vector<char>& marks) {
    return marks.size() == mesh.vertices.size() && marks[static_cast<size_t>(t[0])] &&
           marks[static_cast<size_t>(t[1])] && marks[static_cast<size_t>(t[2])];
  };
  if (marked(known.settled)) return Known::settled;
  if (known.carried.size() != mesh.vertices.size() || known.before.size() != mesh.vertices.size()) return Known::nothing;
  for (int v : t)
    if (!known.carried[static_cast<size_t>(v)]) return Known::nothing;
  for (size_t k = 0; k < 3; ++k)
    if (!kept_length(mesh, known.before, t[k], t[(k + 1) % 3])) return Known::nothing;
  return Known::carried;
}

// The verdicts of `mesh`'s triangles as `known` allows (KnownVerdicts),
// into j.failing, j.settled and j.carried.
void judge_known(const SkinComplex& complex, const SurfaceMesh& mesh, const MeshingOptions& criteria,
                 const KnownVerdicts& known, Judged& j) {
  // A carried triangle's shape is judged where its kind is found, in parallel.
  std::vector<Known> kinds(mesh.triangles.size());
  j.failing.assign(mesh.triangles.size(), 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, kinds.size(), 2048), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t f = r.begin(); f != r.end(); ++f) {
      const std::array<int, 3>& t = mesh.triangles[f];
      kinds[f] = known_of(mesh, known, t);
      if (kinds[f] != Known::carried) continue;
      const std::array<Eigen::Vector3d, 3> corners{mesh.vertices[static_cast<size_t>(t[0])],
                                                   mesh.vertices[static_cast<size_t>(t[1])],
                                                   mesh.vertices[static_cast<size_t>(t[2])]};
      j.failing[f] = !shape_passes(corners, criteria.min_angle);
    }
  });
  std::vector<size_t> at;
  for (size_t f = 0; f < kinds.size(); ++f) {
    if (kinds[f] == Known::settled)
      ++j.settled;
    else if (kinds[f] == Known::carried)
      ++j.carried;
    else
      at.push_back(f);
  }
  judge_these(complex, mesh, at, criteria, j.failing);
}

}  // namespace

Judged judge_and_relax(const SkinComplex& complex, SurfaceMesh& mesh, const RelaxationOptions& relaxation,
                       const MeshingOptions& criteria, const KnownVerdicts* known) {
  Judged j;
  auto stage = Clock::now();
  if (known != nullptr)
    judge_known(complex, mesh, criteria, *known, j);
  else
    j.failing = failing_triangles(complex, mesh, mesh.triangles, criteria);
  j.failing_before_relax = std::count(j.failing.begin(), j.failing.end(), 1);
  j.seconds_judge = seconds_since(stage);
  if (j.failing_before_relax == 0 || relaxation.passes == 0) return j;
  stage = Clock::now();
  std::vector<char> corners(mesh.vertices.size(), 0);
  for (size_t f = 0; f < j.failing.size(); ++f)
    if (j.failing[f])
      for (int v : mesh.triangles[f]) corners[static_cast<size_t>(v)] = 1;
  std::vector<std::pair<Eigen::Vector3d, int>> before;  // each corner's place and cell
  for (size_t v = 0; v < corners.size(); ++v)
    if (corners[v]) before.emplace_back(mesh.vertices[v], mesh.cells[v]);
  relax_tangentially(complex, mesh, relaxation, &corners);
  j.seconds_relax = seconds_since(stage);
  stage = Clock::now();
  // Only triangles with a corner the relaxation moved can have changed verdict.
  size_t k = 0;
  for (size_t v = 0; v < corners.size(); ++v)
    if (corners[v]) {
      corners[v] = mesh.vertices[v] != before[k].first || mesh.cells[v] != before[k].second;
      ++k;
    }
  rejudge_moved(complex, mesh, corners, criteria, j.failing);
  j.relaxed = std::move(corners);
  j.seconds_judge += seconds_since(stage);
  return j;
}

}  // namespace skinmesh::detail
