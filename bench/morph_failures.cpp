// Why a morph's transported triangles fail: from a frame at t0 (meshed as
// prepare_morph does), one step of each size is taken as advance_to takes
// it (every vertex transported in its cell, eq. 19, or projected onto the
// new skin where it left its cell; then relaxed, relaxation.hpp, with the
// morph's passes or --relax N), and every triangle is judged by the
// frame criteria (the mesher's public restricted_triangle and
// triangle_defect, at the morph's default 20 degrees). Counts per defect,
// as JSON lines and a table. A diagnostic for docs/morph.md, not a timing.
//
//   morph_failures [--t0 T] [--steps S,S,...] [--repeat N] [PAIR]
//   PAIR: SOURCE:TARGET as bench_morph takes it (default: pept:3al1 from data/)
//   --repeat N: N steps of each size in a row (the frame advanced between them)
//   --relax N: N passes of tangential relaxation after transport (0: none)
#include "morph_pairs.hpp"

#include "skinmesh/core/interpolation.hpp"
#include "skinmesh/morph/morph.hpp"
#include "skinmesh/morph/relaxation.hpp"
#include "skinmesh/morph/transport.hpp"

#include <cstdio>
#include <cstdlib>
#include <map>
#include <sstream>
#include <string>
#include <vector>

using namespace skinmesh;

namespace {

constexpr double kShrink = 0.5;

struct StepCounts {
  double t0 = 0, t1 = 0;
  long triangles = 0, relocated = 0;
  std::map<std::string, long> defects;  // "none", "no crossing", "topology", "size", "distance", "shape"
};

// The frame's mesh moved to t1 as Morph::advance_to moves it, then judged.
StepCounts judge_step(const Morph& morph, const bench::Pair& p, double t1, const MeshingOptions& frames,
                      const RelaxationOptions& relaxation) {
  const SkinComplex& from = morph.complex();
  const SkinComplex to = from.with_balls(interpolated_balls(p.source, p.target, morph.pairs(), t1));
  SurfaceMesh mesh = morph.frame().mesh;
  StepCounts c;
  c.t0 = morph.t();
  c.t1 = t1;
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    const TransportedPoint moved = transport(from, to, mesh.cells[v], mesh.vertices[v]);
    if (moved.status == TransportStatus::in_cell) {
      mesh.vertices[v] = moved.point;
      continue;
    }
    ++c.relocated;
    const Eigen::Vector3d start = moved.status == TransportStatus::size_vanished ? mesh.vertices[v] : moved.point;
    const Projection projected = to.project(start, mesh.cells[v], 1e-14);
    mesh.vertices[v] = projected.point;
    mesh.cells[v] = projected.cell;
  }
  for (size_t v = 0; v < mesh.vertices.size(); ++v)
    mesh.normals[v] = to.evaluate(mesh.vertices[v], mesh.cells[v]).gradient.normalized();
  if (relaxation.passes > 0) relax_tangentially(to, mesh, relaxation);
  for (const auto& t : mesh.triangles) {
    const std::array<Eigen::Vector3d, 3> corners{mesh.vertices[static_cast<size_t>(t[0])],
                                                 mesh.vertices[static_cast<size_t>(t[1])],
                                                 mesh.vertices[static_cast<size_t>(t[2])]};
    const auto restricted = restricted_triangle(to, corners, frames.tolerance, mesh.cells[static_cast<size_t>(t[0])]);
    ++c.defects[restricted ? triangle_defect_name(triangle_defect(to, *restricted, frames)) : "no crossing"];
    ++c.triangles;
  }
  return c;
}

std::vector<double> parse_list(const std::string& text) {
  std::vector<double> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) out.push_back(std::atof(item.c_str()));
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  double t0 = 0.3;
  std::vector<double> steps{0.01, 0.001, 0.0001};
  int repeat = 3;
  int relax = -1;  // passes of tangential relaxation after transport; -1: the morph's default
  std::string spec = std::string(SKINMESH_DATA_DIR) + "/pept.pdb:" + SKINMESH_DATA_DIR + "/3al1.pdb";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--t0" && i + 1 < argc) t0 = std::atof(argv[++i]);
    else if (a == "--steps" && i + 1 < argc) steps = parse_list(argv[++i]);
    else if (a == "--relax" && i + 1 < argc) relax = std::atoi(argv[++i]);
    else if (a == "--repeat" && i + 1 < argc) repeat = std::max(1, std::atoi(argv[++i]));
    else if (a.find(':') != std::string::npos) spec = a;
    else {
      std::fprintf(stderr, "usage: morph_failures [--t0 T] [--steps S,S,...] [--repeat N] [--relax PASSES] [SOURCE:TARGET]\n");
      return 2;
    }
  }
  const bench::Pair p = bench::load_pair(spec, kShrink);
  MorphOptions options;
  if (relax >= 0) options.relaxation.passes = relax;
  const char* kinds[] = {"none", "no crossing", "topology", "size", "distance", "shape"};
  std::vector<StepCounts> rows;
  for (double step : steps) {
    Morph morph = prepare_morph(p.source, p.target, t0, options);
    for (int k = 0; k < repeat && morph.t() + step < 1; ++k) {
      rows.push_back(judge_step(morph, p, morph.t() + step, options.frames, options.relaxation));
      morph.advance_to(morph.t() + step);
    }
  }
  for (const StepCounts& c : rows) {
    std::printf("{\"pair\":\"%s\",\"alignment\":\"%s\",\"t0\":%.6f,\"t1\":%.6f,\"triangles\":%ld,\"relocated\":%ld,\"relax_passes\":%d",
                p.name.c_str(), p.alignment.c_str(), c.t0, c.t1, c.triangles, c.relocated, options.relaxation.passes);
    for (const char* kind : kinds) std::printf(",\"%s\":%ld", kind, c.defects.count(kind) ? c.defects.at(kind) : 0L);
    std::printf("}\n");
  }
  std::printf("\n| step | from t | triangles | vertices relocated | failing | no crossing | topology | size | distance | shape |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  for (const StepCounts& c : rows) {
    auto n = [&](const char* kind) { return c.defects.count(kind) ? c.defects.at(kind) : 0L; };
    std::printf("| %g | %.4f | %ld | %ld | %ld (%.2f%%) | %ld | %ld | %ld | %ld | %ld |\n", c.t1 - c.t0, c.t0, c.triangles,
                c.relocated, c.triangles - n("none"), 100.0 * static_cast<double>(c.triangles - n("none")) / static_cast<double>(c.triangles),
                n("no crossing"), n("topology"), n("size"), n("distance"), n("shape"));
  }
  return 0;
}
