// The quality report both `quality` and `mesh` print and write: grading as
// JSON, the on-surface error by the oracle, the human summary and the SVG
// histogram of smallest angles.
#pragma once

#include "skinmesh/core/balls.hpp"
#include "skinmesh/meshing/mesh_quality.hpp"
#include "skinmesh/meshing/volume_mesh.hpp"

#include <nlohmann/json.hpp>

#include <ostream>
#include <string>
#include <vector>

namespace skinmesh::app {

nlohmann::json to_json(const MeshQuality& q);

// skinmesh::on_surface_error as JSON: {"max", "mean", "uncertified"}.
nlohmann::json on_surface_error_json(const std::vector<Eigen::Vector3d>& vertices, const std::vector<Ball>& balls,
                                     double shrink);

void print_quality_summary(std::ostream& out, const std::string& name, const MeshQuality& q);

// The same for tetrahedral meshes (regions, boundary match included).
nlohmann::json tet_report(const TetMesh& mesh, const TetQuality& q);
void print_tet_quality(std::ostream& out, const TetQuality& q);

// A bar chart of the smallest angle per triangle, written by the tool itself.
void write_svg(std::ostream& out, const MeshQuality& q, const std::string& title);

}  // namespace skinmesh::app
