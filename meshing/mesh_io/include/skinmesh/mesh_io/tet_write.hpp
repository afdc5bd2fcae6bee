// Writing the flat tetrahedral mesh: VTK XML unstructured grid (ParaView)
// with the region as cell data; Gmsh MSH 4.1 ASCII with one volume entity per
// region and one surface entity per face marker; TetGen's own zero-based
// .node, .ele (region as attribute) and .face (marker). Coordinates at full
// double precision.
#pragma once

#include "skinmesh/core/tet_mesh.hpp"

#include <ostream>

namespace skinmesh {

void write_vtu(std::ostream& out, const TetMesh& mesh);
void write_gmsh(std::ostream& out, const TetMesh& mesh);
void write_tetgen_node(std::ostream& out, const TetMesh& mesh);
void write_tetgen_ele(std::ostream& out, const TetMesh& mesh);
void write_tetgen_face(std::ostream& out, const TetMesh& mesh);

}  // namespace skinmesh
