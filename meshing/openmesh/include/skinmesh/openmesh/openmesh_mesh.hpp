// The mesher's result as an OpenMesh triangle mesh (double precision), for
// local edits: the morph moves, splits and collapses on this structure. Every
// vertex carries its mixed cell, so it can be moved and re-projected with a
// short walk.
#pragma once

#include "skinmesh/core/surface_mesh.hpp"

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

namespace skinmesh {

struct SkinMeshTraits : public OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
  using Normal = OpenMesh::Vec3d;
  VertexAttributes(OpenMesh::Attributes::Normal | OpenMesh::Attributes::Status);
  FaceAttributes(OpenMesh::Attributes::Status);
  EdgeAttributes(OpenMesh::Attributes::Status);
  HalfedgeAttributes(OpenMesh::Attributes::PrevHalfedge);
};
using SkinTriMesh = OpenMesh::TriMesh_ArrayKernelT<SkinMeshTraits>;

// Name of the per-vertex int property holding the mixed cell (-1 when unknown).
inline const char* mixed_cell_property_name() { return "skinmesh:mixed_cell"; }

// Throws ContractError when a triangle cannot be added as a manifold
// face (OpenMesh refuses complex edges and vertices).
SkinTriMesh to_openmesh(const SurfaceMesh& mesh);
SurfaceMesh from_openmesh(const SkinTriMesh& mesh);

}  // namespace skinmesh
