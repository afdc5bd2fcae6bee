// The morph against per-frame reconstruction (the paper's Table 4, Yan, Cheng
// et al.), side by side in one run, each column in its own forked child:
//   (a) each frame rebuilt from all m*n interpolated balls by CGAL's skin
//       mesher (the paper's baseline; centres jittered by 1e-9 A, which CGAL
//       needs on the cospherical groups of B(t));
//   (b) each frame rebuilt by skinmesh's quality mesher from the live pairs
//       (complex and mesh, at the morph's frame criteria);
//   (c) the morph: the source side meshed once at the first frame, then every
//       later frame transported and repaired (morph/morph.hpp);
//   (c_cmd) the `skinmesh morph --pairs all` command at the same times: the
//       morph with the command's check of every frame and its output (its
//       quality columns are what the command's frames.jsonl says);
//   (d) the floor: one closed-form transport pass (eq. 19) over the frame
//       before's vertices into each later frame's complex, no repair.
// (c) runs every frame; (a) and (b) cost the same at every frame and average
// a sample spread over (0,1). Quality per column is measured with the clock
// stopped: every frame graded (closed, manifold, oriented, self-intersections,
// angles) and every vertex measured by the morph oracle (docs/math.md
// section 4), which knows neither the complex nor the live pairs.
//
//   bench_morph [--frames N] [--sample K] [--timeout S] [--skip-cgal] [--only TEXT]
//               [--neck-surgery on|off] [--birth-surgery on|off] [PAIR...]
//   (--only: run the columns whose name contains TEXT, or one of the
//   comma-separated TEXTs: --only "b skin,c morph,c_cmd"; --neck-surgery,
//   --birth-surgery: RepairPolicy's of the c column, default Morph's)
//   PAIR: SOURCE:TARGET, a file optionally followed by #MODEL
//   (default: pept:3al1, 3al1:1ubi, 1ubi:1hpv, 2k39_3models#1:#3 from data/)
#include "cgal_reference.hpp"
#include "forked.hpp"
#include "morph_pairs.hpp"
#include "skinmesh/core/interpolation.hpp"
#include "skinmesh/core/molecule.hpp"
#include "skinmesh/core/skin_oracle.hpp"
#include "skinmesh/core/stopwatch.hpp"
#include "skinmesh/morph/alignment.hpp"
#include "skinmesh/morph/morph.hpp"
#include "skinmesh/morph/transport.hpp"
#include "skinmesh/quality/mesh_quality.hpp"

#include <nlohmann/json.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using namespace skinmesh;
using bench::Pair;

namespace {

constexpr double kShrink = 0.5;

// One column's frames, accumulated; raw bytes through the child's pipe.
struct Column {
  double frames = 0, seconds = 0, seconds_first = 0, seconds_repair = 0;
  // (c) only: where the later frames' time went (FrameStats), summed.
  double seconds_complex = 0, seconds_transport = 0, seconds_relax = 0, seconds_judge = 0;
  double seconds_edits = 0, seconds_patch = 0, patch_attempts = 0, patched_frames = 0;  // parts of the repair
  double triangles = 0, below_20 = 0, min_angle = 180;
  double max_error = 0, uncertified = 0;
  double invalid_frames = 0;  // not closed, manifold and oriented, or self-intersecting
  double repaired = 0, remeshed = 0, full_rebuilds = 0, inserted = 0, removed = 0, relocated = 0, vertices = 0;

