// Writing tetrahedral meshes: VTK XML, Gmsh 4.1 and TetGen's own files (see tet_write.hpp).
#include "skinmesh/mesh_io/tet_write.hpp"

#include "skinmesh/core/number_text.hpp"

#include <Eigen/Core>

#include <cmath>
#include <map>
#include <set>

namespace skinmesh {
namespace {

std::string number(double v) { return exact_number_text(v); }

}  // namespace

void write_vtu(std::ostream& out, const TetMesh& mesh) {
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      << "<UnstructuredGrid>\n"
      << "<Piece NumberOfPoints=\"" << mesh.points.size() << "\" NumberOfCells=\"" << mesh.tets.size() << "\">\n"
      << "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (const auto& p : mesh.points) out << number(p[0]) << ' ' << number(p[1]) << ' ' << number(p[2]) << '\n';
  out << "</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (const auto& t : mesh.tets) out << t[0] << ' ' << t[1] << ' ' << t[2] << ' ' << t[3] << '\n';
  out << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (size_t i = 0; i < mesh.tets.size(); ++i) out << 4 * (i + 1) << '\n';
  out << "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (size_t i = 0; i < mesh.tets.size(); ++i) out << "10\n";  // VTK_TETRA
  out << "</DataArray>\n</Cells>\n<CellData Scalars=\"region\">\n"
      << "<DataArray type=\"Int32\" Name=\"region\" format=\"ascii\">\n";
  for (int r : mesh.tet_region) out << r << '\n';
  out << "</DataArray>\n</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
}

void write_gmsh(std::ostream& out, const TetMesh& mesh) {
  // One surface entity per face marker and one volume entity per region, each
  // its own physical group with the same tag.
  const std::set<int> markers(mesh.face_marker.begin(), mesh.face_marker.end());
  const std::set<int> regions(mesh.tet_region.begin(), mesh.tet_region.end());
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (const auto& p : mesh.points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  auto names = [](int dim, int tag) -> std::string {
    if (dim == 2) return tag == kFaceSkin ? "skin" : tag == kFaceCavity ? "cavity_surface" : tag == kFaceBox ? "box" : "faces";
    return tag == kRegionInterior ? "interior" : tag == kRegionSolvent ? "solvent" : tag == kRegionCavity ? "cavity" : "region";
  };
  const std::string box = number(lo[0]) + ' ' + number(lo[1]) + ' ' + number(lo[2]) + ' ' + number(hi[0]) + ' ' +
                          number(hi[1]) + ' ' + number(hi[2]);
  out << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
  out << "$PhysicalNames\n" << markers.size() + regions.size() << '\n';
  for (int m : markers) out << "2 " << m << " \"" << names(2, m) << "\"\n";
  for (int r : regions) out << "3 " << r << " \"" << names(3, r) << "\"\n";
  out << "$EndPhysicalNames\n";
  out << "$Entities\n0 0 " << markers.size() << ' ' << regions.size() << '\n';
  for (int m : markers) out << m << ' ' << box << " 1 " << m << " 0\n";
  for (int r : regions) out << r << ' ' << box << " 1 " << r << " 0\n";
  out << "$EndEntities\n";
  // All nodes in one block, classified on the first volume.
  const int node_entity = regions.empty() ? 1 : *regions.begin();
  out << "$Nodes\n1 " << mesh.points.size() << " 1 " << mesh.points.size() << '\n';
  out << "3 " << node_entity << " 0 " << mesh.points.size() << '\n';
  for (size_t i = 0; i < mesh.points.size(); ++i) out << i + 1 << '\n';
  for (const auto& p : mesh.points) out << number(p[0]) << ' ' << number(p[1]) << ' ' << number(p[2]) << '\n';
  out << "$EndNodes\n";
  std::map<int, std::vector<size_t>> faces_of, tets_of;
  for (size_t i = 0; i < mesh.faces.size(); ++i) faces_of[mesh.face_marker[i]].push_back(i);
  for (size_t i = 0; i < mesh.tets.size(); ++i) tets_of[mesh.tet_region[i]].push_back(i);
  const size_t total = mesh.faces.size() + mesh.tets.size();
  out << "$Elements\n" << faces_of.size() + tets_of.size() << ' ' << total << " 1 " << total << '\n';
  size_t tag = 1;
  for (const auto& [m, list] : faces_of) {
    out << "2 " << m << " 2 " << list.size() << '\n';  // 3-node triangles
    for (size_t i : list) {
      const auto& f = mesh.faces[i];
      out << tag++ << ' ' << f[0] + 1 << ' ' << f[1] + 1 << ' ' << f[2] + 1 << '\n';
    }
  }
  for (const auto& [r, list] : tets_of) {
    out << "3 " << r << " 4 " << list.size() << '\n';  // 4-node tetrahedra
    for (size_t i : list) {
      const auto& t = mesh.tets[i];
      out << tag++ << ' ' << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << ' ' << t[3] + 1 << '\n';
    }
  }
  out << "$EndElements\n";
}

void write_tetgen_node(std::ostream& out, const TetMesh& mesh) {
  out << mesh.points.size() << " 3 0 0\n";
  for (size_t i = 0; i < mesh.points.size(); ++i)
    out << i << ' ' << number(mesh.points[i][0]) << ' ' << number(mesh.points[i][1]) << ' '
        << number(mesh.points[i][2]) << '\n';
}

void write_tetgen_ele(std::ostream& out, const TetMesh& mesh) {
  out << mesh.tets.size() << " 4 1\n";
  for (size_t i = 0; i < mesh.tets.size(); ++i) {
    const auto& t = mesh.tets[i];
    out << i << ' ' << t[0] << ' ' << t[1] << ' ' << t[2] << ' ' << t[3] << ' ' << mesh.tet_region[i] << '\n';
  }
}

void write_tetgen_face(std::ostream& out, const TetMesh& mesh) {
  out << mesh.faces.size() << " 1\n";
  for (size_t i = 0; i < mesh.faces.size(); ++i) {
    const auto& f = mesh.faces[i];
    out << i << ' ' << f[0] << ' ' << f[1] << ' ' << f[2] << ' ' << mesh.face_marker[i] << '\n';
  }
}

}  // namespace skinmesh
