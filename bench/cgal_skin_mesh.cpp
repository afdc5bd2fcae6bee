// CGAL's skin mesh (make_skin_surface_mesh_3, Kruithof-Vegter) of a molecule,
// with the same balls as skinmesh (w = r^2/s, s = 1/2), written as OFF, so
// that `skinmesh quality` can grade it next to a skinmesh mesh.
//
//   cgal_skin_mesh MOLECULE OUT.off [--subdivisions N]
#include "cgal_reference.hpp"
#include "skinmesh/core/molecule.hpp"
#include "skinmesh/meshing/mesh_write.hpp"

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

using namespace skinmesh;

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: cgal_skin_mesh MOLECULE OUT.off [--subdivisions N]\n");
    return 2;
  }
  const std::string input = argv[1], output = argv[2];
  int subdivisions = 0;
  if (argc >= 5 && std::string(argv[3]) == "--subdivisions") subdivisions = std::atoi(argv[4]);
  const double s = 0.5;
  SurfaceMesh mesh;
  try {
    mesh = test::cgal_skin_mesh(balls_from_molecule(read_molecule(input), s), s, subdivisions);
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