  void grade(const SurfaceMesh& mesh, const MorphOracle& oracle, double t) {
    const MeshQuality q = grade_mesh(mesh);
    frames += 1;
    triangles += static_cast<double>(q.triangles);
    vertices += static_cast<double>(q.vertices);
    below_20 += q.share_below_20 * static_cast<double>(q.triangles);
    min_angle = std::min(min_angle, q.min_angle);
    invalid_frames += !(q.closed && q.manifold && q.oriented && q.self_intersecting_pairs == 0);
    for (const Eigen::Vector3d& v : mesh.vertices) {
      const MorphOracleResult o = oracle.evaluate(v, t);
      max_error = std::max(max_error, o.distance());
      uncertified += !o.certified;
    }
  }
};

std::vector<double> frame_times(int n) {
  std::vector<double> t;
  for (int k = 1; k <= n; ++k) t.push_back(static_cast<double>(k) / (n + 1));
  return t;
}

Column run_morph(const Pair& p, int frames, bool local_repair, const RepairPolicy& surgery) {
  keep_large_blocks_for_reuse();  // as `skinmesh morph` does
  const MorphOracle oracle(p.source, p.target, kShrink);
  const std::vector<double> ts = frame_times(frames);
  Column c;
  const auto start = Clock::now();
  MorphOptions options;
  options.repair.neck_surgery = surgery.neck_surgery;
  options.repair.birth_surgery = surgery.birth_surgery;
  if (!local_repair) {  // c': every failing frame remeshed whole (no edits, no patches)
    options.repair.patch.max_failing_share = 0;
    options.repair.patch.always_patch_up_to = 0;
    options.repair.edits.enabled = false;
  }
  Morph morph = prepare_morph(p.source, p.target, ts.front(), options);
  c.seconds_first = seconds_since(start);
  c.seconds += c.seconds_first;
  c.grade(morph.frame().mesh, oracle, ts.front());
  for (size_t k = 1; k < ts.size(); ++k) {
    const MorphFrame& f = morph.advance_to(ts[k], k + 1 < ts.size() ? ts[k + 1] : -1);
    c.seconds += f.stats.seconds;
    c.seconds_repair += f.stats.seconds_repair;
    c.seconds_complex += f.stats.seconds_complex;
    c.seconds_transport += f.stats.seconds_transport;
    c.seconds_relax += f.stats.seconds_relax;
    c.seconds_judge += f.stats.seconds_judge;
    c.seconds_edits += f.stats.seconds_edits;
    c.seconds_patch += f.stats.seconds_patch;
    c.patch_attempts += static_cast<double>(f.stats.patch_attempts);
    c.patched_frames += f.stats.patch_attempts > 0;
    c.repaired += f.stats.repaired;
    c.remeshed += f.stats.remeshed;
    c.full_rebuilds += f.stats.full_rebuild;
    c.inserted += static_cast<double>(f.stats.inserted);
    c.removed += static_cast<double>(f.stats.removed);
    c.relocated += static_cast<double>(f.stats.relocated);
    c.grade(f.mesh, oracle, ts[k]);
  }
  return c;
}

// (d): the floor, one closed-form transport pass (eq. 19, transport.hpp) over
// the frame before's vertices into each later frame's complex, in parallel as
// the morph does it; the morph itself makes the frames and complexes, off
// the clock. No quality of its own (it makes no frame).
Column run_transport_floor(const Pair& p, int frames) {
  const std::vector<double> ts = frame_times(frames);
  Column c;
  Morph morph = prepare_morph(p.source, p.target, ts.front());
  c.frames = 1;  // the first frame, as the other columns count it
  for (size_t k = 1; k < ts.size(); ++k) {
    const SkinComplex before = morph.complex();
    const SurfaceMesh mesh = morph.frame().mesh;
    morph.advance_to(ts[k], k + 1 < ts.size() ? ts[k + 1] : -1);
    const SkinComplex& after = morph.complex();
    std::vector<Eigen::Vector3d> moved(mesh.vertices.size());
    const auto start = Clock::now();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, moved.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t v = r.begin(); v != r.end(); ++v) moved[v] = transport(before, after, mesh.cells[v], mesh.vertices[v]).point;
    });
    c.seconds += seconds_since(start);
    c.frames += 1;
    c.vertices += static_cast<double>(mesh.vertices.size());
  }
  return c;
}

// (c_cmd): the command's wall time over its frames, into a temporary folder
// removed after; every frame's quality as its frames.jsonl reports it.
Column run_command(const Pair& p, int frames) {
  std::string times;
  for (double t : frame_times(frames)) {
    char text[32];
    std::snprintf(text, sizeof text, "%s%.17g", times.empty() ? "" : ",", t);
    times += text;
  }
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("bench_morph_" + std::to_string(getpid()));
  const std::string command = std::string("'") + SKINMESH_BINARY + "' --quiet morph " + p.command_sides +
                              " --pairs all --t " + times + " -o '" + dir.string() + "'";
  const auto start = Clock::now();
  const int status = std::system(command.c_str());
  Column c;
  c.seconds = seconds_since(start);
  std::ifstream jsonl(dir / "frames.jsonl");
  for (std::string line; std::getline(jsonl, line);) {
    const nlohmann::json f = nlohmann::json::parse(line);
    c.frames += 1;
    c.triangles += f["triangles"].get<double>();
    c.vertices += f["vertices"].get<double>();
    c.min_angle = std::min(c.min_angle, f["min_angle"].get<double>());
    c.below_20 += f["share_below_bound"].get<double>() * f["triangles"].get<double>();
    c.max_error = std::max(c.max_error, f["max_onsurf_error"].get<double>());
    c.uncertified += f["oracle_uncertified"].get<double>();
    c.repaired += f["repaired"].get<bool>();
    c.full_rebuilds += f["full_rebuild"].get<bool>();
    c.remeshed += f["remeshed"].get<bool>();
  }
  std::filesystem::remove_all(dir);
  if (status != 0 || c.frames != frames) throw std::runtime_error("the command failed: " + command.substr(0, 200));
  return c;
}

