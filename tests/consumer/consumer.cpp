// Meshes a molecule through the installed skinmesh package and checks the
// result on its own: a closed, consistently oriented surface (every directed
// edge once, its twin once) whose smallest angle is at least the bound.
// Exit 0 when it holds.
#include <skinmesh/core/balls.hpp>
#include <skinmesh/core/molecule.hpp>
#include <skinmesh/core/skin_complex.hpp>
#include <skinmesh/mesher/skin_mesher.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <utility>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: consumer MOLECULE\n");
    return 2;
  }
  const skinmesh::Molecule molecule = skinmesh::read_molecule(argv[1]);
  const skinmesh::SkinComplex complex = skinmesh::build_skin_complex(skinmesh::balls_from_molecule(molecule, 0.5));
  skinmesh::MeshingOptions options;
  options.min_angle = 30.0;
  const skinmesh::SkinMeshResult result = skinmesh::mesh_skin(complex, options);
  if (result.status != skinmesh::MeshingStatus::ok) {
    std::fprintf(stderr, "meshing failed: %s\n", result.message.c_str());
    return 1;
  }
  const auto& v = result.mesh.vertices;
  std::map<std::pair<int, int>, int> directed;
  double min_angle = 180;
  for (const auto& t : result.mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      ++directed[{t[k], t[(k + 1) % 3]}];
      const Eigen::Vector3d a = v[t[(k + 1) % 3]] - v[t[k]], b = v[t[(k + 2) % 3]] - v[t[k]];
      min_angle = std::min(min_angle, std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / M_PI);
    }
  }
  for (const auto& [edge, count] : directed) {
    const auto twin = directed.find({edge.second, edge.first});
    if (count != 1 || twin == directed.end() || twin->second != 1) {
      std::fprintf(stderr, "edge %d-%d is not shared by two consistently oriented triangles\n", edge.first,
                   edge.second);
      return 1;
    }
  }
  std::printf("%zu atoms, %zu triangles, smallest angle %.3f deg\n", molecule.atoms.size(),
              result.mesh.triangles.size(), min_angle);
  return result.mesh.triangles.empty() || min_angle < options.min_angle - 1e-9 ? 1 : 0;
}
