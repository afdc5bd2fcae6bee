// The triangle and memory estimate (triangle_estimate.hpp) against what the
// mesher then makes: for each molecule and each set of sizes, the skin's area
// from the profile, the estimate and its time, then mesh_skin in a forked
// child (its triangles, time and peak memory). Prints JSON lines, then a
// markdown table. This is the calibration behind the estimate's constants.
//
//   bench_estimate [--timeout S] [--shrink s] [--directions N,N,...] [FILE...]
//   (--directions: only the profile, at each number of directions per cell:
//   its area and estimate and their time, to see how they converge)
//   (default files: data/pept.pdb, data/1ubi.pdb, data/1hpv.pdb, data/3al1.pdb, data/3mht.pdb)
#include "forked.hpp"
#include "skinmesh/core/balls.hpp"
#include "skinmesh/core/molecule.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/stopwatch.hpp"
#include "skinmesh/mesher/skin_mesher.hpp"
#include "skinmesh/mesher/triangle_estimate.hpp"

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using namespace skinmesh;

namespace {

struct Sizes {
  const char* name;
  MeshingOptions options;
};

MeshingOptions sized(double epsilon, double tolerance, double edge_length = 0) {
  MeshingOptions o;
  o.sizing.epsilon = epsilon;
  o.tolerance = tolerance;
  o.edge_length = edge_length;
  return o;
}

// The default, finer and capped (the size bound binds), coarser, and tighter
// (the distance bound binds).
std::vector<Sizes> size_variants() {
  return {{"default", {}},
          {"epsilon 0.4", sized(0.4, 0.1)},
          {"edge 0.5", sized(0.8, 0.1, 0.5)},
          {"epsilon 1.5, tol 1", sized(1.5, 1.0)},
          {"tolerance 0.01", sized(0.8, 0.01)}};
}

struct Meshed {
  double triangles = 0, seconds = 0;
};

struct Row {
  std::string file, sizes, status;
  double area = 0, cells_with_skin = 0, profile_seconds = 0, estimate = 0, size_bound = 0, distance_bound = 0, estimated_mb = 0;
  double triangles = 0, mesh_seconds = 0, peak_mb = 0;
};

void print_json(const Row& r) {
  std::printf(
      "{\"file\":\"%s\",\"sizes\":\"%s\",\"status\":\"%s\",\"area\":%.6g,\"cells_with_skin\":%.0f,\"profile_seconds\":%.4f,"
      "\"estimate\":%.0f,\"size_bound\":%.0f,\"distance_bound\":%.0f,\"estimated_mb\":%.1f,\"triangles\":%.0f,\"ratio\":%.4f,\"mesh_seconds\":%.3f,"
      "\"peak_mb\":%.1f,\"bytes_per_triangle\":%.0f}\n",
      r.file.c_str(), r.sizes.c_str(), r.status.c_str(), r.area, r.cells_with_skin, r.profile_seconds, r.estimate, r.size_bound, r.distance_bound, r.estimated_mb,
      r.triangles, r.triangles / r.estimate, r.mesh_seconds, r.peak_mb, r.peak_mb * 1048576.0 / r.triangles);
  std::fflush(stdout);
}

// The profile alone at several numbers of directions per cell.
int converge(const std::vector<std::string>& files, const std::vector<int>& directions, double shrink) {
  std::printf("| molecule | directions per cell | skin area (A^2) | estimate (default sizes) | seconds |\n|---|---|---|---|---|\n");
  for (const std::string& file : files) {
    const SkinComplex complex = build_skin_complex(balls_from_molecule(read_molecule(file), shrink), {shrink});
    for (int n : directions) {
      const auto start = Clock::now();
      const SkinAreaProfile profile = skin_area_profile(complex, {n});
      const double seconds = seconds_since(start);
      std::printf("| %s | %d | %.2f | %.0f | %.3f |\n", file.substr(file.find_last_of('/') + 1).c_str(), n,
                  profile.area, estimate_triangles(profile, {}).triangles, seconds);
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  int timeout = 600;
  double shrink = 0.5;
  std::vector<std::string> files;
  std::vector<int> directions;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--timeout" && i + 1 < argc) timeout = std::atoi(argv[++i]);
    else if (arg == "--shrink" && i + 1 < argc) shrink = std::atof(argv[++i]);
    else if (arg == "--directions" && i + 1 < argc)
      for (const char* p = argv[++i]; *p;) {
        char* end = nullptr;
        directions.push_back(static_cast<int>(std::strtol(p, &end, 10)));
        p = *end == ',' ? end + 1 : end;
      }
    else files.push_back(arg);
  }
  if (files.empty())
    for (const char* name : {"pept.pdb", "1ubi.pdb", "1hpv.pdb", "3al1.pdb", "3mht.pdb"})
      files.push_back(std::string(SKINMESH_DATA_DIR) + "/" + name);
  if (!directions.empty()) return converge(files, directions, shrink);
  std::vector<Row> rows;
  for (const std::string& file : files) {
    const auto balls = balls_from_molecule(read_molecule(file), shrink);
    const SkinComplex complex = build_skin_complex(balls, {shrink});
    const auto start = Clock::now();
    const SkinAreaProfile profile = skin_area_profile(complex);
    const double profile_seconds = seconds_since(start);
    for (const Sizes& variant : size_variants()) {
      Row row;
      row.file = file.substr(file.find_last_of('/') + 1) + (shrink != 0.5 ? " s=" + std::to_string(shrink) : "");
      row.sizes = variant.name;
      row.area = profile.area;
      row.cells_with_skin = static_cast<double>(profile.cells_with_skin);
      row.profile_seconds = profile_seconds;
      const TriangleEstimate estimate = estimate_triangles(profile, variant.options);
      row.estimate = estimate.triangles;
      row.size_bound = estimate.size_bound;
      row.distance_bound = estimate.distance_bound;
      row.estimated_mb = estimate.peak_bytes / 1048576.0;
      MeshingOptions options = variant.options;
      options.max_triangles = 40'000'000;
      const auto run = bench::run_forked<Meshed>(timeout, [&] {
        const auto t0 = Clock::now();
        const SkinMeshResult result = mesh_skin(complex, options);
        if (result.status != MeshingStatus::ok) throw std::runtime_error(result.message);
        return Meshed{static_cast<double>(result.mesh.triangles.size()), seconds_since(t0)};
      });
      row.status = run.status;
      row.triangles = run.result.triangles;
      row.mesh_seconds = run.result.seconds;
      row.peak_mb = run.peak_mb;
      print_json(row);
      rows.push_back(row);
    }
  }
  std::printf("\n| molecule | sizes | skin area (A^2) | profile s | estimate | triangles | triangles / estimate | "
              "mesh s | peak MB | estimated MB |\n|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Row& r : rows)
    std::printf("| %s | %s | %.0f | %.3f | %.0f | %.0f | %.3f | %.2f | %.0f | %.0f |\n", r.file.c_str(),
                r.sizes.c_str(), r.area, r.profile_seconds, r.estimate, r.triangles, r.triangles / r.estimate,
                r.mesh_seconds, r.peak_mb, r.estimated_mb);
  return 0;
}
