// Tetrahedral meshes bounded by a skin mesh, made by the TetGen program
// (Debian's `tetgen`): the molecule's interior, the solvent between the skin
// and a box around it, or both, with region and boundary markers. The skin's
// triangles stay as they are (no Steiner points on the surface), so the tet
// mesh's boundary is the surface mesh itself; the few tetrahedra TetGen then
// leaves outside the quality bounds are mended by improve_tet_mesh.
#pragma once

#include "skinmesh/core/surface_mesh.hpp"

#include <Eigen/Core>

#include <array>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

namespace skinmesh {

enum class VolumeDomain { interior, exterior, both };

// Region markers of tetrahedra and boundary markers of faces.
constexpr int kRegionInterior = 1;  // inside the molecule's skin
constexpr int kRegionSolvent = 2;   // between the skin and the box
constexpr int kRegionCavity = 3;    // an enclosed void of the molecule (kept as solvent-like region)
constexpr int kFaceSkin = 1;        // a triangle of the skin (outer surface)
constexpr int kFaceCavity = 2;      // a triangle of a cavity's surface
constexpr int kFaceBox = 3;         // a triangle of the outer box

struct VolumeOptions {
  VolumeDomain domain = VolumeDomain::interior;
  double box_margin = 10.0;        // Angstrom between the skin's bounding box and the outer box
  double max_radius_edge = 2.0;    // largest circumradius / shortest edge of a tetrahedron (TetGen -q)
  double min_dihedral = 5.0;       // degrees: smallest dihedral angle (TetGen -q)
  double max_volume = 0.0;         // Angstrom^3: largest tetrahedron, 0 for no bound (TetGen -a)
  bool keep_cavities = true;       // mesh enclosed voids (region kCavityRegion); else leave them empty
  std::string tetgen = "tetgen";   // the program
};

struct TetMesh {
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<int, 4>> tets;          // positively oriented
  std::vector<int> tet_region;                   // kRegion* per tetrahedron
  std::vector<std::array<int, 3>> faces;         // boundary and interface triangles
  std::vector<int> face_marker;                  // kFace* per face
};

// TetGen failed, or the surface cannot bound a volume (not closed, intersecting).
class VolumeMeshError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};


// A second opinion on self-intersections, independent of CGAL: TetGen's -d
// check of the surface. Returns the number of intersecting triangle pairs.
long tetgen_self_intersections(const SurfaceMesh& surface, const std::string& tetgen = "tetgen");

// Brings tetrahedra TetGen left outside radius-edge <= max_radius_edge or
// dihedral angles >= min_dihedral degrees within them: moves the points it
// added (those on no face of `mesh.faces`) and removes edges on no face. The
// faces, the points on them and every region's volume stay as they are.
struct TetImprovement {
  long bad_before = 0, bad_after = 0;  // tetrahedra outside the bounds
  long moved = 0;                      // points moved
  long flips = 0;                      // edges removed (ring of tetrahedra retriangulated)
};
TetImprovement improve_tet_mesh(TetMesh& mesh, double max_radius_edge, double min_dihedral);

// The surface must be closed, manifold and outward oriented (as skinmesh
// writes it); components with negative enclosed volume are cavities.
// TetGen's result is passed through improve_tet_mesh with the options'
// bounds; what that did is stored in *smoothing when given.
TetMesh tetrahedralize(const SurfaceMesh& surface, const VolumeOptions& options = {},
                       TetImprovement* smoothing = nullptr);

// Quality of a tetrahedral mesh.
struct TetQuality {
  long points = 0, tets = 0;
  double volume = 0;                   // Angstrom^3, all tetrahedra
  double min_dihedral = 0, max_dihedral = 0;  // degrees
  double max_radius_edge = 0;          // circumradius / shortest edge
  // The same over tetrahedra with no vertex on a boundary face (the
  // surface's neighbourhood is where TetGen, forbidden to split the surface,
  // leaves tetrahedra outside its bounds).
  double max_radius_edge_off_boundary = 0;
  double min_dihedral_off_boundary = 0;  // degrees, same tetrahedra
  long inverted = 0;                   // tetrahedra with volume <= 0
};
TetQuality grade_tet_mesh(const TetMesh& mesh);
double region_volume(const TetMesh& mesh, int region);

// VTK XML unstructured grid (ParaView) with the region as cell data, and Gmsh
// MSH 4.1 ASCII with one volume entity per region and one surface entity per
// face marker.
void write_vtu(std::ostream& out, const TetMesh& mesh);
void write_gmsh(std::ostream& out, const TetMesh& mesh);
// TetGen's own formats, zero-based: .node, .ele (region as attribute), .face (marker).
void write_tetgen_node(std::ostream& out, const TetMesh& mesh);
void write_tetgen_ele(std::ostream& out, const TetMesh& mesh);
void write_tetgen_face(std::ostream& out, const TetMesh& mesh);

}  // namespace skinmesh