// (b): the complex of B(t) from the live pairs and the quality mesh of it.
Column run_rebuilds(const Pair& p, int sample) {
  const MorphOracle oracle(p.source, p.target, kShrink);
  const std::vector<BallPair> pairs = live_pairs(p.source, p.target);
  const MeshingOptions criteria = MorphOptions{}.frames;
  Column c;
  for (double t : frame_times(sample)) {
    const auto start = Clock::now();
    const SkinComplex complex = build_skin_complex(interpolated_balls(p.source, p.target, pairs, t), {kShrink});
    SkinMeshResult made = mesh_skin(complex, criteria);
    c.seconds += seconds_since(start);
    if (made.status != MeshingStatus::ok) throw std::runtime_error(made.message);
    c.full_rebuilds += 1;
    c.grade(made.mesh, oracle, t);
  }
  return c;
}

// (a): CGAL's skin mesher on all m*n interpolated balls, jittered.
Column run_cgal(const Pair& p, int sample) {
  const MorphOracle oracle(p.source, p.target, kShrink);
  const std::vector<BallPair> pairs = all_pairs(p.source.size(), p.target.size());
  Column c;
  for (double t : frame_times(sample)) {
    const auto start = Clock::now();
    const std::vector<Ball> balls = test::jittered(interpolated_balls(p.source, p.target, pairs, t));
    const SurfaceMesh mesh = test::cgal_skin_mesh(balls, kShrink, 0);
    c.seconds += seconds_since(start);
    c.full_rebuilds += 1;
    c.grade(mesh, oracle, t);
  }
  return c;
}

struct Row {
  std::string pair, column;
  bench::Forked<Column> run;
};

// Milliseconds per frame after the first (the morph's stage times; zero for
// the rebuild columns, which have no later frames of their own).
double later_ms(const Column& c, double seconds) { return c.frames > 1 ? 1e3 * seconds / (c.frames - 1) : 0.0; }

void print_json(const Row& r, const Pair& p) {
  const Column& c = r.run.result;
  const double n = std::max(1.0, c.frames);
  std::printf(
      "{\"pair\": \"%s\", \"source_atoms\": %zu, \"target_atoms\": %zu, \"alignment\": \"%s\", \"column\": \"%s\", "
      "\"status\": \"%s\", \"frames\": %.0f, \"seconds_per_frame\": %.4f, \"seconds_first_frame\": %.3f, "
      "\"seconds_repair_per_frame\": %.4f, \"peak_mb\": %.1f, \"mean_triangles\": %.0f, \"min_angle\": %.3f, "
      "\"share_below_20\": %.6f, \"max_on_surface_error\": %.3e, \"uncertified\": %.0f, \"invalid_frames\": %.0f, "
      "\"repaired_frames\": %.0f, \"remeshed_frames\": %.0f, \"full_rebuilds\": %.0f, \"inserted_per_frame\": %.1f, "
      "\"removed_per_frame\": %.1f, \"relocated_per_frame\": %.1f, \"mean_vertices\": %.0f, "
      "\"later_frame_ms\": {\"complex\": %.3f, \"transport\": %.3f, \"relax\": %.3f, \"judge\": %.3f, "
      "\"repair\": %.3f, \"of_repair_edits\": %.3f, \"of_repair_patch\": %.3f, \"whole\": %.3f}, "
      "\"patched_frames\": %.0f, \"patch_attempts\": %.0f}\n",
      r.pair.c_str(), p.source.size(), p.target.size(), p.alignment.c_str(), r.column.c_str(),
      r.run.status.c_str(), c.frames, c.seconds / n, c.seconds_first, c.seconds_repair / n, r.run.peak_mb,
      c.triangles / n, c.min_angle, c.below_20 / std::max(1.0, c.triangles), c.max_error, c.uncertified,
      c.invalid_frames, c.repaired, c.remeshed, c.full_rebuilds, c.inserted / n, c.removed / n, c.relocated / n,
      c.vertices / n, later_ms(c, c.seconds_complex), later_ms(c, c.seconds_transport),
      later_ms(c, c.seconds_relax), later_ms(c, c.seconds_judge), later_ms(c, c.seconds_repair),
      later_ms(c, c.seconds_edits), later_ms(c, c.seconds_patch), later_ms(c, c.seconds - c.seconds_first),
      c.patched_frames, c.patch_attempts);
  std::fflush(stdout);
}

