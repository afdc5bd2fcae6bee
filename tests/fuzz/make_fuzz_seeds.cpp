// The fuzz targets' seed corpora, made from data/ and the project's own
// writers: fuzz_seeds DATA_DIR OUT_DIR writes OUT_DIR/<target>/<seed> for
// every target of fuzz_input.hpp. Seeds are small (a few atoms, a few
// hundred triangles) so that each execution stays fast.
#include "fuzz_input.hpp"

#include "skinmesh/core/balls.hpp"
#include "skinmesh/core/molecule.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/mesh_io/mesh_write.hpp"
#include "skinmesh/mesh_io/tet_write.hpp"
#include "skinmesh/mesher/skin_mesher.hpp"

#include <zlib.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <sstream>

namespace fs = std::filesystem;
using namespace skinmesh;

namespace {

std::string text_of(const std::function<void(std::ostream&)>& write) {
  std::ostringstream out;
  write(out);
  return out.str();
}

std::string file_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void put(const fs::path& out, const std::string& target, const std::string& name, const std::string& bytes) {
  fs::create_directories(out / target);
  std::ofstream(out / target / name, std::ios::binary) << bytes;
}

// The first `atoms` ATOM/HETATM records of a PDB file, with its END.
std::string pdb_head(const std::string& text, int atoms) {
  std::istringstream in(text);
  std::string line, out;
  while (atoms > 0 && std::getline(in, line)) {
    out += line + "\n";
    if (line.rfind("ATOM", 0) == 0 || line.rfind("HETATM", 0) == 0) --atoms;
  }
  return out + "END\n";
}

std::string mmcif_of(const Molecule& m, size_t atoms) {
  std::ostringstream out;
  out << "data_seed\nloop_\n";
  for (const char* column : {"group_PDB", "id", "type_symbol", "label_atom_id", "label_alt_id", "label_comp_id",
                             "label_asym_id", "label_seq_id", "Cartn_x", "Cartn_y", "Cartn_z", "occupancy",
                             "pdbx_PDB_model_num"})
    out << "_atom_site." << column << "\n";
  for (size_t i = 0; i < atoms && i < m.atoms.size(); ++i) {
    const Atom& a = m.atoms[i];
    out << "ATOM " << i + 1 << " " << a.element << " " << a.name << " . " << a.residue << " A "
        << a.residue_number << " " << a.position.x() << " " << a.position.y() << " " << a.position.z() << " 1.0 1\n";
  }
  return out.str();
}

std::string pqr_of(const Molecule& m, size_t atoms) {
  std::ostringstream out;
  for (size_t i = 0; i < atoms && i < m.atoms.size(); ++i) {
    const Atom& a = m.atoms[i];
    out << "ATOM " << i + 1 << " " << a.name << " " << a.residue << " A " << a.residue_number << " "
        << a.position.x() << " " << a.position.y() << " " << a.position.z() << " 0.0 " << a.radius << "\n";
  }
  return out.str();
}

std::string gzip_of(const std::string& text, const fs::path& scratch) {
  gzFile gz = gzopen(scratch.c_str(), "wb");
  gzwrite(gz, text.data(), static_cast<unsigned>(text.size()));
  gzclose(gz);
  std::string bytes = file_text(scratch.string());
  fs::remove(scratch);
  return bytes;
}

std::string ascii_ply(const SurfaceMesh& mesh) {
  std::ostringstream out;
  out << "ply\nformat ascii 1.0\nelement vertex " << mesh.vertices.size()
      << "\nproperty double x\nproperty double y\nproperty double z\nelement face " << mesh.triangles.size()
      << "\nproperty list uchar int vertex_indices\nend_header\n";
  for (const auto& v : mesh.vertices) out << v.x() << " " << v.y() << " " << v.z() << "\n";
  for (const auto& t : mesh.triangles) out << "3 " << t[0] << " " << t[1] << " " << t[2] << "\n";
  return out.str();
}

std::string binary_stl(const SurfaceMesh& mesh) {
  std::string out = "solid binary seed with facet in its header";
  out.resize(80, ' ');
  const uint32_t count = static_cast<uint32_t>(mesh.triangles.size());
  out.append(reinterpret_cast<const char*>(&count), 4);
  for (const auto& t : mesh.triangles) {
    out.append(12, '\0');
    for (int k = 0; k < 3; ++k)
      for (int c = 0; c < 3; ++c) {
        const float x = static_cast<float>(mesh.vertices[static_cast<size_t>(t[static_cast<size_t>(k)])][c]);
        out.append(reinterpret_cast<const char*>(&x), 4);
      }
    out.append(2, '\0');
  }
  return out;
}

// Five tetrahedra filling a cube, with its twelve boundary triangles.
TetMesh cube_tets() {
  TetMesh m;
  for (int k = 0; k < 8; ++k) m.points.emplace_back(k & 1, (k >> 1) & 1, (k >> 2) & 1);
  m.tets = {{0, 1, 3, 5}, {0, 3, 2, 6}, {0, 5, 4, 6}, {3, 5, 6, 7}, {0, 3, 6, 5}};
  m.tet_region.assign(m.tets.size(), 1);
  m.faces = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
             {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  m.face_marker.assign(m.faces.size(), 1);
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: fuzz_seeds DATA_DIR OUT_DIR\n";
    return 2;
  }
  const fs::path data = argv[1], out = argv[2];
  const std::string pept_text = file_text((data / "pept.pdb").string());
  const Molecule pept = read_molecule((data / "pept.pdb").string());
  put(out, "pdb", "pept-head.pdb", pdb_head(pept_text, 20));
  put(out, "pdb", "1ejg-head.pdb", pdb_head(file_text((data / "1ejg.pdb").string()), 60));  // alternate locations
  put(out, "pdb", "2k39-models.pdb", pdb_head(file_text((data / "2k39_3models.pdb").string()), 30));
  put(out, "mmcif", "pept.cif", mmcif_of(pept, 20));
  put(out, "pqr", "pept.pqr", pqr_of(pept, 20));
  Molecule few = pept;
  few.atoms.resize(20);
  put(out, "xyzr", "pept.xyzr", text_of([&](std::ostream& o) { write_xyzr(o, few, "seed"); }));
  put(out, "wpts", "pept.wpts", text_of([&](std::ostream& o) { write_wpts(o, balls_from_molecule(few, 0.5), "seed"); }));
  put(out, "gzip", "pept-head.pdb.gz", gzip_of(pdb_head(pept_text, 20), out / "scratch.gz"));

  Molecule three = pept;
  three.atoms.resize(3);
  const SkinMeshResult made = mesh_skin(build_skin_complex(balls_from_molecule(three, 0.5)));
  const SurfaceMesh& mesh = made.mesh;
  auto written = [&](MeshFormat format) { return text_of([&](std::ostream& o) { write_mesh(o, mesh, format, nullptr); }); };
  put(out, "off", "skin.off", written(MeshFormat::off));
  put(out, "ply_binary", "skin.ply", written(MeshFormat::ply));
  put(out, "ply_ascii", "skin.ply", ascii_ply(mesh));
  put(out, "obj", "skin.obj", written(MeshFormat::obj));
  put(out, "stl", "skin-ascii.stl", written(MeshFormat::stl));
  put(out, "stl", "skin-binary.stl", binary_stl(mesh));
  put(out, "gmsh", "skin.msh", written(MeshFormat::gmsh));
  const TetMesh cube = cube_tets();
  put(out, "gmsh", "cube.msh", text_of([&](std::ostream& o) { write_gmsh(o, cube); }));
  const std::string nul(1, '\0');
  put(out, "msms", "skin.msms",
      text_of([&](std::ostream& o) { write_msms_vert(o, mesh, nullptr); }) + nul +
          text_of([&](std::ostream& o) { write_msms_face(o, mesh, nullptr); }));
  put(out, "tetgen", "cube.tetgen",
      text_of([&](std::ostream& o) { write_tetgen_node(o, cube); }) + nul +
          text_of([&](std::ostream& o) { write_tetgen_ele(o, cube); }) + nul +
          text_of([&](std::ostream& o) { write_tetgen_face(o, cube); }));
  for (const auto& t : fuzz::fuzz_targets())
    if (!fs::exists(out / t.name)) {
      std::cerr << "fuzz_seeds: no seed for " << t.name << "\n";
      return 1;
    }
  std::cout << "seeds for " << fuzz::fuzz_targets().size() << " targets in " << out.string() << "\n";
  return 0;
}
