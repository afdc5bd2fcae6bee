#include "fuzz_input.hpp"

#include "skinmesh/core/balls.hpp"
#include "skinmesh/core/error.hpp"
#include "skinmesh/core/molecule.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/mesh_io/mesh_read.hpp"
#include "skinmesh/quality/mesh_quality.hpp"
#include "skinmesh/quality/tet_quality.hpp"

#include <algorithm>
#include <fstream>
#include <stdexcept>

namespace skinmesh::fuzz {

namespace {

// Bounds that keep one execution in milliseconds; the readers' own limits
// are what is fuzzed, these only cap the work done after them.
constexpr size_t kMaxAtomsForComplex = 300;
constexpr size_t kMaxTrianglesGraded = 5000;
constexpr long long kMaxMoleculeBytes = 1 << 22;

void write_file(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// The input cut at its first `parts - 1` NUL bytes (missing parts empty).
std::vector<std::string> split_at_nul(const std::string& text, size_t parts) {
  std::vector<std::string> out;
  size_t start = 0;
  while (out.size() + 1 < parts) {
    const size_t nul = text.find('\0', start);
    if (nul == std::string::npos) break;
    out.push_back(text.substr(start, nul - start));
    start = nul + 1;
  }
  out.push_back(text.substr(std::min(start, text.size())));
  out.resize(parts);
  return out;
}

void grade(const SurfaceMesh& mesh) {
  GradeOptions options;
  if (mesh.triangles.size() > kMaxTrianglesGraded) options.self_intersections = SelfIntersectionCheck::skip;
  grade_mesh(mesh, options);
}

void read_molecule_input(const std::string& path) {
  ReadOptions options;
  options.max_bytes = kMaxMoleculeBytes;
  const Molecule m = read_molecule(path, options);
  if (m.atoms.size() <= kMaxAtomsForComplex) build_skin_complex(balls_from_molecule(m, 0.5));
}

}  // namespace

const std::vector<FuzzTarget>& fuzz_targets() {
  static const std::vector<FuzzTarget> targets = {
      {"pdb", ".pdb", InputKind::molecule},     {"mmcif", ".cif", InputKind::molecule},
      {"pqr", ".pqr", InputKind::molecule},     {"xyzr", ".xyzr", InputKind::molecule},
      {"wpts", ".wpts", InputKind::molecule},   {"gzip", ".pdb.gz", InputKind::molecule},
      {"off", ".off", InputKind::mesh},         {"ply_ascii", ".ply", InputKind::mesh},
      {"ply_binary", ".ply", InputKind::mesh},  {"obj", ".obj", InputKind::mesh},
      {"stl", ".stl", InputKind::mesh},         {"gmsh", ".msh", InputKind::gmsh},
      {"msms", ".vert", InputKind::msms},       {"tetgen", ".node", InputKind::tetgen},
  };
  return targets;
}

const FuzzTarget& fuzz_target(const std::string& name) {
  for (const FuzzTarget& t : fuzz_targets())
    if (t.name == name) return t;
  throw std::out_of_range("no fuzz target " + name);
}

void read_fuzz_input(const FuzzTarget& target, const uint8_t* data, size_t size, const std::string& folder) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  const std::string stem = folder + "/input";
  try {
    switch (target.kind) {
      case InputKind::molecule:
        write_file(stem + target.extension, bytes);
        read_molecule_input(stem + target.extension);
        break;
      case InputKind::mesh:
        write_file(stem + target.extension, bytes);
        grade(read_surface_mesh(stem + target.extension));
        break;
      case InputKind::gmsh: {
        write_file(stem + target.extension, bytes);
        const TetMesh m = read_gmsh_volume(stem + target.extension);
        if (!m.tets.empty()) {
          grade_tet_mesh(m);
        } else {  // a surface mesh in Gmsh's format, graded as `quality` does
          SurfaceMesh surface;
          surface.vertices = m.points;
          surface.triangles = m.faces;
          grade(surface);
        }
        break;
      }
      case InputKind::msms: {
        const auto parts = split_at_nul(bytes, 2);
        write_file(stem + ".vert", parts[0]);
        write_file(stem + ".face", parts[1]);
        grade(read_surface_mesh(stem + ".vert"));
        break;
      }
      case InputKind::tetgen: {
        const auto parts = split_at_nul(bytes, 3);
        write_file(stem + ".node", parts[0]);
        write_file(stem + ".ele", parts[1]);
        write_file(stem + ".face", parts[2]);
        grade_tet_mesh(read_tet_mesh(stem + ".node"));
        break;
      }
    }
  } catch (const Error&) {
    // A refusal with the project's error is the right answer to bad input.
  }
}

}  // namespace skinmesh::fuzz
