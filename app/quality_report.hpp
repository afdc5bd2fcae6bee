// The quality report both `quality` and `mesh` print and write: grading as
// JSON, the on-surface error by the oracle, the human summary and the SVG
// histogram of smallest angles.
#pragma once

#include "skinmesh/core/tet_mesh.hpp"
#include "skinmesh/mesher/skin_mesher.hpp"
#include "skinmesh/quality/guarantees.hpp"
#include "skinmesh/quality/mesh_quality.hpp"
#include "skinmesh/quality/on_surface_error.hpp"
#include "skinmesh/quality/skin_area.hpp"
#include "skinmesh/quality/tet_quality.hpp"

#include <nlohmann/json.hpp>

#include <ostream>
#include <string>
#include <vector>

namespace skinmesh::app {

// JSON as text, two-space indented or on one line. Bytes that are not UTF-8 (an atom name
// or a file name from an old file) become U+FFFD instead of an exception
// after the work is done.
enum class JsonLayout { indented, one_line };  // one_line: a JSON Lines record
std::string json_text(const nlohmann::json& j, JsonLayout layout = JsonLayout::indented);

nlohmann::json to_json(const MeshQuality& q);

// {"max", "mean", "uncertified"}.
nlohmann::json to_json(const SurfaceError& e);
// Each guarantee true or false (no_self_intersections and topology_of_skin null when not checked).
nlohmann::json guarantees_json(const GuaranteeReport& g);

// The skin's own area beside the triangles' (skin_area.hpp): {"skin",
// "uncertainty", "mesh", "mesh_relative_error", "converged"}.
nlohmann::json skin_area_json(const SkinArea& skin, double mesh_area);

// The mesher's options and its refinement counts as `skinmesh mesh --report` writes them.
nlohmann::json options_json(const MeshingOptions& m);
nlohmann::json refinement_json(const MeshingStats& s);

void print_quality_summary(std::ostream& out, const std::string& name, const MeshQuality& q);

// The same for tetrahedral meshes (regions, boundary match included).
nlohmann::json tet_report(const TetMesh& mesh, const TetQuality& q);
void print_tet_quality(std::ostream& out, const TetQuality& q);

// A bar chart of the smallest angle per triangle, written by the tool itself.
void write_svg(std::ostream& out, const MeshQuality& q, const std::string& title);

}  // namespace skinmesh::app
