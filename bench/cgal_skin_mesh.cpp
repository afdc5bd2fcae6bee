// CGAL's skin mesh (Kruithof-Vegter, as make_skin_surface_mesh_3) of a molecule,
// with the same balls as skinmesh (w = r^2/s, s = 1/2), written as OFF, so
// that `skinmesh quality` can grade it next to a skinmesh mesh.
//
//   cgal_skin_mesh MOLECULE OUT.off [--subdivisions N (0-8)] [--jitter A]
//
// --jitter moves every centre by up to A Angstrom per coordinate (fixed seed),
// which CGAL needs on degenerate sets such as the interpolated sets of a morph.
#include "cgal_reference.hpp"
#include "skinmesh/core/molecule.hpp"
#include "skinmesh/mesh_io/mesh_write.hpp"

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

using namespace skinmesh;

int main(int argc, char** argv) {
  const char* usage = "usage: cgal_skin_mesh MOLECULE OUT.off [--subdivisions N (0-8)] [--jitter A]\n";
  if (argc < 3 || argc % 2 == 0) {
    std::fprintf(stderr, "%s", usage);
    return 2;
  }
  const std::string input = argv[1], output = argv[2];
  int subdivisions = 0;
  double jitter = 0;
  for (int i = 3; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    char* end = nullptr;
    const double value = std::strtod(argv[i + 1], &end);
    const bool known = flag == "--jitter" || (flag == "--subdivisions" && value <= 8 && value == static_cast<int>(value));
    if (*end != '\0' || !(value >= 0) || !known) {
      std::fprintf(stderr, "cgal_skin_mesh: bad option %s %s\n%s", argv[i], argv[i + 1], usage);
      return 2;
    }
    if (flag == "--subdivisions") subdivisions = static_cast<int>(value);
    else jitter = value;
  }
  const double s = 0.5;
  SurfaceMesh mesh;
  try {
    std::vector<Ball> balls = balls_from_molecule(read_molecule(input), s);
    if (jitter > 0) balls = test::jittered(balls, jitter);
    mesh = test::cgal_skin_mesh(balls, s, subdivisions);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cgal_skin_mesh: %s\n", e.what());
    return 2;
  }
  const std::string temporary = output + ".partial";
  {
    std::ofstream out(temporary);
    write_mesh(out, mesh, MeshFormat::off, nullptr);
    if (!out) {
      std::fprintf(stderr, "cgal_skin_mesh: cannot write %s\n", output.c_str());
      std::remove(temporary.c_str());
      return 1;
    }
  }
  if (std::rename(temporary.c_str(), output.c_str()) != 0) {
    std::fprintf(stderr, "cgal_skin_mesh: cannot write %s\n", output.c_str());
    return 1;
  }
  std::printf("%s: %zu vertices, %zu triangles\n", output.c_str(), mesh.vertices.size(), mesh.triangles.size());
  return 0;
}