double per_frame(const Row* r) {
  return r && r->run.status == "ok" ? r->run.result.seconds / std::max(1.0, r->run.result.frames) : NAN;
}

// Where a later frame of (c) goes, and what a/c and b/c could be at most if
// every repair were free: transport and judging run on every frame before any
// repair (the "transport every vertex, watch every triangle"), and
// relaxation, without which far more triangles fail (docs/morph.md).
void print_stage_table(const std::vector<Row>& rows) {
  // other: the wait for the complex moved ahead (advance_to's next_t) and the bookkeeping between stages.
  std::printf("\n| pair | c ms/frame | complex | transport | relax | judge | repair | other | a/c, free repairs | "
              "b/c, free repairs | b/c, free repairs and relaxation |\n|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Row& r : rows) {
    if (r.column != "c morph" || r.run.status != "ok") continue;
    const Row *a = nullptr, *b = nullptr;
    for (const Row& other : rows)
      if (other.pair == r.pair) {
        if (other.column.rfind("a ", 0) == 0) a = &other;
        if (other.column.rfind("b ", 0) == 0) b = &other;
      }
    const Column& c = r.run.result;
    const double watch = later_ms(c, c.seconds_transport + c.seconds_judge), relax = later_ms(c, c.seconds_relax);
    const double a_ms = 1e3 * per_frame(a), b_ms = 1e3 * per_frame(b), whole = later_ms(c, c.seconds - c.seconds_first);
    const double complex = later_ms(c, c.seconds_complex), repair = later_ms(c, c.seconds_repair);
    std::printf("| %s | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.0f | %.1f | %.1f |\n", r.pair.c_str(),
                whole, complex, later_ms(c, c.seconds_transport), relax, later_ms(c, c.seconds_judge), repair,
                whole - complex - watch - relax - repair, a_ms / (watch + relax), b_ms / (watch + relax), b_ms / watch);
  }
}

void print_table(const std::vector<Row>& rows, int timeout) {
  std::printf("\n| pair | column | frames | s/frame | peak MB | triangles | min angle | <20 deg | max error A | "
              "invalid frames | repaired | remeshed | full rebuilds |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Row& r : rows) {
    const Column& c = r.run.result;
    if (r.run.status != "ok") {
      std::printf("| %s | %s | %s (limit %d s) | | | | | | | | | | |\n", r.pair.c_str(), r.column.c_str(),
                  r.run.status.c_str(), timeout);
      continue;
    }
    const double n = std::max(1.0, c.frames);
    if (r.column.rfind("d ", 0) == 0) {  // no frames of its own: time only, over the later frames
      std::printf("| %s | %s | %.0f | %.6f | %.0f | | | | | | | | |\n", r.pair.c_str(), r.column.c_str(), c.frames - 1,
                  later_ms(c, c.seconds) / 1e3, r.run.peak_mb);
      continue;
    }
    std::printf("| %s | %s | %.0f | %.4f | %.0f | %.0f | %.2f | %.3f%% | %.1e | %.0f | %.0f | %.0f | %.0f |\n",
                r.pair.c_str(), r.column.c_str(), c.frames, c.seconds / n, r.run.peak_mb, c.triangles / n,
                c.min_angle, 100 * c.below_20 / std::max(1.0, c.triangles), c.max_error, c.invalid_frames,
                c.repaired, c.remeshed, c.full_rebuilds);
  }
  std::printf("\n| pair | a/c | b/c | b/c_cmd | c_cmd/c | c/d |\n|---|---|---|---|---|---|\n");
  for (size_t i = 0; i < rows.size(); ++i) {
    if (rows[i].column != "c morph") continue;
    const Row *a = nullptr, *b = nullptr, *cmd = nullptr, *d = nullptr;
    for (const Row& r : rows)
      if (r.pair == rows[i].pair) {
        if (r.column.rfind("a ", 0) == 0) a = &r;
        if (r.column.rfind("b ", 0) == 0) b = &r;
        if (r.column.rfind("c_cmd ", 0) == 0) cmd = &r;
        if (r.column.rfind("d ", 0) == 0) d = &r;
      }
    const double c = per_frame(&rows[i]);
    // c and d per later frame: the first frame is meshed from scratch and has no transport.
    const double c_later = later_ms(rows[i].run.result, rows[i].run.result.seconds - rows[i].run.result.seconds_first);
    const double d_later = d && d->run.status == "ok" ? later_ms(d->run.result, d->run.result.seconds) : NAN;
    std::printf("| %s | %.1f | %.1f | %.1f | %.2f | %.0f |\n", rows[i].pair.c_str(), per_frame(a) / c, per_frame(b) / c,
                per_frame(b) / per_frame(cmd), per_frame(cmd) / c, c_later / d_later);
  }
  print_stage_table(rows);
}

