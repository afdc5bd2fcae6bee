// The size ladder of the speed-and-scale issue: assemblies of copies of one
// molecule (3mht by default) on a cubic lattice, 1, 8, 27 and 64 copies
// (3,141 to 201,024 heavy atoms for 3mht), far enough apart that their skins
// do not touch, and one assembly whose copies overlap so that they do. Each
// rung is meshed by `mesh_skin` at default options in a forked child (its own
// peak memory, a time limit), with the triangle budget raised and the memory
// limit set to what the machine has available, so that a rung too big for
// the machine is refused by the estimate instead of swapping. After the clock
// stops the child checks every guarantee (check_guarantees: angles, closed
// oriented manifold, no self-intersections, every vertex on the skin by the
// oracle). Prints JSON lines, a markdown table, and the growth of the cost
// per triangle from the smallest rung to the largest one meshed.
//
//   bench_ladder [--copies 1,8,27,64] [--touching 8] [--gap A] [--overlap A] [--timeout S] [FILE]
#include "forked.hpp"

#include "skinmesh/core/molecule.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/mesher/skin_mesher.hpp"
#include "skinmesh/quality/guarantees.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/resource.h>
#include <vector>

using namespace skinmesh;
using Clock = std::chrono::steady_clock;

namespace {

constexpr double kShrink = 0.5;

struct Rung {
  int copies = 1;
  bool touching = false;
};

// What a child sends back (raw bytes through a pipe).
struct Measured {
  int status = 0;  // 0 meshed, 1 refused or stopped by the mesher (see estimate), 2 a guarantee failed
  long atoms = 0, triangles = 0, vertices = 0;
  double estimated_triangles = 0;
  double seconds_complex = 0, seconds_mesh = 0, seconds_check = 0;
  double peak_mb_meshing = 0;  // resident peak when meshing ended, before the check
  double min_angle = 0, max_error = 0;
  long components = 0, genus = 0;
};

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

double peak_rss_mb() {
  struct rusage usage {};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;
}

// MemAvailable of /proc/meminfo, bytes; 0 when unknown (no limit then).
double available_memory_bytes() {
  std::ifstream in("/proc/meminfo");
  std::string key;
  double kilobytes = 0;
  while (in >> key) {
    if (key == "MemAvailable:") {
      in >> kilobytes;
      return kilobytes * 1024.0;
    }
    in.ignore(1 << 10, '\n');
  }
  return 0;
}

// k^3 copies of `balls` on a cubic lattice of pitch `pitch` (Angstrom).
std::vector<Ball> lattice_of(const std::vector<Ball>& balls, int copies, double pitch) {
  const int k = static_cast<int>(std::lround(std::cbrt(copies)));
  std::vector<Ball> out;
  out.reserve(balls.size() * static_cast<size_t>(k * k * k));
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j)
      for (int l = 0; l < k; ++l)
        for (Ball b : balls) {
          b.center += pitch * Eigen::Vector3d(i, j, l);
          out.push_back(b);
        }
  return out;
}

// The largest extent of the molecule's balls along an axis (Angstrom).
double extent_of(const std::vector<Ball>& balls) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (const Ball& b : balls) {
    const double r = std::sqrt(std::max(0.0, b.weight));
    lo = lo.cwiseMin(b.center - Eigen::Vector3d::Constant(r));
    hi = hi.cwiseMax(b.center + Eigen::Vector3d::Constant(r));
  }
  return (hi - lo).maxCoeff();
}

Measured mesh_rung(const std::vector<Ball>& balls) {
  Measured m;
  m.atoms = static_cast<long>(balls.size());
  const auto t0 = Clock::now();
  const SkinComplex complex = build_skin_complex(balls, {kShrink});
  m.seconds_complex = seconds_since(t0);
  MeshingOptions options;
  options.max_triangles = 2'000'000'000L;
  options.max_memory_bytes = available_memory_bytes();
  const auto t1 = Clock::now();
  const SkinMeshResult result = mesh_skin(complex, options);
  m.seconds_mesh = seconds_since(t1);
  m.peak_mb_meshing = peak_rss_mb();
  m.estimated_triangles = result.estimated_triangles;
  if (result.status != MeshingStatus::ok) {
    std::fprintf(stderr, "  %s\n", result.message.c_str());
    m.status = 1;
    return m;
  }
  m.triangles = static_cast<long>(result.mesh.triangles.size());
  m.vertices = static_cast<long>(result.mesh.vertices.size());
  const auto t2 = Clock::now();
  const GuaranteeReport g = check_guarantees(result.mesh, balls, kShrink);
  m.seconds_check = seconds_since(t2);
  m.min_angle = g.quality.min_angle;
  m.max_error = g.surface_error.max;
  m.components = g.quality.components;
  m.genus = g.quality.genus;
  m.status = g.all_hold() ? 0 : 2;
  return m;
}

std::vector<int> parse_list(const std::string& text) {
  std::vector<int> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ','))
    if (!item.empty()) out.push_back(std::atoi(item.c_str()));
  return out;
}

bool is_cube(int n) {
  const int k = static_cast<int>(std::lround(std::cbrt(n)));
  return n > 0 && k * k * k == n;
}

