// Reading and skin-complex construction, side by side with CGAL's own
// Skin_surface_3 construction (regular triangulation + triangulated mixed
// complex) on the same balls, and the skin's topology counted from the
// weighted alpha complex (skin_topology: the certificate every mesh and
// morph frame is checked against). Each measurement runs in a forked child, so the
// peak memory reported is that task's own.
//
//   bench_complex [--repeat N] [FILE...]     (default: data/1hpv.pdb and data/3mht.pdb)
#include "skinmesh/core/molecule.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/skin_topology.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Skin_surface_3.h>
#include <CGAL/Skin_surface_traits_3.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <iostream>
#include <string>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

using namespace skinmesh;
using Clock = std::chrono::steady_clock;

namespace {

struct Measure {
  double seconds = 0;   // median over repeats
  double peak_mb = 0;   // peak resident memory of the child that ran it
  long count = 0;       // what the task produced (atoms, cells)
};

// Runs task() `repeat` times in one child; the child sends back the median time
// and the count through a pipe; the parent reads the child's peak RSS.
Measure run_in_child(int repeat, const std::function<long()>& task) {
  int fds[2];
  if (pipe(fds) != 0) throw std::runtime_error("pipe failed");
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    std::vector<double> times;
    long count = 0;
    for (int i = 0; i < repeat; ++i) {
      const auto t0 = Clock::now();
      count = task();
      times.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
    }
    std::sort(times.begin(), times.end());
    double out[2] = {times[times.size() / 2], static_cast<double>(count)};
    if (write(fds[1], out, sizeof out) != sizeof out) _exit(1);
    _exit(0);
  }
  close(fds[1]);
  double in[2] = {0, 0};
  const ssize_t got = read(fds[0], in, sizeof in);
  close(fds[0]);
  int status = 0;
  struct rusage usage {};
  wait4(pid, &status, 0, &usage);
  if (got != sizeof in || !WIFEXITED(status) || WEXITSTATUS(status) != 0) throw std::runtime_error("task failed");
  return {in[0], usage.ru_maxrss / 1024.0, static_cast<long>(in[1])};
}

}  // namespace

int main(int argc, char** argv) {
  int repeat = 5;
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--repeat" && i + 1 < argc) repeat = std::max(1, std::atoi(argv[++i]));
    else files.push_back(a);
  }
  if (files.empty())
    files = {std::string(SKINMESH_DATA_DIR) + "/1hpv.pdb", std::string(SKINMESH_DATA_DIR) + "/3mht.pdb"};

  const double s = 0.5;
  struct Row {
    std::string file;
    long atoms;
    long cells;
    Measure read, complex, cgal, topology;
  };
  std::vector<Row> rows;
  for (const std::string& file : files) {
    const Molecule m = read_molecule(file);
    const auto balls = balls_from_molecule(m, s);
    Row row{file, static_cast<long>(m.atoms.size()), 0, {}, {}, {}, {}};
    row.read = run_in_child(repeat, [&] { return static_cast<long>(read_molecule(file).atoms.size()); });
    row.complex = run_in_child(repeat, [&] { return static_cast<long>(build_skin_complex(balls, {s}).cells().size()); });
    row.cells = row.complex.count;
    row.cgal = run_in_child(repeat, [&] {
      using K = CGAL::Exact_predicates_inexact_constructions_kernel;
      std::vector<K::Weighted_point_3> wp;
      for (const Ball& b : balls) wp.emplace_back(K::Point_3(b.center.x(), b.center.y(), b.center.z()), b.weight);
      CGAL::Skin_surface_3<CGAL::Skin_surface_traits_3<K>> skin(wp.begin(), wp.end(), s, false);
      return static_cast<long>(skin.triangulated_mixed_complex().number_of_cells());
    });
    row.topology = run_in_child(repeat, [&] { return skin_topology(balls).euler; });
    std::printf(
        "{\"file\": \"%s\", \"atoms\": %ld, \"repeat\": %d, \"read_seconds\": %.6f, \"read_peak_mb\": %.1f, "
        "\"mixed_cells\": %ld, \"complex_seconds\": %.6f, \"complex_peak_mb\": %.1f, "
        "\"cgal_skin_surface_3_seconds\": %.6f, \"cgal_peak_mb\": %.1f, \"cgal_tmc_cells\": %ld, "
        "\"topology_seconds\": %.6f, \"topology_peak_mb\": %.1f}\n",
        file.c_str(), row.atoms, repeat, row.read.seconds, row.read.peak_mb, row.cells, row.complex.seconds,
        row.complex.peak_mb, row.cgal.seconds, row.cgal.peak_mb, row.cgal.count, row.topology.seconds,
        row.topology.peak_mb);
    std::fflush(stdout);
    rows.push_back(row);
  }
  std::printf("\n| file | atoms | read s | mixed cells | complex s | complex peak MB | CGAL Skin_surface_3 s | CGAL peak MB | topology s |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|\n");
  for (const Row& r : rows) {
    const std::string name = r.file.substr(r.file.find_last_of('/') + 1);
    std::printf("| %s | %ld | %.4f | %ld | %.4f | %.1f | %.3f | %.1f | %.4f |\n", name.c_str(), r.atoms, r.read.seconds,
                r.cells, r.complex.seconds, r.complex.peak_mb, r.cgal.seconds, r.cgal.peak_mb, r.topology.seconds);
  }
  return 0;
}