// Whether `name` contains one of the comma-separated texts of `list`.
bool names_any(const std::string& name, const std::string& list) {
  size_t from = 0;
  while (from <= list.size()) {
    const size_t comma = std::min(list.find(',', from), list.size());
    const std::string text = list.substr(from, comma - from);
    if (!text.empty() && name.find(text) != std::string::npos) return true;
    from = comma + 1;
  }
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  int frames = 100, sample = 5, timeout = 3600;
  bool cgal = true;
  RepairPolicy surgery;  // the c column's neck_surgery and birth_surgery
  std::string only;
  std::vector<std::string> specs;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--frames" && i + 1 < argc) frames = std::max(2, std::atoi(argv[++i]));
    else if (a == "--sample" && i + 1 < argc) sample = std::max(1, std::atoi(argv[++i]));
    else if (a == "--timeout" && i + 1 < argc) timeout = std::max(1, std::atoi(argv[++i]));
    else if (a == "--skip-cgal") cgal = false;
    else if (a == "--only" && i + 1 < argc) only = argv[++i];
    else if (a == "--neck-surgery" && i + 1 < argc) surgery.neck_surgery = std::string(argv[++i]) == "on";
    else if (a == "--birth-surgery" && i + 1 < argc) surgery.birth_surgery = std::string(argv[++i]) == "on";
    else if (!a.empty() && a[0] == '-') {
      std::fprintf(stderr, "usage: bench_morph [--frames N] [--sample K] [--timeout S] [--skip-cgal] [--only TEXT] "
                           "[--neck-surgery on|off] [--birth-surgery on|off] [PAIR...]\n");
      return 2;
    } else specs.push_back(a);
  }
  const std::string d = SKINMESH_DATA_DIR;
  if (specs.empty())
    specs = {d + "/pept.pdb:" + d + "/3al1.pdb", d + "/3al1.pdb:" + d + "/1ubi.pdb", d + "/1ubi.pdb:" + d + "/1hpv.pdb",
             d + "/2k39_3models.pdb#1:#3"};
  std::vector<Row> rows;
  for (const std::string& spec : specs) {
    Pair p;
    try {
      p = bench::load_pair(spec, kShrink);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "bench_morph: %s\n", e.what());
      return 1;
    }
    std::vector<std::pair<std::string, std::function<Column()>>> columns;
    if (cgal) columns.emplace_back("a CGAL skin, all m*n pairs", [&] { return run_cgal(p, sample); });
    columns.emplace_back("b skinmesh rebuild, live pairs", [&] { return run_rebuilds(p, sample); });
    columns.emplace_back("c morph", [&] { return run_morph(p, frames, true, surgery); });
    columns.emplace_back("c' morph, whole-frame repairs only", [&] { return run_morph(p, frames, false, RepairPolicy{}); });
    columns.emplace_back("c_cmd skinmesh morph --pairs all", [&] { return run_command(p, frames); });
    columns.emplace_back("d transport pass (floor)", [&] { return run_transport_floor(p, frames); });
    for (const auto& [name, task] : columns) {
      if (!only.empty() && !names_any(name, only)) continue;
      std::fprintf(stderr, "%s: %s ...\n", p.name.c_str(), name.c_str());
      Row row{p.name, name, bench::run_forked<Column>(timeout, task)};
      print_json(row, p);
      rows.push_back(row);
    }
  }
  print_table(rows, timeout);
  return 0;
}