const char* status_name(const bench::Forked<Measured>& f) {
  if (f.status != "ok") return f.status.c_str();
  switch (f.result.status) {
    case 0: return "ok";
    case 1: return "refused";
    default: return "guarantee failed";
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::string file = std::string(SKINMESH_DATA_DIR) + "/3mht.pdb";
  std::vector<int> separate = {1, 8, 27, 64}, touching = {8};
  // 20 A: at 6 A of box overlap no two copies of 3mht met (888 components).
  double gap = 10.0, overlap = 20.0;
  int timeout = 3600;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--copies" && i + 1 < argc) separate = parse_list(argv[++i]);
    else if (a == "--touching" && i + 1 < argc) touching = parse_list(argv[++i]);
    else if (a == "--gap" && i + 1 < argc) gap = std::atof(argv[++i]);
    else if (a == "--overlap" && i + 1 < argc) overlap = std::atof(argv[++i]);
    else if (a == "--timeout" && i + 1 < argc) timeout = std::max(1, std::atoi(argv[++i]));
    else if (!a.empty() && a[0] != '-') file = a;
    else {
      std::fprintf(stderr,
                   "usage: bench_ladder [--copies 1,8,27,64] [--touching 8] [--gap A] [--overlap A] [--timeout S] "
                   "[FILE]\n");
      return 2;
    }
  }
  std::vector<Rung> rungs;
  for (int n : separate) rungs.push_back({n, false});
  for (int n : touching) rungs.push_back({n, true});
  for (const Rung& r : rungs)
    if (!is_cube(r.copies)) {
      std::fprintf(stderr, "bench_ladder: %d copies is not a cube (1, 8, 27, 64, ...)\n", r.copies);
      return 2;
    }
  std::vector<Ball> molecule;
  try {
    molecule = balls_from_molecule(read_molecule(file), kShrink);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_ladder: %s\n", e.what());
    return 1;
  }
  const double extent = extent_of(molecule);
  const std::string name = file.substr(file.find_last_of('/') + 1);
  std::vector<std::pair<Rung, bench::Forked<Measured>>> rows;
  for (const Rung& r : rungs) {
    // Apart: one ball extent plus the gap, so no two copies' skins touch;
    // touching: the extent less the overlap, so neighbours interpenetrate.
    const double pitch = r.touching ? extent - overlap : extent + gap;
    const std::vector<Ball> balls = lattice_of(molecule, r.copies, pitch);
    std::fprintf(stderr, "%s x %d%s (%zu atoms, pitch %.1f A) ...\n", name.c_str(), r.copies,
                 r.touching ? " touching" : "", balls.size(), pitch);
    const auto f = bench::run_forked<Measured>(timeout, [&] { return mesh_rung(balls); });
    const Measured& m = f.result;
    std::printf("{\"molecule\": \"%s\", \"copies\": %d, \"touching\": %s, \"pitch\": %.2f, \"atoms\": %zu, "
                "\"status\": \"%s\", \"estimated_triangles\": %.0f, \"triangles\": %ld, \"seconds_complex\": %.3f, "
                "\"seconds_mesh\": %.3f, \"seconds_check\": %.3f, \"peak_mb_meshing\": %.1f, \"peak_mb\": %.1f, "
                "\"us_per_triangle\": %.3f, \"bytes_per_triangle\": %.0f, \"min_angle\": %.3f, "
                "\"max_on_surface_error\": %.2e, \"components\": %ld, \"genus\": %ld}\n",
                name.c_str(), r.copies, r.touching ? "true" : "false", pitch, balls.size(), status_name(f),
                m.estimated_triangles, m.triangles, m.seconds_complex, m.seconds_mesh, m.seconds_check,
                m.peak_mb_meshing, f.peak_mb,
                m.triangles > 0 ? 1e6 * (m.seconds_complex + m.seconds_mesh) / static_cast<double>(m.triangles) : 0.0,
                m.triangles > 0 ? m.peak_mb_meshing * 1048576.0 / static_cast<double>(m.triangles) : 0.0,
                m.min_angle, m.max_error, m.components, m.genus);
    std::fflush(stdout);
    rows.emplace_back(r, f);
  }

  std::printf("\n| copies | atoms | status | estimate | triangles | complex + mesh s | check s | peak MB (meshing) | "
              "us / triangle | bytes / triangle | min angle | max error A | components |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const auto& [r, f] : rows) {
    const Measured& m = f.result;
    std::printf("| %d%s | %ld | %s | %.0f | %ld | %.1f | %.1f | %.0f | %.2f | %.0f | %.2f | %.1e | %ld |\n", r.copies,
                r.touching ? " touching" : "", m.atoms, status_name(f), m.estimated_triangles, m.triangles,
                m.seconds_complex + m.seconds_mesh, m.seconds_check, m.peak_mb_meshing,
                m.triangles > 0 ? 1e6 * (m.seconds_complex + m.seconds_mesh) / static_cast<double>(m.triangles) : 0.0,
                m.triangles > 0 ? m.peak_mb_meshing * 1048576.0 / static_cast<double>(m.triangles) : 0.0, m.min_angle,
                m.max_error, m.components);
  }
  // Growth of the cost per triangle from the smallest separate rung meshed to the largest.
  const Measured *first = nullptr, *last = nullptr;
  for (const auto& [r, f] : rows)
    if (!r.touching && f.status == "ok" && f.result.status == 0) {
      if (!first || f.result.atoms < first->atoms) first = &f.result;
      if (!last || f.result.atoms > last->atoms) last = &f.result;
    }
  if (first && last && first != last) {
    auto per_triangle = [](const Measured& m) {
      return (m.seconds_complex + m.seconds_mesh) / static_cast<double>(m.triangles);
    };
    std::printf("\ncost per triangle grows %.2fx from %ld to %ld atoms (goal: at most 1.5x)\n",
                per_triangle(*last) / per_triangle(*first), first->atoms, last->atoms);
  }
  return 0;
}
